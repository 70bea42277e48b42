// The accuracy view: a one-shot render of the current view through POST /api/render with
// "compare" (the server renders the same frame and a CPU reference, and reports error metrics),
// and the difference between that render and the streamed frame. Pure: request building, metric
// formatting and the difference image; main.js does the fetch and the drawing.
//
// The server's answer has the metrics (stats.compare), the rendered image and the reference, both
// tone-mapped PNGs (PROTOCOL.md, HTTP API).

import { requestLight } from './lights.js';
import { validateJson } from './protocol.js';

/** The reference modes of render_request.json, cheapest first. */
export const COMPARE_MODES = Object.freeze(['one-bounce-unoccluded', 'direct', 'one-bounce', 'path']);
export const DEFAULT_COMPARE = Object.freeze({ mode: 'one-bounce-unoccluded', spp: 8, maxSide: 128 });

/** The render size: `frameSize`'s aspect with the longer side at most `maxSide`, each side >= 16. */
export function compareSize(frameSize, maxSide) {
    const [w, h] = frameSize?.length === 2 && frameSize[0] > 0 && frameSize[1] > 0 ? frameSize : [1, 1];
    const s = Math.min(1, maxSide / Math.max(w, h));
    return [Math.max(16, Math.round(w * s)), Math.max(16, Math.round(h * s))];
}

/** Scenes the HTTP API can render: uploads belong to their session's WebSocket only. */
export function canCompare(scene) {
    return typeof scene === 'string' && scene.length > 0 && !scene.startsWith('upload:');
}

/**
 * The POST /api/render body for the frame on screen: its scene, technique and parameters
 * (stats.params of the drawn frame, so presets and the effect plan's choices are the same), the
 * camera and the session's `lights` (all of them, with types and ids: they replace the scene's, so
 * added and removed lights count too), at compareSize(); PNG so that the difference view sees no
 * codec artefacts. `light` (one light, edits the scene's first) is for servers without a light list.
 */
export function buildCompareRequest({ scene, technique, params, camera, lights, light, frameSize, maxSide, mode, spp }) {
    const request = {
        scene,
        technique,
        params: { ...(params ?? {}) },
        size: compareSize(frameSize, maxSide),
        format: 'png',
        response: 'json',
        compare: { mode, spp },
    };
    if (camera) request.camera = { ...camera };
    if (Array.isArray(lights)) request.lights = lights.map(requestLight);
    else if (light) request.light = { ...light };
    return request;
}

/**
 * Checks a request against protocol/http/render_request.json (`response` is the server's own
 * field, outside that schema). Returns null or {where, message}.
 */
export function validateCompareRequest(request, schema) {
    const { response, ...rest } = request;
    if (response !== undefined && response !== 'json' && response !== 'image') {
        return { where: '/response', message: 'must be "image" or "json"' };
    }
    return validateJson(rest, schema);
}

/** A key for "is the measurement still about this view": the request without its size and compare settings. */
export function viewKey(request) {
    const { size, compare, format, response, ...rest } = request;
    return JSON.stringify(rest);
}

function pct(v) {
    return Number.isFinite(v) && v < 1e300 ? `${(100 * v).toFixed(2)} %` : '–';
}

/** The lines the Accuracy section shows for stats.compare. */
export function formatCompare(compare) {
    if (!compare) return null;
    const ref = compare.reference ?? {};
    return {
        relRmse: pct(compare.relative_rmse),
        psnr: Number.isFinite(compare.psnr_db) ? `${compare.psnr_db.toFixed(1)} dB` : '–',
        ssim: Number.isFinite(compare.ssim) ? compare.ssim.toFixed(4) : '–',
        flip: Number.isFinite(compare.flip) ? compare.flip.toFixed(4) : '–',
        reference: [ref.mode, ref.spp !== undefined ? `${ref.spp} spp` : null,
            Number.isFinite(ref.seconds) ? `${ref.seconds.toFixed(2)} s` : null,
            ref.cache_hit ? 'cached' : null].filter(Boolean).join(', '),
    };
}

/**
 * |a - b| per channel times `gain`, as an opaque RGBA image; `a` and `b` are RGBA pixel arrays of
 * the same size (ImageData.data). Also returns the mean absolute difference in 0..255 units.
 */
export function diffImage(a, b, gain = 4) {
    if (a.length !== b.length) throw new Error(`images differ in size: ${a.length} vs ${b.length} bytes`);
    const out = new Uint8ClampedArray(a.length);
    let sum = 0;
    for (let i = 0; i < a.length; i += 4) {
        for (let c = 0; c < 3; ++c) {
            const d = Math.abs(a[i + c] - b[i + c]);
            sum += d;
            out[i + c] = d * gain;
        }
        out[i + 3] = 255;
    }
    const pixels = a.length / 4;
    return { data: out, meanAbs: pixels ? sum / (pixels * 3) : 0 };
}
