// The session's lights as a list (state.lights, protocol 2): which light the panel edits after the
// server sends a new list, where a light added from the current view goes, local edits that follow
// the server's rules, and what a frame's stats.lighting says about each light. Pure functions on
// protocol lights ({id, name, type, position, direction, intensity, ...}) so node's tests load them.

import { add, clamp, length, normalize, roundVec, scale, sub } from './vec.js';

export const LIGHT_TYPES = Object.freeze(['spot', 'point', 'directional']);

// Fields of a light that render_request.json accepts; anything else the state carries would make
// the accuracy request invalid.
const REQUEST_LIGHT_FIELDS = ['id', 'name', 'type', 'position', 'direction', 'intensity', 'color', 'range',
    'cone_deg', 'inner_cone_deg', 'enabled'];

/** A protocol-1 light has no type: it is the spotlight. */
export function lightType(light) {
    return LIGHT_TYPES.includes(light?.type) ? light.type : 'spot';
}

/** What the panel calls a light: its name, else its id, else its type. */
export function lightLabel(light) {
    return light?.name || light?.id || `${lightType(light)} light`;
}

/** The unit of `intensity`: a directional light's is illuminance, the others' luminous intensity. */
export function intensityUnit(light) {
    return lightType(light) === 'directional' ? 'lux' : 'cd';
}

/**
 * The lights of a session state: `lights` (protocol 2) or the single `light` of protocol 1, deep
 * copies. Returns null when the state says nothing about lights.
 */
export function lightsOfState(s) {
    if (Array.isArray(s?.lights)) return structuredClone(s.lights);
    if (s?.light) return [structuredClone(s.light)];
    if (s && 'light' in s) return [];
    return null;
}

/**
 * The id the panel edits after a new light list arrives: the light that appeared when one was just
 * added (`expectAdded`), else the one selected before if it is still there, else the first.
 */
export function pickSelection(previousIds, lights, selectedId, { expectAdded = false } = {}) {
    const ids = lights.map((l) => l.id ?? null);
    if (expectAdded) {
        const before = new Set(previousIds);
        const added = ids.find((id) => id !== null && !before.has(id));
        if (added !== undefined) return added;
    }
    if (selectedId !== null && ids.includes(selectedId)) return selectedId;
    return ids.length ? ids[0] : null;
}

/**
 * `light` with `changes` applied as the server applies them: a new outer cone keeps the inner
 * cone's proportion unless the changes set the inner cone too (server/frame/StateJson.cpp), so the
 * local copy never holds an inner cone wider than the outer one. Returns a new object.
 */
export function applyLightChanges(light, changes) {
    const next = { ...light, ...structuredClone(changes) };
    if (changes.cone_deg !== undefined && changes.inner_cone_deg === undefined
        && Number.isFinite(light.inner_cone_deg) && light.cone_deg > 0) {
        const ratio = clamp(light.inner_cone_deg / light.cone_deg, 0, 0.99);
        next.inner_cone_deg = ratio * changes.cone_deg;
    }
    return next;
}

/** Illuminance (lux) that `light` gives at `point`, ignoring cones and shadows. */
function illuminanceAt(light, point) {
    const intensity = Number.isFinite(light?.intensity) ? light.intensity : 0;
    if (lightType(light) === 'directional') return intensity;
    if (!light?.position) return 0;
    const d = Math.max(0.05, length(sub(light.position, point)));
    return intensity / (d * d);
}

const roundIntensity = (v) => Math.round(clamp(v, 0.01, 1e6) * 1000) / 1000;

/**
 * A light of `type` for a light_add message, placed from the orbit `camera` ({position, target}):
 * a point light a little above the target, a directional light shining along the view (tilted
 * down), a spot between the eye and the target aimed at it. Its intensity makes it light the target
 * about as brightly as `reference` (the light the user is looking at) does, so a new light is
 * neither invisible nor blinding whatever the scene's scale.
 */
export function newLightFor(type, camera, reference = null) {
    const target = camera.target;
    const toEye = sub(camera.position, target);
    const distance = Math.max(0.05, length(toEye));
    const forward = normalize(scale(toEye, -1));
    const above = add(target, [0, 0.15 * distance, 0]);
    const lux = illuminanceAt(reference, target) > 0 ? illuminanceAt(reference, target) : 2;
    if (type === 'point') {
        const position = roundVec(above);
        return { type, position, intensity: roundIntensity(lux * (0.15 * distance) ** 2), color: [1, 1, 1] };
    }
    if (type === 'directional') {
        // Along the view and somewhat down, as from over the viewer's shoulder: straight along the
        // view its aim handle would sit on top of its anchor, and it would light no floor. The
        // position only anchors the gizmo: a directional light has none of its own.
        const direction = safeUnit(add(forward, [0, -0.5, 0]));
        return { type, position: roundVec(target), direction, intensity: roundIntensity(lux), color: [1, 1, 1] };
    }
    const position = roundVec(add(add(target, scale(toEye, 0.5)), [0, 0.15 * distance, 0]));
    const reach = length(sub(target, position));
    return { type: 'spot', position, direction: safeUnit(sub(target, position)),
        intensity: roundIntensity(lux * reach * reach), color: [1, 1, 1], cone_deg: 30 };
}

function safeUnit(v) {
    const n = roundVec(normalize(v)).map((x) => clamp(x, -1, 1));
    return length(n) > 0 ? n : [0, -1, 0];
}

/** The light as render_request.json's `lights` items want it: known fields only, a type always. */
export function requestLight(light) {
    const out = {};
    for (const key of REQUEST_LIGHT_FIELDS) {
        if (light[key] !== undefined && light[key] !== null) out[key] = structuredClone(light[key]);
    }
    out.type = lightType(light);
    if (typeof out.name === 'string' && out.name.length > 200) out.name = out.name.slice(0, 200);
    // The server refuses an inner cone that is not narrower than the outer one; without it the
    // server keeps the scene's proportion.
    if (!(out.inner_cone_deg < out.cone_deg)) delete out.inner_cone_deg;
    return out;
}

/**
 * Per light of `lights`, what the frame's stats.lighting says: {id, rendered (true, false, or null
 * when the frame does not say: no stats, or a frame rendered before the light was added), reason
 * (why it was skipped), views}.
 */
export function lightStatuses(lights, lighting) {
    const rendered = Array.isArray(lighting?.rendered) ? lighting.rendered : null;
    const skipped = Array.isArray(lighting?.skipped) ? lighting.skipped.map(String) : [];
    return lights.map((light) => {
        const id = light.id ?? null;
        if (!rendered || id === null) return { id, rendered: null, reason: null, views: null };
        const hit = rendered.find((r) => r.id === id);
        if (hit) return { id, rendered: true, reason: null, views: hit.views ?? null };
        // "light 'NAME' (ID): REASON": the id in parentheses is unique where the name may not be.
        const marker = `(${id}): `;
        const line = skipped.find((s) => s.includes(marker));
        if (!line) return { id, rendered: null, reason: null, views: null };
        return { id, rendered: false, reason: line.slice(line.indexOf(marker) + marker.length), views: 0 };
    });
}

/** An EV value as the server writes it: signed, one decimal ("+1.5 EV", "-10.9 EV"). */
export function formatEv(ev) {
    const r = Math.round(ev * 10) / 10;
    return `${r >= 0 ? '+' : '-'}${Math.abs(r).toFixed(1)} EV`;
}

/** The sentences the Light section shows for a frame's stats.lighting (or a state's lighting). */
export function lightingLines(lighting) {
    if (!lighting) return [];
    const lines = [];
    if (lighting.note) {
        const from = { scene: 'Lights from the scene', default: 'Default lighting', request: 'Lights from the request' };
        lines.push({ kind: 'note', text: `${from[lighting.source] ?? 'Lighting'}: ${lighting.note}` });
    }
    const exposure = lighting.exposure;
    if (exposure && typeof exposure.note === 'string') {
        // The base the exposure parameter adds to: a file's lamps metered, or the scene's own.
        const ev = Number(exposure.ev), base = Number(exposure.base_ev);
        const added = Number.isFinite(ev) && Number.isFinite(base) && Math.abs(ev - base) > 1e-9
            ? `; with exposure ${formatEv(ev - base)}: ${formatEv(ev)}` : '';
        lines.push({ kind: 'note', text: `Exposure: ${exposure.note}${added}` });
    }
    if (lighting.warning) lines.push({ kind: 'warning', text: lighting.warning });
    for (const s of Array.isArray(lighting.skipped) ? lighting.skipped : []) {
        lines.push({ kind: 'skipped', text: `not rendered: ${s}` });
    }
    return lines;
}
