// Sending: every message validated as the server would before it leaves (an invalid one is shown,
// never sent), steering counted as input, and the outbox that merges what pointer moves and slider
// drags change into one message of each kind per animation frame (camera, each light, parameters);
// the viewport, hello and quality messages. Emits viewport, camera, lights and params.
import { budgetViewport, frameTargetSupported } from './budget.js';
import { applyLightChanges, newLightFor } from './lights.js';
import {
    cameraMsg, CLIENT_NAME, helloMsg, lightAddMsg, lightMsg, lightRemoveMsg, paramsMsg, qualityMsg, resizeMsg,
    validateClientMessage, validateParamValues,
} from './protocol.js';
import { CLIENT_SCHEMAS } from './schemas.js';
import { DEFAULT_FRAME_TARGET_MS } from './progress.js';

/**
 * `connection` sends; `sentLog` keeps the last messages for the console hook; `renderGizmo` redraws
 * the light gizmo now (a light change) and `followCamera` with the next frame (a camera move,
 * gizmo.js); `hello` has the page's fixed hello fields ({codecs, maxInFlight, token, view,
 * resumeKey}).
 */
export function createOutbox({ ui, state, settings, store, camera, connection, latency, watch, sentLog, showMessage,
    renderGizmo, followCamera, hello }) {
    const { codecs: CODECS, maxInFlight: MAX_IN_FLIGHT, resumeKey: RESUME_KEY, page } = hello;

    /** Validates like the server would and sends; an invalid message is shown, never sent. */
    function send(msg) {
        const problem = validateClientMessage(msg, CLIENT_SCHEMAS);
        if (problem) {
            showMessage(`Not sent (${problem.code}): ${problem.where || '/'}: ${problem.message}`);
            return false;
        }
        const sent = connection.send(msg);
        if (sent && msg.type !== 'camera' && msg.type !== 'ack' && msg.type !== 'ping') {
            sentLog.push(structuredClone(msg));
            if (sentLog.length > 50) sentLog.shift();
        }
        return sent;
    }

    // Steering messages are numbered (`seq`); each frame echoes the last number its state includes
    // (stats.input_seq), which tells the page which inputs a frame shows. The numbers rise for the
    // page's lifetime: the server starts afresh with each connection, so any rising count will do.
    let steerSeq = 0;

    /** A steering message: numbered, sent, and counted as input for the latency. */
    function steer(msg) {
        if (state.viewer) return false;
        const sent = send({ ...msg, seq: steerSeq + 1 });
        if (sent) {
            steerSeq += 1;
            const now = performance.now();
            latency.input(now, steerSeq);
            watch.input(now, steerSeq);
            state.lastSteerAt = now;
        }
        return sent;
    }

    /** The viewport to announce: its CSS size and the device pixel ratio, capped by the pixel budget. */
    function currentViewport() {
        return budgetViewport(ui.viewport.clientWidth, ui.viewport.clientHeight, window.devicePixelRatio,
            settings.pixelBudget);
    }

    let lastSize = null; // the last viewport sent, "WxH@dpr"
    function sendResize(force = false) {
        if (state.viewer) return;
        const { size, dpr } = currentViewport();
        const key = `${size[0]}x${size[1]}@${dpr}`;
        if (!force && key === lastSize) return;
        if (send(resizeMsg(size[0], size[1], dpr))) {
            lastSize = key;
            state.viewport = { size, dpr };
            store.emit('viewport');
        }
    }

    // Pointer moves and slider drags arrive faster than frames: coalesce them into one message of each
    // kind per animation frame.
    // Light changes are kept per light (key: its id, '' for protocol 1's unnamed one), so switching
    // the selected light mid-drag cannot send one light's changes to another.
    const outbox = { camera: false, lights: new Map(), params: null, frame: 0 };
    let lastFlush = -Infinity;
    function flushOutbox() {
        outbox.frame = 0;
        lastFlush = performance.now();
        if (outbox.camera) {
            outbox.camera = false;
            steer(cameraMsg(camera.toCamera()));
        }
        const lightChanges = [...outbox.lights];
        outbox.lights.clear();
        for (const [key, changes] of lightChanges) steer(lightMsg(changes, key === '' ? null : key));
        if (outbox.params) {
            const values = outbox.params;
            outbox.params = null;
            sendParamsNow(values);
        }
    }
    function scheduleFlush() {
        if (outbox.frame) return;
        // The first change after a pause goes out at once (after this task, so that what one event changes
        // goes together): waiting for an animation frame would add up to one to the answer to input.
        // Changes that follow within a frame are merged into one message per animation frame.
        if (performance.now() - lastFlush > 20) {
            outbox.frame = -1;
            queueMicrotask(flushOutbox);
            return;
        }
        outbox.frame = requestAnimationFrame(flushOutbox);
    }

    function scheduleCamera() {
        if (state.viewer) return;
        outbox.camera = true;
        scheduleFlush();
        followCamera();
        store.emit('camera');
    }

    function selectedLight() {
        return state.lights.find((l) => (l.id ?? null) === state.selectedLightId) ?? state.lights[0] ?? null;
    }

    /** Changes light `id` (default: the selected one) here at once and queues them for the server. */
    function changeLight(changes, id = state.selectedLightId) {
        if (state.viewer) return;
        let index = state.lights.findIndex((l) => (l.id ?? null) === id);
        if (index < 0 && id === null && state.lights.length > 0) index = 0;
        if (index < 0) return;
        state.lights[index] = applyLightChanges(state.lights[index], changes);
        const key = state.lights[index].id ?? '';
        outbox.lights.set(key, { ...(outbox.lights.get(key) ?? {}), ...structuredClone(changes) });
        scheduleFlush();
        renderGizmo();
        store.emit('lights');
    }

    function selectLight(id) {
        state.selectedLightId = id;
        store.emit('lights');
        renderGizmo();
    }

    /** light_add for a light of `type` placed from the current view; the server's state answer selects it. */
    function addLight(type) {
        if (state.viewer || !state.lightList) return;
        // Queued edits go first, so the server's answer already contains them.
        flushOutbox();
        if (steer(lightAddMsg(newLightFor(type, camera.toCamera(), state.light)))) state.lightOps.push('add');
    }

    function removeSelectedLight() {
        const id = state.light?.id;
        if (state.viewer || !state.lightList || !id) return;
        flushOutbox();
        if (steer(lightRemoveMsg(id))) state.lightOps.push('remove');
    }

    function queueParams(values) {
        outbox.params = { ...(outbox.params ?? {}), ...values };
        scheduleFlush();
    }

    /** Parameters are checked against the welcome schemas first: an invalid value never leaves the page. */
    function sendParamsNow(values) {
        const technique = state.techniques.get(state.technique);
        const problem = validateParamValues(values, technique?.params_schema, state.welcome?.frame_params_schema);
        if (problem) {
            showMessage(`Not sent: ${problem.where}: ${problem.message}`);
            store.emit('params', state.params, { force: true });
            return;
        }
        if (steer(paramsMsg(values))) {
            Object.assign(state.params, values);
            for (const name of Object.keys(values)) state.explicit.add(name);
            store.emit('params', values);
        }
    }

    /** hello for this page: a viewer names the view token, a controller its viewport and a resume token if it has one. */
    function buildHello() {
        // Patches (regions of a refining image) where this page's schema copy has the field.
        const patches = CLIENT_SCHEMAS.hello?.properties?.patches ? true : undefined;
        const common = { client: CLIENT_NAME, token: page.token, codecs: CODECS, max_in_flight: MAX_IN_FLIGHT, patches };
        if (state.viewer) return helloMsg({ ...common, view: page.view });
        const { size, dpr } = currentViewport();
        lastSize = `${size[0]}x${size[1]}@${dpr}`;
        state.viewport = { size, dpr };
        // Only where this page's schema copy has the field: an older server refuses a hello with it.
        const target = settings.frameTargetMs !== null && frameTargetSupported(null, CLIENT_SCHEMAS, 'hello')
            ? settings.frameTargetMs : undefined;
        return helloMsg({
            ...common, resume: sessionStorage.getItem(RESUME_KEY) ?? undefined, size, dpr, frame_target_ms: target,
        });
    }

    /** The session's frame-time target: what welcome said (or the quality control set), else the default. */
    function frameTargetMs() {
        return state.frameTargetMs ?? state.welcome?.limits?.frame_target_ms ?? DEFAULT_FRAME_TARGET_MS;
    }

    /** The quality message for the current adaptive choice and, where the server takes one, the frame target. */
    function sendQuality() {
        const adaptive = state.adaptive;
        const target = frameTargetSupported(state.welcome, CLIENT_SCHEMAS)
            ? settings.frameTargetMs ?? state.welcome?.limits?.frame_target_ms : undefined;
        if (!steer(qualityMsg(adaptive, Number.isInteger(target) ? target : undefined))) return false;
        if (Number.isInteger(target)) state.frameTargetMs = target;
        return true;
    }

    /** Light edits queued for light `id` ('' without ids), not yet sent: newer than any state. */
    const pendingLight = (id) => outbox.lights.get(id ?? '');

    return {
        send, steer, currentViewport, sendResize, flushOutbox, scheduleFlush, scheduleCamera, selectedLight, changeLight, selectLight, addLight, removeSelectedLight, queueParams, sendParamsNow, buildHello, frameTargetMs, sendQuality, pendingLight,
        lastSteerSeq: () => steerSeq,
    };
}
