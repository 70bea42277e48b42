// Small 3-vector helpers shared by camera.js and light.js (arrays [x, y, z]).

export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
export const length = (a) => Math.hypot(a[0], a[1], a[2]);
export const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));

/** a / |a|; the zero vector stays zero. */
export function normalize(a) {
    const l = length(a);
    return l > 0 ? scale(a, 1 / l) : [0, 0, 0];
}

/** Rounded to 1e-5 (what the camera and light messages carry; keeps the JSON short). */
export function roundVec(v) {
    return v.map((x) => Math.round(x * 1e5) / 1e5 + 0);
}
