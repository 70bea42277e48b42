// Orbit camera: yaw/pitch/distance around a target, world +Y up (the built-in scenes' convention).
// yaw = 0, pitch = 0 looks down -Z from +Z, the way the Cornell box's welcome camera does.
// The math is pure; attachOrbitControls() binds it to pointer and wheel events.

const DEG = Math.PI / 180;
// Keep the eye off the poles: at exactly +-90 degrees the look-at basis with up = +Y degenerates.
export const MAX_PITCH = 89 * DEG;
export const MIN_DISTANCE = 0.05;
export const MAX_DISTANCE = 1e5;
const ORBIT_RADIANS_PER_PIXEL = 0.005;
const ZOOM_PER_WHEEL_UNIT = 0.001;

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const length = (a) => Math.hypot(a[0], a[1], a[2]);
const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));

/** Position of an eye at {yaw, pitch, distance} (radians, metres) around `target`. */
export function positionFromOrbit({ yaw, pitch, distance }, target) {
    const c = Math.cos(pitch);
    return add(target, [distance * c * Math.sin(yaw), distance * Math.sin(pitch), distance * c * Math.cos(yaw)]);
}

/** The inverse of positionFromOrbit: {yaw, pitch, distance} of `position` around `target`. */
export function orbitFromPosition(position, target) {
    const d = sub(position, target);
    const distance = length(d);
    if (distance === 0) return { yaw: 0, pitch: 0, distance: 0 };
    return {
        yaw: Math.atan2(d[0], d[2]),
        pitch: Math.asin(clamp(d[1] / distance, -1, 1)),
        distance,
    };
}

/** Camera right and up unit vectors in world space for an eye at `yaw`/`pitch`. */
export function cameraBasis(yaw, pitch) {
    const right = [Math.cos(yaw), 0, -Math.sin(yaw)];
    const up = [-Math.sin(pitch) * Math.sin(yaw), Math.cos(pitch), -Math.sin(pitch) * Math.cos(yaw)];
    return { right, up };
}

export class OrbitCamera {
    /** `camera` is a protocol camera: {position, target, up?, fov_deg?}. */
    constructor(camera = { position: [0, 1, 3.9], target: [0, 1, 0], fov_deg: 40 }) {
        this.home = structuredClone(camera);
        this.set(camera);
    }

    /** Adopts a protocol camera (welcome.state.camera); the up vector is taken to be +Y. */
    set(camera) {
        this.target = [...camera.target];
        this.fovDeg = camera.fov_deg ?? this.fovDeg ?? 40;
        const o = orbitFromPosition(camera.position, camera.target);
        this.yaw = o.yaw;
        this.pitch = clamp(o.pitch, -MAX_PITCH, MAX_PITCH);
        this.distance = clamp(o.distance, MIN_DISTANCE, MAX_DISTANCE);
    }

    /** Makes `camera` the one reset() goes back to, and adopts it. */
    setHome(camera) {
        this.home = structuredClone(camera);
        this.set(camera);
    }

    reset() {
        this.set(this.home);
    }

    get position() {
        return positionFromOrbit(this, this.target);
    }

    /** Drag by (dx, dy) pixels: the scene follows the cursor, as if grabbed (dragging down looks from above). */
    orbit(dx, dy) {
        this.yaw -= dx * ORBIT_RADIANS_PER_PIXEL;
        this.pitch = clamp(this.pitch + dy * ORBIT_RADIANS_PER_PIXEL, -MAX_PITCH, MAX_PITCH);
    }

    /** Wheel by `delta` units (deltaY); positive moves away. Exponential, so it feels the same at any distance. */
    zoom(delta) {
        this.distance = clamp(this.distance * Math.exp(delta * ZOOM_PER_WHEEL_UNIT), MIN_DISTANCE, MAX_DISTANCE);
    }

    /**
     * Moves target and eye together so the point under the cursor follows it: a drag of
     * (dx, dy) pixels on a view `viewHeight` pixels tall.
     */
    pan(dx, dy, viewHeight) {
        const metresPerPixel = (2 * this.distance * Math.tan((this.fovDeg * DEG) / 2)) / Math.max(viewHeight, 1);
        const { right, up } = cameraBasis(this.yaw, this.pitch);
        const move = add(scale(right, -dx * metresPerPixel), scale(up, dy * metresPerPixel));
        this.target = add(this.target, move);
    }

    /** The protocol camera for a `camera` message. */
    toCamera() {
        const round = (v) => Math.round(v * 1e5) / 1e5;
        return {
            position: this.position.map(round),
            target: this.target.map(round),
            up: [0, 1, 0],
            fov_deg: this.fovDeg,
        };
    }
}

/**
 * Binds mouse/touch input on `element` to `camera`: left drag orbits, shift-drag or right-drag
 * pans, the wheel or a two-finger pinch zooms. `onChange()` runs after every change.
 * Returns a function that removes the listeners.
 */
export function attachOrbitControls(element, camera, onChange) {
    const pointers = new Map(); // pointerId -> {x, y}
    let pinchDistance = 0;

    const pinchSpan = () => {
        const [a, b] = [...pointers.values()];
        return Math.hypot(a.x - b.x, a.y - b.y);
    };

    const onPointerDown = (e) => {
        element.setPointerCapture(e.pointerId);
        pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, button: e.button });
        if (pointers.size === 2) pinchDistance = pinchSpan();
    };

    const onPointerMove = (e) => {
        const p = pointers.get(e.pointerId);
        if (!p) return;
        const dx = e.clientX - p.x;
        const dy = e.clientY - p.y;
        p.x = e.clientX;
        p.y = e.clientY;
        if (pointers.size === 2) {
            const span = pinchSpan();
            if (pinchDistance > 0 && span > 0) camera.zoom(-Math.log(span / pinchDistance) / ZOOM_PER_WHEEL_UNIT);
            pinchDistance = span;
        } else if (e.shiftKey || p.button === 2 || p.button === 1) {
            camera.pan(dx, dy, element.clientHeight);
        } else {
            camera.orbit(dx, dy);
        }
        onChange();
    };

    const onPointerUp = (e) => {
        pointers.delete(e.pointerId);
        pinchDistance = 0;
    };

    const onWheel = (e) => {
        e.preventDefault();
        // deltaMode 1 counts lines, 2 pages; bring both to roughly pixels.
        const unit = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
        camera.zoom(e.deltaY * unit);
        onChange();
    };

    const onContextMenu = (e) => e.preventDefault();

    element.addEventListener('pointerdown', onPointerDown);
    element.addEventListener('pointermove', onPointerMove);
    element.addEventListener('pointerup', onPointerUp);
    element.addEventListener('pointercancel', onPointerUp);
    element.addEventListener('wheel', onWheel, { passive: false });
    element.addEventListener('contextmenu', onContextMenu);
    return () => {
        element.removeEventListener('pointerdown', onPointerDown);
        element.removeEventListener('pointermove', onPointerMove);
        element.removeEventListener('pointerup', onPointerUp);
        element.removeEventListener('pointercancel', onPointerUp);
        element.removeEventListener('wheel', onWheel);
        element.removeEventListener('contextmenu', onContextMenu);
    };
}
