// Generated .glb files for the tests and benchmarks that need a scene of a given shape: a texture
// slow to decode, or many textures to upload.
import { deflateSync } from 'node:zlib';

/** A .glb of the glTF document `doc` and its binary chunk `bin` (4-byte aligned). */
export function glbOf(doc, bin) {
    const json = Buffer.from(JSON.stringify(doc).padEnd(Math.ceil(JSON.stringify(doc).length / 4) * 4, ' '));
    const header = Buffer.alloc(12);
    header.writeUInt32LE(0x46546c67, 0);
    header.writeUInt32LE(2, 4);
    header.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
    const chunkHeader = (length, type) => {
        const b = Buffer.alloc(8);
        b.writeUInt32LE(length, 0);
        b.writeUInt32LE(type, 4);
        return b;
    };
    return Buffer.concat([header, chunkHeader(json.length, 0x4e4f534a), json, chunkHeader(bin.length, 0x004e4942), bin]);
}

/** A .glb of one textured quad whose side x side PNG (a gradient) takes a while to decode. */
// `images` copies of one side x side PNG: each is decoded on its own (about 250 ms at 4096).
export function slowToLoadGlb(side, images = 1) {
    const crcTable = Array.from({ length: 256 }, (_, n) => {
        let c = n;
        for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
        return c >>> 0;
    });
    const crc = (buf) => {
        let c = 0xffffffff;
        for (const b of buf) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
        return (c ^ 0xffffffff) >>> 0;
    };
    const chunk = (type, data) => {
        const head = Buffer.alloc(4);
        head.writeUInt32BE(data.length);
        const body = Buffer.concat([Buffer.from(type, 'ascii'), data]);
        const tail = Buffer.alloc(4);
        tail.writeUInt32BE(crc(body));
        return Buffer.concat([head, body, tail]);
    };
    const rows = Buffer.alloc(side * (1 + side * 4));
    for (let y = 0; y < side; y++) {
        const row = y * (1 + side * 4);
        for (let x = 0; x < side; x++) rows.set([(x * 255) / side, (y * 255) / side, 128, 255], row + 1 + x * 4);
    }
    const ihdr = Buffer.alloc(13);
    ihdr.writeUInt32BE(side, 0);
    ihdr.writeUInt32BE(side, 4);
    ihdr.set([8, 6, 0, 0, 0], 8);
    const png = Buffer.concat([Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr),
        chunk('IDAT', deflateSync(rows)), chunk('IEND', Buffer.alloc(0))]);
    const geometry = Buffer.from(new Float32Array([-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1, 0, 0, 1, 0, 1, 1, 0, 1]).buffer);
    const indices = Buffer.from(new Uint32Array([0, 2, 1, 0, 3, 2]).buffer);
    const pad = (b) => Buffer.concat([b, Buffer.alloc((4 - (b.length % 4)) % 4)]);
    const bin = pad(Buffer.concat([geometry, indices, png]));
    const doc = {
        asset: { version: '2.0' }, scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
        meshes: [{ primitives: [{ attributes: { POSITION: 0, TEXCOORD_0: 1 }, indices: 2, material: 0 }] }],
        materials: [{ pbrMetallicRoughness: { baseColorTexture: { index: 0 }, metallicFactor: 0 } }],
        textures: [{ source: 0 }], images: Array.from({ length: images }, () => ({ bufferView: 3, mimeType: 'image/png' })),
        accessors: [
            { bufferView: 0, componentType: 5126, count: 4, type: 'VEC3', min: [-1, 0, -1], max: [1, 0, 1] },
            { bufferView: 1, componentType: 5126, count: 4, type: 'VEC2' },
            { bufferView: 2, componentType: 5125, count: 6, type: 'SCALAR' }],
        bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: 48 }, { buffer: 0, byteOffset: 48, byteLength: 32 },
            { buffer: 0, byteOffset: 80, byteLength: 24 }, { buffer: 0, byteOffset: 104, byteLength: png.length }],
        buffers: [{ byteLength: bin.length }],
    };
    return glbOf(doc, bin);
}

/** `count` quads side by side, each with its own material and texture, all from the PNG in `glb`'s images[0]. */
export function texturedQuadsGlb(glb, count) {
    const jsonLength = glb.readUInt32LE(12);
    const doc = JSON.parse(glb.subarray(20, 20 + jsonLength).toString());
    const bin = glb.subarray(20 + jsonLength + 8);
    const pngView = doc.images[0].bufferView;
    Object.assign(doc, {
        scenes: [{ nodes: Array.from({ length: count }, (_, i) => i) }],
        nodes: Array.from({ length: count }, (_, i) => ({ mesh: i, translation: [i * 2.2, 0, 0] })),
        meshes: Array.from({ length: count }, (_, i) => ({ primitives: [{ ...doc.meshes[0].primitives[0], material: i }] })),
        materials: Array.from({ length: count }, (_, i) => ({ pbrMetallicRoughness: { baseColorTexture: { index: i }, metallicFactor: 0 } })),
        textures: Array.from({ length: count }, (_, i) => ({ source: i })),
        images: Array.from({ length: count }, () => ({ bufferView: pngView, mimeType: 'image/png' })),
    });
    return glbOf(doc, bin);
}
