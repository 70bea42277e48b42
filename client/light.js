// A light seen from the eye camera: projecting it into the view for the gizmo, and turning pixel
// drags into new light positions and directions. Pure math on protocol cameras
// ({position, target, up?, fov_deg}) and lights ({type, position, direction, ...}).

import { add, clamp, cross, dot, length, normalize, roundVec, scale, sub } from './vec.js';

const DEG = Math.PI / 180;
// Closer than this (metres along the view) a point is not drawn: it is at or behind the eye.
const NEAR = 1e-3;

/** {eye, forward, right, up}: the camera's orthonormal view basis (up is +Y unless the camera says otherwise). */
export function viewBasis(camera) {
    const eye = camera.position;
    const forward = normalize(sub(camera.target, eye));
    let right = normalize(cross(forward, camera.up ?? [0, 1, 0]));
    if (length(right) === 0) right = [1, 0, 0];
    const up = cross(right, forward);
    return { eye, forward, right, up };
}

function tanHalfFov(camera) {
    return Math.tan(((camera.fov_deg ?? 40) * DEG) / 2);
}

/**
 * Where world point `p` lands in the image of `camera` with aspect `aspect` (width / height):
 * {x, y} in normalised device coordinates (-1..1, y up) and `depth` (metres along the view), or
 * null when the point is behind the eye. The vertical field of view is fov_deg, as the server's.
 */
export function projectPoint(camera, aspect, p) {
    const { eye, forward, right, up } = viewBasis(camera);
    const d = sub(p, eye);
    const depth = dot(d, forward);
    if (depth <= NEAR) return null;
    const t = tanHalfFov(camera);
    return { x: dot(d, right) / (depth * t * aspect), y: dot(d, up) / (depth * t), depth };
}

/**
 * The world displacement in the plane `depth` metres in front of the eye that matches a drag of
 * (dx, dy) pixels (y down, as pointer events) on an image `viewHeight` pixels tall: a point
 * dragged this way stays under the cursor.
 */
export function dragToWorld(camera, depth, dx, dy, viewHeight) {
    const { right, up } = viewBasis(camera);
    const metresPerPixel = (2 * Math.max(depth, NEAR) * tanHalfFov(camera)) / Math.max(viewHeight, 1);
    return add(scale(right, dx * metresPerPixel), scale(up, -dy * metresPerPixel));
}

/** A light position dragged by (dx, dy) pixels: it moves parallel to the image, following the cursor. */
export function moveLight(position, camera, dx, dy, viewHeight) {
    const depth = dot(sub(position, camera.position), viewBasis(camera).forward);
    // Behind the eye there is no cursor to follow; use the target's depth so the drag still moves it.
    const usable = depth > NEAR ? depth : length(sub(camera.target, camera.position));
    return roundVec(add(position, dragToWorld(camera, usable, dx, dy, viewHeight)));
}

/**
 * A light direction turned by a drag of (dx, dy) pixels (Ctrl-drag): the end of the beam (the
 * gizmo's aim handle) follows the cursor in the plane parallel to the image, so dragging right
 * turns the beam to the right as seen from the camera, whichever way it points (no poles).
 * `light` needs a direction (and a position, else the orbit target anchors it); the result is a
 * unit vector rounded for the message.
 */
export function aimLight(light, camera, dx, dy, viewHeight) {
    const anchor = gizmoAnchor(light, camera);
    const tip = add(anchor, scale(normalize(light.direction), aimHandleLength(camera, anchor)));
    let depth = dot(sub(tip, camera.position), viewBasis(camera).forward);
    if (depth <= NEAR) depth = length(sub(camera.target, camera.position));
    return aimAt(anchor, add(tip, dragToWorld(camera, depth, dx, dy, viewHeight)));
}

/** A unit direction whose rounded components stay within the light schema's [-1, 1] and not all zero. */
export function safeDirection(d) {
    const n = normalize(d);
    if (length(n) === 0) return [0, -1, 0];
    const r = roundVec(n).map((v) => clamp(v, -1, 1));
    return length(r) > 0 ? r : [0, -1, 0];
}

/** The direction from the light at `position` to the point `tip` (the gizmo's aim handle). */
export function aimAt(position, tip) {
    return safeDirection(sub(tip, position));
}

/** Length of the gizmo's aim line in metres: a fraction of the eye's distance to the light. */
export function aimHandleLength(camera, position) {
    return 0.25 * Math.max(0.05, length(sub(position, camera.position)));
}

/**
 * Which gizmo handles a light has: a point light shines every way, so it only moves; a directional
 * light is everywhere at once, so it only turns; a spot does both. A light without a type is
 * protocol 1's spotlight.
 */
export function gizmoKinds(light) {
    const type = light?.type ?? 'spot';
    return { move: type !== 'directional', aim: type !== 'point' };
}

/** The handles' tooltips, by light type. */
export function gizmoLabels(light) {
    switch (light?.type ?? 'spot') {
    case 'point': return { move: 'point light: drag to move it', aim: '' };
    case 'directional': return { move: '', aim: 'directional light: drag to turn the direction it shines in' };
    default: return { move: 'spotlight: drag to move it', aim: 'spotlight aim: drag to point the beam' };
    }
}

/**
 * Where the gizmo sits: the light's position. A directional light's position means nothing to the
 * renderer; the server fills it with a point in the scene, and without one the orbit target keeps
 * the aim handle in view.
 */
export function gizmoAnchor(light, camera) {
    if (Array.isArray(light?.position) && light.position.length === 3) return light.position;
    return camera.target;
}

/** The gizmo's handles in normalised device coordinates (null where behind the eye or not shown). */
export function gizmoHandles(camera, aspect, light) {
    const kinds = gizmoKinds(light);
    const anchor = gizmoAnchor(light, camera);
    const tipWorld = kinds.aim && light.direction
        ? add(anchor, scale(normalize(light.direction), aimHandleLength(camera, anchor)))
        : null;
    return {
        anchor,
        anchorPoint: projectPoint(camera, aspect, anchor),
        origin: kinds.move ? projectPoint(camera, aspect, anchor) : null,
        tip: tipWorld ? projectPoint(camera, aspect, tipWorld) : null,
        tipWorld,
    };
}

/**
 * The rectangle the frame occupies inside a box of boxW x boxH CSS pixels when scaled to fit with
 * its aspect kept (CSS object-fit: contain): {left, top, width, height}.
 */
export function containRect(boxW, boxH, imageW, imageH) {
    if (!(imageW > 0 && imageH > 0 && boxW > 0 && boxH > 0)) return { left: 0, top: 0, width: boxW, height: boxH };
    const s = Math.min(boxW / imageW, boxH / imageH);
    const width = imageW * s;
    const height = imageH * s;
    return { left: (boxW - width) / 2, top: (boxH - height) / 2, width, height };
}
