// The accuracy view: a one-shot render of the current view through POST /api/render with
// "compare" (the server renders the same frame and a CPU reference, and reports error metrics),
// and the difference between that render and the streamed frame. Pure: request building, settings,
// metric formatting and the difference image; main.js does the fetch and the drawing.
//
// The server's answer has the metrics (stats.compare), the rendered image and the reference, both
// tone-mapped PNGs (PROTOCOL.md, HTTP API). The reference is a Monte Carlo render with noise of its
// own: the request asks for a noise target rather than a sample count, and the figures shown are
// corrected for that noise, for the whole image and for the indirect light alone.

import { requestLight } from './lights.js';
import { validateJson } from './protocol.js';

/** The reference modes of render_request.json, cheapest first. */
export const COMPARE_MODES = Object.freeze(['one-bounce-unoccluded', 'direct', 'one-bounce', 'path']);
/**
 * noiseTarget: the reference's relative noise (of its indirect light) to stop at; maxSpp: the cap
 * on its samples per pixel, the server's own limit by default (more is a 400 naming /compare/spp).
 */
export const DEFAULT_COMPARE = Object.freeze({
    mode: 'one-bounce-unoccluded', noiseTarget: 0.1, maxSpp: 1024, maxSide: 128,
});
/** The ranges of the Accuracy controls (the schema allows noise targets up to 0.5; above 20 % a reference says little). */
export const COMPARE_RANGES = Object.freeze({
    noiseTarget: Object.freeze({ min: 0.01, max: 0.2 }),
    maxSpp: Object.freeze({ min: 1, max: 4096 }),
});

const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));

/**
 * The saved Accuracy settings made usable: {noiseTarget, maxSpp} within COMPARE_RANGES, the defaults
 * for anything missing or unreadable. An older page saved `compareSpp`, a fixed sample count; it is
 * not taken as the cap, since a cap of 8 would keep every reference far from the noise target.
 */
export function compareSettings(stored) {
    const target = Number(stored?.compareNoiseTarget);
    const cap = Number(stored?.compareMaxSpp);
    const { noiseTarget: t, maxSpp: c } = COMPARE_RANGES;
    return {
        noiseTarget: Number.isFinite(target) && target > 0 ? clamp(target, t.min, t.max) : DEFAULT_COMPARE.noiseTarget,
        maxSpp: Number.isFinite(cap) && cap >= 1 ? clamp(Math.round(cap), c.min, c.max) : DEFAULT_COMPARE.maxSpp,
    };
}

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
 * The request's "compare": the reference stops at `noiseTarget` (relative to its indirect light, the
 * server's default noise_of) with `maxSpp` only the cap. A direct reference is one exact sample, so
 * a noise target means nothing there; the cap still goes along, so a cap over the server's limit is
 * refused alike in every mode.
 */
function compareOptions(mode, noiseTarget, maxSpp) {
    const compare = { mode };
    if (mode !== 'direct' && noiseTarget > 0) compare.noise_target = noiseTarget;
    if (maxSpp !== undefined) compare.spp = maxSpp;
    return compare;
}

/**
 * The POST /api/render body for the frame on screen: its scene, technique and parameters
 * (stats.params of the drawn frame, so presets and the effect plan's choices are the same), the
 * camera and the session's `lights` (all of them, with types and ids: they replace the scene's, so
 * added and removed lights count too), at compareSize(); PNG so that the difference view sees no
 * codec artefacts. `light` (one light, edits the scene's first) is for servers without a light list.
 */
export function buildCompareRequest({
    scene, technique, params, camera, lights, light, frameSize, maxSide, mode, noiseTarget, maxSpp,
}) {
    const request = {
        scene,
        technique,
        params: { ...(params ?? {}) },
        size: compareSize(frameSize, maxSide),
        format: 'png',
        response: 'json',
        compare: compareOptions(mode, noiseTarget, maxSpp),
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

/** A relative figure in percent: one decimal, two below 1 % so that small errors do not read as 0. */
export function percent(v) {
    if (!Number.isFinite(v) || v >= 1e300) return '–'; // the server's "undefined" relative RMSE is huge
    const p = 100 * v;
    if (p === 0) return '0 %';
    return `${p.toFixed(Math.abs(p) < 1 ? 2 : 1)} %`;
}

/** A noise target in percent as the user set it: 0.05 -> "5 %", 0.025 -> "2.5 %". */
function targetPercent(v) {
    return `${Number((100 * v).toPrecision(3))} %`;
}

/** What the progress line says the server is rendering: the reference and what stops it. */
export function referenceLabel(request) {
    const { mode, spp, noise_target: target } = request.compare;
    const size = `${request.size[0]}×${request.size[1]}`;
    if (mode === 'direct') return `direct, ${size}`;
    const cap = spp !== undefined ? `, at most ${spp} spp` : '';
    if (target > 0) return `${mode}, to ${targetPercent(target)} noise${cap}, ${size}`;
    return `${mode}, ${spp ?? 64} spp, ${size}`; // 64: the schema's default
}

/**
 * One relative error with the reference's noise: the corrected figure when the server sent one
 * (older servers send neither it nor the noise), and whether it is corrected.
 */
function errorWithNoise(m) {
    const noise = Number.isFinite(m?.reference_noise) ? m.reference_noise : null;
    const corrected = noise !== null && Number.isFinite(m.relative_rmse_corrected);
    return { error: corrected ? m.relative_rmse_corrected : m?.relative_rmse, noise, corrected };
}

function errorText({ error, noise }, noiseLabel) {
    return `${percent(error)} (${noiseLabel} ${noise === null ? '–' : percent(noise)})`;
}

/**
 * How the reference ended, for a noise target: stopped at it, or not reached (the cap or the
 * server's time limit came first). The noise reached is the one compare measured over the same
 * pixels, of the indirect light or the whole image as the target was.
 */
function stopNote(ref, compare) {
    const target = ref.noise_target;
    if (!Number.isFinite(target?.value)) return '';
    const reached = target.of === 'image' ? compare.reference_noise : compare.indirect?.reference_noise;
    const asked = targetPercent(target.value);
    if (!Number.isFinite(reached)) return ` (to ${asked} noise)`;
    // 2 %: the renderer's own estimate and compare's may differ in the last digits.
    if (reached > target.value * 1.02) return ` (${asked} noise not reached: ${percent(reached)})`;
    return ` (stopped at ${asked} noise)`;
}

/**
 * The lines the Accuracy section and the overlay show for stats.compare; null without one.
 * `rows` are [label, text] for the result block: the indirect light's error (each side less its
 * own direct light: the GI technique's own error) and its energy balance, the whole image, the
 * direct pass, PSNR/SSIM/FLIP and the reference. The headline figures are corrected for the
 * reference's noise where the server reports it; `hint` says which. Fields an older server does
 * not send read "–"; a direct reference has no indirect light or direct pass to split.
 */
export function formatCompare(compare) {
    if (!compare) return null;
    const ref = compare.reference ?? {};
    const split = ref.mode !== 'direct';
    const image = errorWithNoise(compare);
    const indirect = compare.indirect ? errorWithNoise(compare.indirect) : null;
    const direct = compare.direct ? errorWithNoise(compare.direct) : null;
    const ratio = compare.indirect?.mean_ratio;
    const headline = indirect ?? image;
    const f = {
        indirect: indirect ? errorText(indirect, 'reference noise') : '–',
        indirectEnergy: Number.isFinite(ratio) ? `${ratio.toFixed(3)} × the reference's` : '–',
        image: errorText(image, 'noise'),
        direct: direct ? percent(direct.error) : '–',
        psnr: Number.isFinite(compare.psnr_db) ? `${compare.psnr_db.toFixed(1)} dB` : '–',
        ssim: Number.isFinite(compare.ssim) ? compare.ssim.toFixed(4) : '–',
        flip: Number.isFinite(compare.flip) ? compare.flip.toFixed(4) : '–',
        reference: [ref.mode, ref.spp !== undefined ? `${ref.spp} spp${stopNote(ref, compare)}` : null,
            Number.isFinite(ref.seconds) ? `${ref.seconds.toFixed(2)} s` : null,
            ref.cache_hit ? 'cached' : null].filter(Boolean).join(', '),
        // The one figure of the overlay and the layer label: the indirect light's when there is one.
        relRmse: percent(headline.error),
        overlay: `${indirect ? 'indirect' : 'image'} error ${percent(headline.error)}`
            + `${headline.noise !== null ? ` ±${percent(headline.noise)} noise` : ''}`,
        corrected: Boolean(indirect?.corrected || image.corrected),
    };
    f.hint = [f.corrected ? 'Errors corrected for the reference\'s own noise'
        : 'Errors as measured (the server reports no noise for this reference)',
    indirect ? 'indirect = each side less its own direct light' : null].filter(Boolean).join('; ') + '.';
    f.rows = [
        ...(split ? [['indirect light error', f.indirect], ['indirect energy', f.indirectEnergy]] : []),
        ['whole image', f.image],
        ...(split ? [['direct pass', f.direct]] : []),
        ['PSNR', f.psnr], ['SSIM', f.ssim], ['FLIP', f.flip], ['reference', f.reference],
    ];
    return f;
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
