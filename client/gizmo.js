// The light gizmo: an SVG layer over the frame for the selected light, with a disc at its position
// (drag: move it parallel to the image) and an aim handle at the end of its beam (drag: point the
// beam there). A point light has only the disc, a directional light only the aim handle (its beam
// starts at the light's position field, or the orbit target). Drawn from the client's own camera,
// so it follows a drag at once, before the frame does.

import { aimAt, containRect, dragToWorld, gizmoHandles, gizmoKinds, gizmoLabels, moveLight } from './light.js';

const SVG = 'http://www.w3.org/2000/svg';

/** At most this long (ms) after a camera move without a frame drawn, the gizmo follows the camera. */
export const CAMERA_FOLLOW_MS = 100;

function svgElement(tag, attrs = {}) {
    const el = document.createElementNS(SVG, tag);
    for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, String(v));
    return el;
}

// What render last wrote to each element (attributes, and style properties as "style.name"): a value
// written again unchanged would still invalidate the layer's paint.
const written = new WeakMap();

function writeOnce(el, key, value, apply) {
    const text = String(value);
    const seen = written.get(el) ?? new Map();
    written.set(el, seen);
    if (seen.get(key) === text) return;
    seen.set(key, text);
    apply(text);
}

function setIfChanged(el, name, value) {
    writeOnce(el, name, value, (text) => el.setAttribute(name, text));
}

/** A screen coordinate as written: a hundredth of a CSS pixel, so rounding noise writes nothing. */
const px = (v) => v.toFixed(2);

function setStyleIfChanged(el, property, value) {
    writeOnce(el, `style.${property}`, value, (text) => {
        el.style[property] = text;
    });
}

function cssColor(rgb) {
    const c = (rgb ?? [1, 1, 1]).map((v) => Math.round(255 * Math.min(1, Math.max(0, v))));
    return `rgb(${c[0]} ${c[1]} ${c[2]})`;
}

/**
 * `svg` covers the viewport. Options: getCamera() (protocol camera), getLight() (the selected protocol light),
 * getFrameSize() ([w, h] of the frame shown), onMove(position), onAim(direction), onDragEnd().
 */
export class LightGizmo {
    constructor(svg, options) {
        this.svg = svg;
        this.options = options;
        this.visible = true;
        this.enabled = true;
        this.followTimer = 0;
        // The layer's size, kept by a ResizeObserver: reading it from layout would force a layout in
        // the middle of every frame's handler. Hidden (display: none) it has none, and is measured
        // once more when shown; a new size redraws the handles.
        this.box = null;
        if (typeof ResizeObserver === 'function') {
            new ResizeObserver(([entry]) => {
                const { width, height } = entry.contentRect;
                this.box = width > 0 && height > 0 ? { width, height } : null;
                if (this.box) this.render();
            }).observe(svg);
        }
        this.line = svgElement('line', { class: 'gizmo-beam' });
        // Where a directional light's beam starts, which has no handle of its own.
        this.anchor = svgElement('circle', { class: 'gizmo-anchor', r: 3 });
        this.origin = svgElement('circle', { class: 'gizmo-handle gizmo-origin', r: 9 });
        this.tip = svgElement('circle', { class: 'gizmo-handle gizmo-tip', r: 6 });
        this.origin.append(svgElement('title'));
        this.tip.append(svgElement('title'));
        svg.append(this.line, this.anchor, this.origin, this.tip);
        this.bindDrag(this.origin, 'move');
        this.bindDrag(this.tip, 'aim');
    }

    rect() {
        const box = this.box ?? this.svg.getBoundingClientRect();
        const [w, h] = this.options.getFrameSize();
        return containRect(box.width, box.height, w, h);
    }

    /** Screen position (CSS pixels in the svg) of a projected point. */
    static toScreen(p, rect) {
        return [rect.left + ((p.x + 1) / 2) * rect.width, rect.top + ((1 - p.y) / 2) * rect.height];
    }

    /**
     * The camera moved: redraw with the next frame drawn (whose handler calls render), or after
     * CAMERA_FOLLOW_MS if no frame comes (a slow server, a lost connection).
     */
    followCamera() {
        if (this.followTimer) return;
        this.followTimer = setTimeout(() => {
            this.followTimer = 0;
            this.render();
        }, CAMERA_FOLLOW_MS);
    }

    render() {
        clearTimeout(this.followTimer);
        this.followTimer = 0;
        const camera = this.options.getCamera();
        const light = this.options.getLight();
        const kinds = gizmoKinds(light);
        const show = Boolean(this.visible && this.enabled && camera && light
            && (!kinds.move || light.position) && (!kinds.aim || light.direction));
        if (this.svg.classList.contains('hidden') === show) this.svg.classList.toggle('hidden', !show);
        if (!show) return;
        const type = light.type ?? 'spot';
        if (this.svg.dataset.lightType !== type) this.svg.dataset.lightType = type;
        const labels = gizmoLabels(light);
        if (this.origin.firstChild.textContent !== labels.move) this.origin.firstChild.textContent = labels.move;
        if (this.tip.firstChild.textContent !== labels.aim) this.tip.firstChild.textContent = labels.aim;
        const rect = this.rect();
        const { anchorPoint, origin, tip } = gizmoHandles(camera, rect.width / Math.max(1, rect.height), light);
        const place = (el, p) => {
            setStyleIfChanged(el, 'display', p ? '' : 'none');
            if (!p) return null;
            const [x, y] = LightGizmo.toScreen(p, rect);
            setIfChanged(el, 'cx', px(x));
            setIfChanged(el, 'cy', px(y));
            return [x, y];
        };
        const originAt = place(this.origin, origin);
        const anchorAt = place(this.anchor, kinds.move ? null : anchorPoint);
        const a = originAt ?? anchorAt;
        const b = place(this.tip, tip);
        setStyleIfChanged(this.line, 'display', a && b ? '' : 'none');
        if (a && b) {
            setIfChanged(this.line, 'x1', px(a[0]));
            setIfChanged(this.line, 'y1', px(a[1]));
            setIfChanged(this.line, 'x2', px(b[0]));
            setIfChanged(this.line, 'y2', px(b[1]));
        }
        const color = cssColor(light.color);
        setStyleIfChanged(this.origin, 'fill', light.enabled === false ? 'transparent' : color);
        setStyleIfChanged(this.anchor, 'fill', color);
        setStyleIfChanged(this.line, 'stroke', color);
    }

    bindDrag(handle, kind) {
        let start = null;
        handle.addEventListener('pointerdown', (e) => {
            e.stopPropagation();
            e.preventDefault();
            handle.setPointerCapture?.(e.pointerId);
            const camera = this.options.getCamera();
            const light = this.options.getLight();
            const rect = this.rect();
            const handles = gizmoHandles(camera, rect.width / Math.max(1, rect.height), light);
            start = { x: e.clientX, y: e.clientY, camera, rect, position: [...handles.anchor], handles };
            handle.classList.add('dragging');
        });
        handle.addEventListener('pointermove', (e) => {
            if (!start) return;
            const dx = e.clientX - start.x;
            const dy = e.clientY - start.y;
            if (kind === 'move') {
                this.options.onMove(moveLight(start.position, start.camera, dx, dy, start.rect.height));
            } else if (start.handles.tip) {
                const delta = dragToWorld(start.camera, start.handles.tip.depth, dx, dy, start.rect.height);
                const tip = start.handles.tipWorld.map((v, i) => v + delta[i]);
                this.options.onAim(aimAt(start.position, tip));
            }
        });
        const end = () => {
            if (!start) return;
            start = null;
            handle.classList.remove('dragging');
            this.options.onDragEnd?.();
        };
        handle.addEventListener('pointerup', end);
        handle.addEventListener('pointercancel', end);
    }
}
