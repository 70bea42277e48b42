// Carrying a session over to a new one. When the server restarts (resume_failed) or drains
// (shutdown), the new session starts from the server's defaults although the page still knows
// the scene, technique, explicit parameters, lights and camera the user had: they are sent again
// with ordinary messages, as PROTOCOL.md's shutdown section asks of clients. Pure.

import { requestLight } from './lights.js';
import {
    cameraMsg, lightAddMsg, lightMsg, lightRemoveMsg, paramsMsg, techniqueMsg, validateParamValues,
} from './protocol.js';

/**
 * What the page knew of a session: {scene, technique, params (the explicit values only), camera,
 * adaptive, lights (protocol 2's list with ids, or undefined)}. `explicit` names the parameters the
 * user set.
 */
export function sessionSnapshot({ scene, technique, params = {}, explicit = new Set(), camera, adaptive, lights }) {
    const own = Object.fromEntries([...explicit].filter((k) => Object.hasOwn(params, k)).map((k) => [k, params[k]]));
    return structuredClone({ scene, technique, params: own, camera, adaptive, lights });
}

/**
 * The light messages that turn the new session's `current` lights into the `saved` ones (both
 * lists with ids, the same scene): light_remove for lights the user removed, light with the fields
 * that differ for lights both have, light_add for lights the user added (the server gives them new
 * ids). Ids are the scene's own, so a light keeps its id across sessions unless the user added it.
 */
export function lightRestoreMessages(saved, current) {
    const savedIds = new Set(saved.map((l) => l.id));
    const byId = new Map(current.map((l) => [l.id, l]));
    const out = current.filter((l) => !savedIds.has(l.id)).map((l) => lightRemoveMsg(l.id));
    for (const light of saved) {
        const want = requestLight(light);
        const now = byId.get(light.id);
        if (!now) {
            const { id, ...fields } = want; // the server gives an added light its own id
            out.push(lightAddMsg(fields));
            continue;
        }
        const have = requestLight(now);
        const changed = Object.fromEntries(Object.entries(want)
            .filter(([k, v]) => JSON.stringify(v) !== JSON.stringify(have[k])));
        if (Object.keys(changed).length > 0) out.push(lightMsg(changed, light.id));
    }
    return out;
}

/**
 * How to bring the new session of `welcome` to `saved`: {scene (to load first, or null), technique
 * (or null), params (valid under the new session's schemas), lights (light messages, see
 * lightRestoreMessages; empty when nothing changed, when the scene is loaded first, or when it could
 * not be restored), camera (null
 * when the scene could not be restored: the old camera belongs to the old scene), adaptive (or null
 * when unchanged), notes (what could not be restored, as sentences)}. Null without a snapshot.
 */
export function restorePlan(saved, welcome) {
    if (!saved) return null;
    const s = welcome?.state ?? {};
    const notes = [];
    let scene = null;
    let sameScene = !saved.scene || saved.scene === s.scene;
    if (!sameScene) {
        if ((welcome?.scenes ?? []).includes(saved.scene)) {
            scene = saved.scene;
            sameScene = true;
        } else if (saved.scene.startsWith('upload:')) {
            notes.push(`${saved.scene.slice('upload:'.length)} was deleted with the old session: upload it again`);
        } else {
            notes.push(`the server no longer offers ${saved.scene}`);
        }
    }
    const techniques = new Map((welcome?.techniques ?? []).map((t) => [t.name, t]));
    let technique = null;
    if (saved.technique && saved.technique !== s.technique) {
        if (techniques.has(saved.technique)) technique = saved.technique;
        else notes.push(`the server no longer offers the technique ${saved.technique}`);
    }
    const schema = techniques.get(technique ?? s.technique)?.params_schema;
    const params = {};
    for (const [k, v] of Object.entries(saved.params ?? {})) {
        if (validateParamValues({ [k]: v }, schema, welcome?.frame_params_schema) === null) params[k] = v;
        else notes.push(`${k} = ${JSON.stringify(v)} is not a parameter of the new session`);
    }
    const adaptive = typeof saved.adaptive === 'boolean' && saved.adaptive !== (welcome?.adaptive !== false)
        ? saved.adaptive : null;
    // The lights, against the new session's when it shows the saved scene already; a scene loaded
    // first has lights of its own only once its state arrives (main.js diffs them then).
    let lights = [];
    if (sameScene && scene === null && Array.isArray(saved.lights)) {
        if (Array.isArray(s.lights)) lights = lightRestoreMessages(saved.lights, s.lights);
        else notes.push('the lights (this server does not list them)');
    }
    return {
        scene, technique, params, lights, camera: sameScene && saved.camera ? saved.camera : null, adaptive, notes,
    };
}

/** The messages that follow the scene (once it has loaded): technique, parameters, lights, camera. */
export function restoreMessages(plan) {
    if (!plan) return [];
    const out = [];
    if (plan.technique) out.push(techniqueMsg(plan.technique));
    if (Object.keys(plan.params).length > 0) out.push(paramsMsg(plan.params));
    out.push(...(plan.lights ?? []));
    if (plan.camera) out.push(cameraMsg(plan.camera));
    return out;
}
