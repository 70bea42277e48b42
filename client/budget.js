// The resolution and frame-time choices of the "Resolution & quality" section: the pixel budget
// that caps the device pixel ratio announced in hello and resize, the frame-time targets a session
// may ask for (protocol 2, `frame_target_ms`), and how a frame's `stats.budget` reads. Pure, so
// node's test runner checks it.

import { MAX_DPR, MIN_DPR, viewportFor } from './protocol.js';

export const MIN_FRAME_TARGET_MS = 20;
export const MAX_FRAME_TARGET_MS = 1000;

// About a megapixel: a phone at dpr 3 would otherwise ask for 3x3 the pixels of its CSS viewport,
// which costs render time for detail the small screen barely shows.
export const DEFAULT_PIXEL_BUDGET = 1_000_000;

/** Pixel budgets offered in the sidebar; 0 announces the device's own ratio. */
export const PIXEL_BUDGETS = Object.freeze([
    Object.freeze({ label: '0.25 MP (fastest)', px: 250_000 }),
    Object.freeze({ label: '0.5 MP', px: 500_000 }),
    Object.freeze({ label: '1 MP', px: 1_000_000 }),
    Object.freeze({ label: '2 MP', px: 2_000_000 }),
    Object.freeze({ label: '4 MP', px: 4_000_000 }),
    Object.freeze({ label: 'device pixels (no cap)', px: 0 }),
]);

/** Frame-time targets offered in the sidebar; null leaves the server's default. */
export const FRAME_TARGETS = Object.freeze([
    Object.freeze({ label: 'server default', ms: null }),
    Object.freeze({ label: 'smooth (50 ms)', ms: 50 }),
    Object.freeze({ label: 'balanced (80 ms)', ms: 80 }),
    Object.freeze({ label: 'sharp (150 ms)', ms: 150 }),
]);

/**
 * The device pixel ratio to announce for a viewport of cssWidth x cssHeight CSS pixels: the
 * device's own, lowered so that width x height x dpr^2 stays within `budgetPx` (0: no cap).
 * Rounded down to 1/1000 so the product never ends up just over the budget; never below the
 * protocol's minimum.
 */
export function budgetDpr(cssWidth, cssHeight, devicePixelRatio, budgetPx) {
    const dpr = Math.min(MAX_DPR, Number.isFinite(devicePixelRatio) && devicePixelRatio > 0 ? devicePixelRatio : 1);
    const area = cssWidth * cssHeight;
    if (!(budgetPx > 0) || !(area > 0) || area * dpr * dpr <= budgetPx) return Math.max(MIN_DPR, dpr);
    return Math.max(MIN_DPR, Math.floor(Math.sqrt(budgetPx / area) * 1000) / 1000);
}

/** viewportFor() with the dpr capped to the pixel budget: {size: [w, h] CSS pixels, dpr}. */
export function budgetViewport(cssWidth, cssHeight, devicePixelRatio, budgetPx) {
    const { size } = viewportFor(cssWidth, cssHeight, 1);
    return { size, dpr: budgetDpr(size[0], size[1], devicePixelRatio, budgetPx) };
}

/** A stored pixel budget when it is one of the choices, else the default. */
export function normalizePixelBudget(px) {
    return PIXEL_BUDGETS.some((b) => b.px === px) ? px : DEFAULT_PIXEL_BUDGET;
}

/** A stored frame target: null (the server's default) or a whole number of ms in the protocol's range. */
export function normalizeFrameTarget(ms) {
    if (!Number.isInteger(ms)) return null;
    return ms >= MIN_FRAME_TARGET_MS && ms <= MAX_FRAME_TARGET_MS ? ms : null;
}

/**
 * Whether frame targets can be asked for: the server announces them (welcome.frame_target_ms)
 * and the client's schema copy lets `message` ('hello' or 'quality') carry the field, so the
 * page's own validation does not refuse it.
 */
export function frameTargetSupported(welcome, schemas, message = 'quality') {
    const field = schemas?.[message]?.properties?.frame_target_ms;
    if (!field) return false;
    return message === 'hello' || Number.isFinite(welcome?.frame_target_ms);
}

/** The dropdown's labels: {label: ms}; the default says what the server's default is. */
export function frameTargetOptions(serverDefaultMs) {
    return Object.fromEntries(FRAME_TARGETS.map((t) => [
        t.ms === null && Number.isFinite(serverDefaultMs) ? `server default (${serverDefaultMs} ms)` : t.label,
        t.ms === null ? 'default' : t.ms,
    ]));
}

const ms0 = (v) => (Number.isFinite(v) ? `${Math.round(v)} ms` : '–');

/**
 * A frame's `stats.budget` as one overlay line and its reason, or null without one:
 * "budget 80 ms: predicted 70 ms · VPLs 256 of 1024 · scale 0.31 · detail within 1 px, light views 1 texel
 * · maps 2048/512 of 4096/1024".
 */
export function budgetLine(budget) {
    if (!budget || typeof budget !== 'object') return null;
    const parts = [`predicted ${ms0(budget.predicted_ms)}`];
    // The receiver cap cut this frame's VPLs further, after the budget's own cap (the view had many
    // more receivers than the frame before it).
    const receiverCapped = Number.isFinite(budget.receiver_capped_vpls);
    if (receiverCapped) {
        parts.push(`VPLs ${budget.receiver_capped_vpls} of ${budget.vpls} (receiver cap)`);
    } else if (Number.isFinite(budget.vpls)) {
        parts.push(Number.isFinite(budget.vpl_cap) && budget.vpl_cap < budget.vpls
            ? `VPLs ${budget.vpl_cap} of ${budget.vpls}` : `VPLs ${budget.vpls}`);
    }
    if (Number.isFinite(budget.scale)) parts.push(`scale ${Number(budget.scale.toPrecision(3))}`);
    // The server draws big meshes simplified within this many of the frame's pixels, and in the light
    // views within this many texels of their maps.
    const eye = Number.isFinite(budget.lod_pixels) && budget.lod_pixels > 0 ? `${budget.lod_pixels} px` : null;
    const lights = Number.isFinite(budget.light_lod_texels) && budget.light_lod_texels > 0
        ? `${budget.light_lod_texels} texel${budget.light_lod_texels === 1 ? '' : 's'}` : null;
    if (eye && lights) parts.push(`detail within ${eye}, light views ${lights}`);
    else if (eye) parts.push(`detail within ${eye}`);
    else if (lights) parts.push(`light views within ${lights}`);
    // Light views drawn again at smaller sides than the parameters ask (shadow maps / RSMs, texels).
    const maps = budget.light_view_cap;
    if (maps && typeof maps === 'object' && Number.isFinite(maps.shadow_side)) {
        const rsm = Number.isFinite(maps.rsm_side);
        parts.push(`maps ${maps.shadow_side}${rsm ? `/${maps.rsm_side}` : ''} of ` +
            `${maps.shadow_side_asked}${rsm ? `/${maps.rsm_side_asked}` : ''}`);
    }
    return {
        text: `budget ${ms0(budget.target_ms)}: ${parts.join(' · ')}`,
        reason: typeof budget.reason === 'string' ? budget.reason : '',
        capped: receiverCapped || (Number.isFinite(budget.vpl_cap) && budget.vpl_cap < budget.vpls),
    };
}
