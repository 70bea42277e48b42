// A frame's encoded bytes to an image the canvas can draw. Where the page may use WebCodecs'
// ImageDecoder (a secure context: https, or the server on localhost) it decodes straight from the bytes,
// where createImageBitmap needs them in a Blob, which the browser reads back through its blob registry
// before it decodes: 1.2-1.6 ms at the median against 3.4-4.4 ms for cornell's 282 x 240 JPEGs
// (`node bench/interactive/orbit.mjs --scenes cornell --refinement 0`, `decode`; docs/interactive.md).
// Elsewhere, and for a type ImageDecoder does not take, createImageBitmap. Pure apart from the decoders
// it is given.

/**
 * The decoder for a page: `decode(bytes, mime)` resolves to `{ image, close(), way }`, where `image`
 * goes to drawImage, `close()` frees it and `way` names the path taken. `scope` supplies ImageDecoder,
 * createImageBitmap and isSecureContext (the window by default; a test passes its own).
 */
export function createFrameDecoder(scope = globalThis) {
    const Decoder = scope.isSecureContext !== false ? scope.ImageDecoder : undefined;
    // Whether ImageDecoder takes a type, asked once per type (the answer is a promise).
    const takes = new Map();
    const decoderTakes = (mime) => {
        if (!Decoder || typeof Decoder.isTypeSupported !== 'function') return Promise.resolve(false);
        if (!takes.has(mime)) takes.set(mime, Decoder.isTypeSupported(mime).then(Boolean, () => false));
        return takes.get(mime);
    };

    async function viaBitmap(bytes, mime) {
        const bitmap = await scope.createImageBitmap(new Blob([bytes], { type: mime }));
        return { image: bitmap, close: () => bitmap.close(), way: 'createImageBitmap' };
    }

    async function viaDecoder(bytes, mime) {
        const decoder = new Decoder({ data: bytes, type: mime });
        try {
            const { image } = await decoder.decode();
            return { image, close: () => image.close(), way: 'ImageDecoder' };
        } finally {
            decoder.close();
        }
    }

    return {
        async decode(bytes, mime) {
            return (await decoderTakes(mime)) ? viaDecoder(bytes, mime) : viaBitmap(bytes, mime);
        },
    };
}
