// The eye camera: orbit, pan, zoom and fly around a target, world +Y up (the built-in scenes'
// convention). yaw = 0, pitch = 0 looks down -Z from +Z, the way the Cornell box's welcome camera
// does. The math is pure; attachViewControls() binds it (and the light drags) to pointer, wheel,
// touch and keyboard input.

import { add, clamp, cross, dot, length, normalize, roundVec, scale, sub } from './vec.js';

const DEG = Math.PI / 180;
// Keep the eye off the poles: at exactly +-90 degrees the look-at basis with up = +Y degenerates.
export const MAX_PITCH = 89 * DEG;
export const MIN_DISTANCE = 0.05;
export const MAX_DISTANCE = 1e5;
export const MIN_FOV_DEG = 1;
export const MAX_FOV_DEG = 170;
const ORBIT_RADIANS_PER_PIXEL = 0.005;
const LOOK_RADIANS_PER_PIXEL = 0.003;
const ZOOM_PER_WHEEL_UNIT = 0.001;
const ZOOM_UNITS_PER_DRAG_PIXEL = 5;

/** What a one-finger or left-button drag does, picked in the Camera section. */
export const DRAG_TOOLS = Object.freeze(['orbit', 'pan', 'zoom', 'fly', 'light-aim', 'light-move']);

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

/**
 * The bounding sphere of `state.bounds` ({min, max} in metres): {centre, radius}, or null when
 * the bounds are missing or malformed.
 */
export function boundsSphere(bounds) {
    const { min, max } = bounds ?? {};
    const ok = (v) => Array.isArray(v) && v.length === 3 && v.every(Number.isFinite);
    if (!ok(min) || !ok(max) || min.some((v, i) => v > max[i])) return null;
    return { centre: scale(add(min, max), 0.5), radius: length(sub(max, min)) / 2 };
}

/**
 * The eye distance at which a sphere of `radius` fits a view of vertical field `fovDeg` and
 * width/height `aspect`: the narrower of the two fields decides.
 */
export function fitDistance(radius, fovDeg, aspect = 1) {
    const half = (clamp(fovDeg, MIN_FOV_DEG, MAX_FOV_DEG) * DEG) / 2;
    const halfH = Math.atan(Math.tan(half) * (aspect > 0 ? aspect : 1));
    return clamp(Math.max(radius, MIN_DISTANCE) / Math.sin(Math.min(half, halfH)), MIN_DISTANCE, MAX_DISTANCE);
}

/**
 * `camera` with its orbit target moved along the view ray to the depth of the bounds' centre, so
 * that orbiting turns around the model instead of a point a metre ahead of the eye (what a glTF
 * camera's look-at gives). The view is unchanged. Without usable bounds, or with the model behind
 * the eye, the camera is returned as it is.
 */
export function withOrbitTarget(camera, bounds) {
    const sphere = boundsSphere(bounds);
    if (!sphere || !camera?.position || !camera?.target) return camera;
    const forward = normalize(sub(camera.target, camera.position));
    const depth = dot(sub(sphere.centre, camera.position), forward);
    if (!(length(forward) > 0) || !(depth > MIN_DISTANCE)) return camera;
    return { ...structuredClone(camera), target: roundVec(add(camera.position, scale(forward, depth))) };
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
        this.fovDeg = clamp(camera.fov_deg ?? this.fovDeg ?? 40, MIN_FOV_DEG, MAX_FOV_DEG);
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

    /** A length that fits the scene: the home camera's distance to its target (fly speed, gizmo size). */
    get sceneScale() {
        return Math.max(MIN_DISTANCE, length(sub(this.home.position, this.home.target)));
    }

    get position() {
        return positionFromOrbit(this, this.target);
    }

    /** Unit vector from the eye towards the target. */
    get forward() {
        return normalize(sub(this.target, this.position));
    }

    /** Drag by (dx, dy) pixels: the scene follows the cursor, as if grabbed (dragging down looks from above). */
    orbit(dx, dy) {
        this.yaw -= dx * ORBIT_RADIANS_PER_PIXEL;
        this.pitch = clamp(this.pitch + dy * ORBIT_RADIANS_PER_PIXEL, -MAX_PITCH, MAX_PITCH);
    }

    /**
     * Fly mode's mouse look: the eye stays, the view turns (drag right looks right, drag down looks
     * down); the target moves with the view at the same distance.
     */
    look(dx, dy) {
        const eye = this.position;
        this.yaw -= dx * LOOK_RADIANS_PER_PIXEL;
        this.pitch = clamp(this.pitch + dy * LOOK_RADIANS_PER_PIXEL, -MAX_PITCH, MAX_PITCH);
        this.target = sub(eye, positionFromOrbit(this, [0, 0, 0]));
    }

    /** Wheel by `delta` units (deltaY); positive moves away. Exponential, so it feels the same at any distance. */
    zoom(delta) {
        this.distance = clamp(this.distance * Math.exp(delta * ZOOM_PER_WHEEL_UNIT), MIN_DISTANCE, MAX_DISTANCE);
    }

    /** Zoom by a vertical drag of `dy` pixels (down moves away). */
    zoomDrag(dy) {
        this.zoom(dy * ZOOM_UNITS_PER_DRAG_PIXEL);
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

    /** Fly: moves eye and target by `forward` metres along the view, `right` to the side and `up` along world +Y. */
    move(forward, right, up) {
        const f = this.forward;
        const r = normalize(cross(f, [0, 1, 0]));
        const step = add(add(scale(f, forward), scale(r, right)), [0, up, 0]);
        this.target = add(this.target, step);
    }

    setFov(deg) {
        this.fovDeg = clamp(deg, MIN_FOV_DEG, MAX_FOV_DEG);
    }

    /**
     * Frames the model: the target goes to the centre of `bounds`, the eye back along the current
     * view direction until the bounding sphere fits both fields of view (`aspect` = width/height).
     * Returns false (and changes nothing) without usable bounds.
     */
    frame(bounds, aspect = 1) {
        const sphere = boundsSphere(bounds);
        if (!sphere) return false;
        this.target = [...sphere.centre];
        this.distance = fitDistance(sphere.radius, this.fovDeg, aspect);
        return true;
    }

    /** The protocol camera for a `camera` message. */
    toCamera() {
        return {
            position: roundVec(this.position),
            target: roundVec(this.target),
            up: [0, 1, 0],
            fov_deg: Math.round(this.fovDeg * 1000) / 1000,
        };
    }
}

/**
 * What a drag does: Ctrl (or Cmd) aims the light, Ctrl+Shift moves it; Shift, the right or the
 * middle button pan; otherwise the drag tool picked in the Camera section ('fly' drags look around).
 */
export function gestureFor({ ctrlKey = false, metaKey = false, shiftKey = false, button = 0 }, tool) {
    if (ctrlKey || metaKey) return shiftKey ? 'light-move' : 'light-aim';
    if (shiftKey || button === 1 || button === 2) return 'pan';
    if (tool === 'fly') return 'look';
    return DRAG_TOOLS.includes(tool) ? tool : 'orbit';
}

/** Key codes (KeyboardEvent.code, so WASD stays where it is on any layout) the view reacts to. */
export const MOTION_KEYS = Object.freeze(new Set([
    'KeyW', 'KeyA', 'KeyS', 'KeyD', 'KeyQ', 'KeyE', 'ArrowLeft', 'ArrowRight', 'ArrowUp', 'ArrowDown',
    'Equal', 'Minus', 'NumpadAdd', 'NumpadSubtract', 'PageUp', 'PageDown',
]));
const KEY_ORBIT_PIXELS_PER_S = 300;
const KEY_ZOOM_UNITS_PER_S = 800;

/**
 * The camera motion of the keys held for `dt` seconds: {move: [forward, right, up] metres,
 * turn: [dx, dy] pixels (orbit, or look in fly mode), zoom: wheel units}. W/S forward and back,
 * A/D sideways, E/Q (or PageUp/PageDown) up and down; arrows orbit (fly: look); +/- zoom; Shift
 * three times as fast. `speed` is metres per second.
 */
export function keyMotion(keys, tool, dt, speed, fast = false) {
    const held = (...codes) => (codes.some((c) => keys.has(c)) ? 1 : 0);
    const k = (fast ? 3 : 1) * dt;
    const move = [
        (held('KeyW') - held('KeyS')) * speed * k,
        (held('KeyD') - held('KeyA')) * speed * k,
        (held('KeyE', 'PageUp') - held('KeyQ', 'PageDown')) * speed * k,
    ];
    const sign = tool === 'fly' ? 1 : -1;
    // Orbit: ArrowLeft moves the eye left around the target (like dragging right); fly: looks left.
    const turn = [
        sign * (held('ArrowRight') - held('ArrowLeft')) * KEY_ORBIT_PIXELS_PER_S * k,
        (tool === 'fly' ? held('ArrowDown') - held('ArrowUp') : held('ArrowUp') - held('ArrowDown')) * KEY_ORBIT_PIXELS_PER_S * k,
    ];
    const zoom = (held('Minus', 'NumpadSubtract') - held('Equal', 'NumpadAdd')) * KEY_ZOOM_UNITS_PER_S * k;
    return { move, turn, zoom };
}

/**
 * Binds input on `element` (the frame canvas):
 * - pointer drags: gestureFor() picks orbit, pan, zoom, look (fly), or a light drag, which goes
 *   to onLight(gesture, dx, dy) instead of the camera;
 * - two fingers: pinch zooms, moving both pans;
 * - wheel: zoom (fly: moves forward and back);
 * - keys while the canvas has focus: keyMotion(), Home or R for onHome(), and the single-press
 *   `shortcuts` ({KeyboardEvent.code: fn}, e.g. fullscreen).
 * Options: {camera, getTool(), onCamera(), onLight(gesture, dx, dy), onHome(), flySpeed(), shortcuts}.
 * Returns a function that removes the listeners.
 */
export function attachViewControls(element, { camera, getTool, onCamera, onLight, onHome, flySpeed, shortcuts = {} }) {
    const pointers = new Map(); // pointerId -> {x, y, gesture}
    let pinch = null; // {span, cx, cy}
    const keys = new Set();
    let keyFrame = 0;
    let lastKeyTime = 0;
    let shiftHeld = false;

    const twoFingers = () => {
        const [a, b] = [...pointers.values()];
        return { span: Math.hypot(a.x - b.x, a.y - b.y), cx: (a.x + b.x) / 2, cy: (a.y + b.y) / 2 };
    };

    const apply = (gesture, dx, dy) => {
        switch (gesture) {
        case 'light-aim':
        case 'light-move':
            onLight?.(gesture, dx, dy);
            return;
        case 'pan': camera.pan(dx, dy, element.clientHeight); break;
        case 'zoom': camera.zoomDrag(dy); break;
        case 'look': camera.look(dx, dy); break;
        default: camera.orbit(dx, dy);
        }
        onCamera();
    };

    const onPointerDown = (e) => {
        element.focus({ preventScroll: true });
        element.setPointerCapture?.(e.pointerId);
        pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, gesture: gestureFor(e, getTool()) });
        pinch = pointers.size === 2 ? twoFingers() : null;
    };

    const onPointerMove = (e) => {
        const p = pointers.get(e.pointerId);
        if (!p) return;
        const dx = e.clientX - p.x;
        const dy = e.clientY - p.y;
        p.x = e.clientX;
        p.y = e.clientY;
        if (pointers.size === 2 && pinch) {
            const now = twoFingers();
            if (pinch.span > 0 && now.span > 0) camera.zoom(-Math.log(now.span / pinch.span) / ZOOM_PER_WHEEL_UNIT);
            camera.pan(now.cx - pinch.cx, now.cy - pinch.cy, element.clientHeight);
            pinch = now;
            onCamera();
        } else if (pointers.size === 1) {
            apply(p.gesture, dx, dy);
        }
    };

    const onPointerUp = (e) => {
        pointers.delete(e.pointerId);
        pinch = null;
    };

    const onWheel = (e) => {
        e.preventDefault();
        // deltaMode 1 counts lines, 2 pages; bring both to roughly pixels.
        const unit = e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1;
        if (getTool() === 'fly') camera.move(-e.deltaY * unit * 0.002 * camera.sceneScale, 0, 0);
        else camera.zoom(e.deltaY * unit);
        onCamera();
    };

    const keyLoop = (time) => {
        const dt = Math.min(0.1, Math.max(0, (time - lastKeyTime) / 1000));
        lastKeyTime = time;
        const tool = getTool();
        const { move, turn, zoom } = keyMotion(keys, tool, dt, flySpeed(), shiftHeld);
        if (move.some((v) => v !== 0)) camera.move(...move);
        if (turn[0] !== 0 || turn[1] !== 0) {
            if (tool === 'fly') camera.look(turn[0], turn[1]);
            else camera.orbit(turn[0], turn[1]);
        }
        if (zoom !== 0) camera.zoom(zoom);
        if (move.some((v) => v !== 0) || turn[0] !== 0 || turn[1] !== 0 || zoom !== 0) onCamera();
        keyFrame = keys.size ? requestAnimationFrame(keyLoop) : 0;
    };

    const onKeyDown = (e) => {
        shiftHeld = e.shiftKey;
        if (e.ctrlKey || e.metaKey || e.altKey) return;
        if (e.code === 'Home' || e.code === 'KeyR') {
            e.preventDefault();
            onHome?.();
            return;
        }
        if (Object.hasOwn(shortcuts, e.code)) {
            e.preventDefault();
            // Held keys repeat: a toggle such as fullscreen must not flicker.
            if (!e.repeat) shortcuts[e.code]();
            return;
        }
        if (!MOTION_KEYS.has(e.code)) return;
        e.preventDefault();
        keys.add(e.code);
        if (!keyFrame) {
            // The first step now, as one frame's motion, rather than at the next animation frame.
            const now = performance.now();
            lastKeyTime = now - 1000 / 60;
            keyLoop(now);
        }
    };

    const onKeyUp = (e) => {
        shiftHeld = e.shiftKey;
        keys.delete(e.code);
    };

    const onBlur = () => keys.clear();
    const onContextMenu = (e) => e.preventDefault();

    const listeners = [
        ['pointerdown', onPointerDown], ['pointermove', onPointerMove], ['pointerup', onPointerUp],
        ['pointercancel', onPointerUp], ['wheel', onWheel, { passive: false }], ['contextmenu', onContextMenu],
        ['keydown', onKeyDown], ['keyup', onKeyUp], ['blur', onBlur],
    ];
    for (const [type, fn, opts] of listeners) element.addEventListener(type, fn, opts);
    return () => {
        for (const [type, fn] of listeners) element.removeEventListener(type, fn);
        cancelAnimationFrame(keyFrame);
    };
}
