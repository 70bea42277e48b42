// App wiring: the connection and session role, receiving (welcome, state, errors, restores), what a
// drawn frame tells the page, the light gizmo and view input, notices, and the page's state (a Store
// whose topics the sidebar sections in sections/ subscribe to; no section calls another). Sending is
// outbox.js, frame display frame-view.js, the overlay overlay.js, uploads uploads.js; the pure pieces
// live in their own modules (protocol, camera, light, lights, params, stats, progress, budget,
// restore, accuracy, messages, upload, store).

import {
    cameraMsg, isKnownServerMessage, parseServerMessage, pingMsg, sceneMsg, snapshotMsg, techniqueMsg,
} from './protocol.js';
import { CLIENT_SCHEMAS } from './schemas.js';
import { OrbitCamera, attachViewControls, boundsSphere, withOrbitTarget } from './camera.js';
import { aimLight, gizmoKinds, moveLight } from './light.js';
import { applyLightChanges, lightsOfState, pickSelection } from './lights.js';
import { StreamConnection, formatCountdown, pageOptions, shareLink, streamUrl } from './connection.js';
import { block } from './controls.js';
import { resetPlan, schemaDefaults } from './params.js';
import { ChartSchedule, LatencyTracker, PassHistory, RateCounter, RoundTrip, networkMs } from './stats.js';
import { InputWatch, RefineTracker } from './progress.js';
import { estimatedRenderStart } from './inputs.js';
import { DEFAULT_PIXEL_BUDGET, frameTargetSupported, normalizeFrameTarget, normalizePixelBudget } from './budget.js';
import { lightRestoreMessages, restoreMessages, restorePlan, sessionSnapshot } from './restore.js';

import { PassChart } from './chart.js';
import { LightGizmo } from './gizmo.js';
import { DEFAULT_COMPARE, compareSettings } from './accuracy.js';
import { MessageStack, describeError, noticeFor } from './messages.js';
import { bindUploads } from './uploads.js';
import { Store } from './store.js';
import { createFrameView } from './frame-view.js';
import { figuresDue } from './frames.js';
import { createOutbox } from './outbox.js';
import { createOverlay } from './overlay.js';
import { createAccuracySection } from './sections/accuracy.js';
import { createCameraSection } from './sections/camera.js';
import { createLightSection } from './sections/light.js';
import { createQualitySection } from './sections/quality.js';
import { createSceneSection } from './sections/scene.js';
import { createShareSection } from './sections/share.js';
import { createStatsSection } from './sections/stats.js';
import { createTechniqueSection } from './sections/technique.js';

const RESIZE_DEBOUNCE_MS = 200;
const MESSAGE_HIDE_MS = 8000;
const PING_INTERVAL_MS = 2000;
const CHART_WINDOW_S = 10;
const OVERLAY_TICK_MS = 250; // the overlay's figures, and the chart's redraw at most this often
// WebP first: about a third smaller than JPEG at the same quality; JPEG for browsers without it.
const CODECS = ['webp', 'jpeg'];
// Two frames in flight: the next frame travels while this one decodes, without building a queue.
const MAX_IN_FLIGHT = 2;
// sessionStorage, not localStorage: the token belongs to this tab's session (it survives a reload,
// which then resumes the session) and another tab must start its own.
const RESUME_KEY = 'gi-resume-token';
const SETTINGS_KEY = 'gi-client-settings';
const NARROW_QUERY = '(max-width: 760px)';

// Errors after which the server closes the connection and retrying the same hello cannot help.
const FATAL_ERRORS = new Set(['hello_required', 'protocol_mismatch', 'unauthorized', 'unknown_view_token',
    'session_ended', 'idle_timeout']);

const $ = (id) => document.getElementById(id);
const ui = {
    app: $('app'),
    sidebar: $('sidebar'),
    sections: $('sections'),
    backdrop: $('backdrop'),
    sidebarToggle: $('sidebar-toggle'),
    canvas: $('view'),
    compareCanvas: $('compare-view'),
    layerLabel: $('layer-label'),
    gizmo: $('gizmo'),
    viewport: $('viewport'),
    connDot: $('conn-dot'),
    connText: $('conn-text'),
    retryNow: $('retry-now'),
    busy: $('busy'),
    fullscreen: $('fullscreen'),
    notice: $('notice'),
    noticeTitle: $('notice-title'),
    noticeText: $('notice-text'),
    noticeAction: $('notice-action'),
    role: $('role'),
    sessionToggle: $('session-toggle'),
    messages: $('messages'),
    overlay: $('overlay'),
    ovRate: $('ov-rate'),
    ovTimes: $('ov-times'),
    ovBytes: $('ov-bytes'),
    ovAccuracy: $('ov-accuracy'),
    ovStale: $('ov-stale'),
    ovBudget: $('ov-budget'),
    ovRefine: $('ov-refine'),
    ovRefineBar: $('ov-refine-bar'),
    ovRefineText: $('ov-refine-text'),
    ovChartNote: $('ov-chart-note'),
    ovChart: $('ov-chart'),
    ovLegend: $('ov-legend'),
    dropHint: $('drop-hint'),
    fileInput: $('file-input'),
};

const page = pageOptions(window.location);

function loadSettings() {
    const defaults = {
        tool: 'orbit', flySpeed: 0.5, overlay: true, chart: true, help: false, gizmo: true,
        compareMode: DEFAULT_COMPARE.mode, compareNoiseTarget: DEFAULT_COMPARE.noiseTarget,
        compareMaxSpp: DEFAULT_COMPARE.maxSpp, compareMaxSide: DEFAULT_COMPARE.maxSide,
        compareView: 'live', diffGain: 4, frameTargetMs: null, pixelBudget: DEFAULT_PIXEL_BUDGET,
    };
    let stored = {};
    try {
        stored = JSON.parse(localStorage.getItem(SETTINGS_KEY) ?? '{}') ?? {};
    } catch { /* unreadable: the defaults */ }
    const s = { ...defaults, ...stored };
    s.frameTargetMs = normalizeFrameTarget(s.frameTargetMs);
    s.pixelBudget = normalizePixelBudget(s.pixelBudget);
    const compare = compareSettings(s);
    s.compareNoiseTarget = compare.noiseTarget;
    s.compareMaxSpp = compare.maxSpp;
    delete s.compareSpp; // an older page's fixed reference spp: the noise target replaces it (compareSettings)
    return s;
}
const settings = loadSettings();
function saveSettings() {
    try {
        localStorage.setItem(SETTINGS_KEY, JSON.stringify(settings));
    } catch { /* private mode: settings last for this page only */ }
}

// The page's state and its change notices: the sections subscribe to the topics (store.js).
const store = new Store({
    viewer: page.view !== undefined, // joined with a view token: watch only
    adaptive: true, // adaptive quality (the Technique section's toggle; welcome and restores set it)
    viewport: null, // the last {size, dpr} announced in hello or resize
    welcome: null,
    techniques: new Map(), // name -> technique description from welcome
    technique: null,
    scene: null,
    scenes: [],
    uploads: [], // upload:NAME scenes of this session
    params: {}, // the session's own parameter values (what the panel shows)
    explicit: new Set(), // parameters this page set in this session: they win over the adaptive presets
    bounds: null, // state.bounds {min, max} of the scene (protocol 2), for framing and the orbit target
    restore: null, // what the page knew of a session that was lost, for the next new session
    restoreAfterScene: null, // {scene, messages, saved} to send once the restored scene has loaded
    deadView: false, // this page's view token no longer works: never retried
    retryAt: null, // when the next reconnect attempt starts (performance.now() ms)
    frameTargetMs: null, // the session's frame-time target (welcome.frame_target_ms), when the server has one
    lights: [], // the session's lights as this client knows them (state.lights, or protocol 1's one light)
    lightList: false, // the server lists its lights with ids (protocol 2): only then can they be added and removed
    selectedLightId: null, // the light the Light section and the gizmo edit
    /** The selected light: what code written for the single light of protocol 1 reads. */
    get light() {
        return selectedLight();
    },
    lightHomes: new Map(), // id ('' without ids) -> the light as the scene defined it, for "Reset light"
    lightOps: [], // 'add' / 'remove' sent, oldest first, whose state answer has not arrived
    serverScene: null, // the scene of the last full state from the server
    lighting: null, // state.lighting {source, note}, until a frame's stats.lighting says more
    statsByFrame: new Map(), // frame -> {stats, arrivedAt}
    lastDrawn: null, // {frame, width, height, stats, arrivedAt, drawnAt, decodeMs} (times: performance.now())
    figuresShownAt: -Infinity, // when a drawn frame's figures were last shown (performance.now())
    lastSteerAt: null, // performance.now() when the last steering message (camera, light, params) left
    framesDrawn: 0,
    decoding: false,
    pending: [], // frames that arrived while another was decoding (frames.js: the newest whole frame, then patches)
    snapshotWanted: false, // a snapshot was asked for and has not arrived yet
    rttMs: null,
    decodeMs: null, // createImageBitmap time of the last frame
    connState: 'connecting',
    compare: null, // {request, key, result, image (canvas), at}
    compareRunning: null, // {abort, started}
});
const state = store.state;

const camera = new OrbitCamera();
const rate = new RateCounter(1000);
const latency = new LatencyTracker();
const roundTrip = new RoundTrip(); // state.rttMs: the least of the last pings' round trips
const passes = new PassHistory(CHART_WINDOW_S);
const refine = new RefineTracker();
const watch = new InputWatch();
const toasts = new MessageStack({ max: 4, ttlMs: MESSAGE_HIDE_MS });
const chart = new PassChart(ui.ovChart, ui.ovLegend, { windowS: CHART_WINDOW_S });
const chartSchedule = new ChartSchedule({ periodMs: OVERLAY_TICK_MS });
const overlay = createOverlay({ ui, state, settings, store },
    { rate, latency, passes, chart, chartSchedule, refine, watch, toasts, frameTargetMs: () => frameTargetMs() });
const { showRate, showProgress, showFrameStats } = overlay;
const connection = new StreamConnection(streamUrl(window.location), {
    onOpen: handleOpen,
    onText: handleText,
    onBinary: (buffer) => frameView.handleBinary(buffer),
    onClose: handleClose,
    onState: showConnectionState,
});

// What the browser tests (tests/e2e/browser.test.mjs) and a curious user can read from the console.
const hook = {
    get framesDrawn() { return state.framesDrawn; },
    get lastStats() { return state.lastDrawn?.stats ?? null; },
    get lastFrame() { return state.lastDrawn?.frame ?? null; },
    // When the last frame's bytes arrived and when it was drawn on the canvas, and when the last steering
    // message left (epoch ms, as Date.now() counts): where an answer to input spent its time.
    get lastDrawTiming() {
        const epoch = (t) => (t === null || t === undefined ? null : performance.timeOrigin + t);
        return { arrivedAt: epoch(state.lastDrawn?.arrivedAt), drawnAt: epoch(state.lastDrawn?.drawnAt),
            decodeMs: state.lastDrawn?.decodeMs ?? null, steerAt: epoch(state.lastSteerAt) };
    },
    // How the last frame was decoded: 'ImageDecoder' (a secure context) or 'createImageBitmap'.
    get decodedBy() { return frameView.decodedBy; },
    get connection() { return state.connState; },
    get role() { return state.viewer ? 'viewer' : 'controller'; },
    get session() { return state.welcome?.session ?? null; },
    welcomes: 0, // welcome messages so far (a reconnect adds one)
    resumed: null, // whether the last welcome resumed a session
    states: [], // the last connection states, oldest first
    get params() { return { ...state.params }; },
    get light() { return state.light ? structuredClone(state.light) : null; },
    get lights() { return structuredClone(state.lights); },
    get selectedLightId() { return state.selectedLightId; },
    get camera() { return camera.toCamera(); },
    get compare() { return state.compare?.result ?? null; },
    get rttMs() { return state.rttMs; },
    get latencyMs() { return latency.typical; },
    get viewport() { return state.viewport ? structuredClone(state.viewport) : null; },
    sent: [], // the last messages sent, oldest first (camera, ack and ping left out: they would crowd the rest)
    get refine() { return refine.view(performance.now()); },
    get busy() { return ui.busy.hidden ? null : ui.busy.textContent; },
    get stale() { return ui.overlay.classList.contains('stale'); },
    get notice() { return ui.notice.hidden ? null : ui.noticeTitle.textContent; },
    get bounds() { return state.bounds ? structuredClone(state.bounds) : null; },
    get welcome() { return state.welcome ? structuredClone(state.welcome) : null; },
    get frameTargetMs() { return state.frameTargetMs; },
    get chartRedraws() { return chart.redraws; },
    get figuresShownAt() { return state.figuresShownAt; }, // when a frame's figures were last shown (ms)
    get inputPending() { return watch.pending; }, // an input no drawn frame shows yet
    get steerSeq() { return lastSteerSeq(); }, // the number of the last steering message sent
    get explicit() { return [...state.explicit]; },
    // Benchmarks and tests steer through the page's own connection, exactly as the panels do.
    send: (msg) => send(msg),
};
window.giClient = hook;

// ---------------------------------------------------------------------------------------------
// Sending (outbox.js)

const {
    send, steer, currentViewport, sendResize, flushOutbox, scheduleFlush, scheduleCamera, selectedLight, changeLight, selectLight, addLight, removeSelectedLight, queueParams, sendParamsNow, buildHello, frameTargetMs, sendQuality, pendingLight, lastSteerSeq,
} = createOutbox({
    ui, state, settings, store, camera, connection, latency, watch, sentLog: hook.sent, showMessage,
    renderGizmo: () => gizmo.render(),
    followCamera: () => gizmo.followCamera(),
    hello: { codecs: CODECS, maxInFlight: MAX_IN_FLIGHT, resumeKey: RESUME_KEY, page },
});
const frameView = createFrameView({ ui, state, connection, send, showMessage, onDrawn: recordDraw });

// ---------------------------------------------------------------------------------------------
// Receiving

function handleOpen() {
    state.statsByFrame.clear();
    state.pending = [];
    state.snapshotWanted = false;
    latency.reset();
    watch.reset();
    refine.reset();
    roundTrip.reset(); // another connection, perhaps another way
    state.rttMs = null;
    send(buildHello());
    sendPing();
}

/** A close the user did not ask for: what the session was is kept for a new session to restore. */
function handleClose(code) {
    if (code === 1013) showMessage(describeError({ code: 'busy' }));
    // A restore still waiting for its scene knows more than the half-restored session does.
    if (!state.viewer && state.welcome && !state.restore) {
        state.restore = state.restoreAfterScene?.saved ?? snapshotSession();
    }
    refine.reset();
    watch.reset();
}

function snapshotSession() {
    return sessionSnapshot({
        scene: state.scene, technique: state.technique, params: state.params, explicit: state.explicit,
        camera: camera.toCamera(), adaptive: state.adaptive,
        lights: state.lightList ? state.lights : undefined,
    });
}

function handleText(text) {
    const msg = parseServerMessage(text);
    if (!msg) {
        showMessage('The server sent a message that is not a JSON object with a type.');
        return;
    }
    switch (msg.type) {
    case 'welcome': handleWelcome(msg); break;
    case 'stats':
        state.statsByFrame.set(msg.frame, { stats: msg, arrivedAt: performance.now() });
        // Stats whose frame never arrives (a reconnect in between) must not pile up.
        for (const frame of state.statsByFrame.keys()) if (frame < msg.frame - 8) state.statsByFrame.delete(frame);
        break;
    case 'state': applyServerState(msg.state ?? {}); break;
    case 'error': handleError(msg); break;
    case 'shutdown':
        // The server drains before it stops: this session will not survive it, so the reconnect
        // after the close starts a new session (on this server's replacement).
        sessionStorage.removeItem(RESUME_KEY);
        showMessage(`The server is shutting down; this session ends within ${msg.grace_s ?? '?'} s and the `
            + 'client will reconnect to a new one.', 'info');
        break;
    case 'pong':
        if (Number.isFinite(msg.t)) state.rttMs = roundTrip.add(performance.now() - msg.t);
        break;
    case 'progress':
        refine.message(msg, performance.now());
        showProgress();
        break;
    default:
        if (!isKnownServerMessage(msg.type)) console.warn('unhandled server message', msg);
    }
}

function handleError(msg) {
    const notice = FATAL_ERRORS.has(msg.code) ? noticeFor(msg.code, { viewer: state.viewer }) : null;
    // A notice stays until it is dealt with; a toast would fade and leave a black view behind.
    if (notice) showNotice(notice, describeError(msg));
    else showMessage(describeError(msg));
    if (msg.code === 'resume_failed' || msg.code === 'shutting_down') {
        // The session is gone (grace period over, server restarted): the reconnect that follows
        // the close starts a new one.
        sessionStorage.removeItem(RESUME_KEY);
        connection.markHealthy();
    } else if (FATAL_ERRORS.has(msg.code)) {
        if (msg.code === 'session_ended' || msg.code === 'idle_timeout') sessionStorage.removeItem(RESUME_KEY);
        // A view token dies with its session: Connect would only be refused again.
        if (state.viewer && (msg.code === 'unknown_view_token' || msg.code === 'session_ended')) state.deadView = true;
        connection.stopReconnecting();
    } else if ((msg.code === 'unknown_scene' || msg.code === 'scene_load_failed') && state.restoreAfterScene) {
        // The old scene did not come back: the rest of the restore belongs to it.
        state.restoreAfterScene = null;
    } else if (msg.request === 'light_add' || msg.request === 'light_remove') {
        // Refused: no state answer will come for it.
        const index = state.lightOps.indexOf(msg.request === 'light_add' ? 'add' : 'remove');
        if (index >= 0) state.lightOps.splice(index, 1);
    } else if (msg.code === 'invalid_param' || msg.code === 'limit_exceeded') {
        // The server kept its values: show them again (the next stats carry what it renders).
        store.emit('params', state.params, { force: true });
    }
}

function handleWelcome(msg) {
    connection.markHealthy();
    hook.welcomes += 1;
    hook.resumed = msg.resumed === true;
    state.welcome = msg;
    state.lightOps = [];
    state.frameTargetMs = Number.isFinite(msg.frame_target_ms) ? msg.frame_target_ms : null;
    hideNotice();
    setRole(msg.role === 'viewer');
    if (msg.resume_token) sessionStorage.setItem(RESUME_KEY, msg.resume_token);
    if (!msg.resumed) {
        state.uploads = [];
        state.explicit = new Set();
        state.restoreAfterScene = null;
    }
    state.techniques = new Map((msg.techniques ?? []).map((t) => [t.name, t]));
    state.scenes = msg.scenes ?? [];
    store.emit('techniques', [...state.techniques.keys()]);
    store.emit('adaptive', msg.adaptive !== false);
    applyState(msg.state ?? {}, { resumed: msg.resumed === true, fresh: true });
    store.emit('welcome');
    // A resumed session still has the viewport of before the outage (or the reload).
    if (msg.resumed) sendResize(true);
    const saved = state.restore;
    state.restore = null;
    if (state.viewer) return;
    const qualitySent = !msg.resumed && saved ? restoreSession(saved, msg) : false;
    // A resumed session may run another target than the one chosen here since.
    if (!qualitySent && settings.frameTargetMs !== null && frameTargetSupported(msg, CLIENT_SCHEMAS)
        && msg.frame_target_ms !== settings.frameTargetMs) {
        sendQuality();
    }
}

/**
 * Brings a new session to what the lost one was: its scene first (which resets the camera and
 * lights when it loads), then technique, explicit parameters and camera. Returns whether it sent
 * a quality message.
 */
function restoreSession(saved, welcome) {
    const plan = restorePlan(saved, welcome);
    const messages = restoreMessages(plan);
    const restored = [];
    let quality = null;
    if (plan.adaptive !== null) {
        store.emit('adaptive', plan.adaptive);
        if (sendQuality()) quality = plan.adaptive ? 'adaptive quality' : 'fixed quality';
    }
    if (plan.scene) {
        if (steer(sceneMsg(plan.scene))) {
            state.scene = plan.scene;
            store.emit('scenes');
            state.restoreAfterScene = { scene: plan.scene, messages, saved };
            restored.push(plan.scene);
        }
    } else {
        sendRestoreMessages(messages);
    }
    if (plan.technique) restored.push(plan.technique);
    const count = Object.keys(plan.params).length;
    if (count) restored.push(`${count} parameter${count === 1 ? '' : 's'}`);
    if (plan.lights.length) restored.push('the lights');
    if (plan.camera) restored.push('the camera');
    if (quality) restored.push(quality);
    const list = restored.length > 1 ? `${restored.slice(0, -1).join(', ')} and ${restored.at(-1)}` : restored[0];
    const text = restored.length ? `New session: restored ${list}.` : '';
    const missing = plan.notes.length ? ` Not restored: ${plan.notes.join('; ')}.` : '';
    if (text || missing) showMessage(`${text || 'New session.'}${missing}`, 'info');
    return quality !== null;
}

function sendRestoreMessages(messages) {
    for (const msg of messages) {
        if (msg.type === 'technique') {
            if (!steer(msg)) continue;
            const technique = state.techniques.get(msg.name);
            Object.assign(state.params, schemaDefaults(technique?.params_schema));
            showTechnique(msg.name);
        } else if (msg.type === 'params') {
            sendParamsNow(msg.values);
        } else if (msg.type === 'light') {
            changeLight(msg.light, msg.id);
        } else if (msg.type === 'light_add' || msg.type === 'light_remove') {
            if (steer(msg)) state.lightOps.push(msg.type === 'light_add' ? 'add' : 'remove');
        } else if (msg.type === 'camera') {
            camera.set(msg);
            store.emit('camera');
            steer(cameraMsg(camera.toCamera()));
            gizmo.render();
        }
    }
}

/**
 * Shows a session state (welcome.state, state messages). A new session's camera and light become
 * the ones "Reset" returns to; a resumed one keeps the home it had.
 */
function applyState(s, { resumed = false, fresh = false } = {}) {
    if (s.scene !== undefined) state.scene = s.scene;
    state.serverScene = state.scene;
    store.emit('scenes');
    if (s.bounds !== undefined) state.bounds = boundsSphere(s.bounds) ? structuredClone(s.bounds) : null;
    else if (s.scene !== undefined) state.bounds = null;
    if (s.camera) {
        // The orbit target at the model's depth: a glTF camera's look-at point is a metre ahead.
        const current = withOrbitTarget(s.camera, state.bounds);
        // "Reset camera" goes to the scene's own camera where the server names it; else to the
        // camera a new session or scene started with.
        if (s.scene_camera) camera.setHome(withOrbitTarget(s.scene_camera, state.bounds));
        else if (!resumed) camera.setHome(current);
        camera.set(current);
        store.emit('camera');
    }
    store.emit('bounds', Boolean(state.bounds));
    const lights = lightsOfState(s);
    if (lights) {
        showLights(lights, s, {});
        if (!resumed || state.lightHomes.size === 0) {
            state.lightHomes = new Map(lights.map((l) => [l.id ?? '', structuredClone(l)]));
        }
    }
    if (s.params) state.params = { ...s.params };
    if (s.technique !== undefined || fresh) showTechnique(s.technique ?? state.technique);
    store.emit('params', state.params);
    gizmo.render();
}

/**
 * A state message from the server. The answer to this client's light_add or light_remove changes
 * only the lights: applying the rest would make the camera it carries the new home (and may undo
 * camera moves sent since), so only the lights are taken from it.
 */
function applyServerState(s) {
    const sameScene = s.scene === undefined || s.scene === state.serverScene;
    if (state.lightOps.length > 0 && sameScene && Array.isArray(s.lights)) {
        const op = state.lightOps.shift();
        showLights(lightsOfState(s), s, { expectAdded: op === 'add' });
        return;
    }
    applyState(s);
    const pending = state.restoreAfterScene;
    if (pending && s.scene === pending.scene) {
        state.restoreAfterScene = null;
        // The scene's own lights are known now: the user's changes to them go too.
        const lights = Array.isArray(pending.saved?.lights) && Array.isArray(s.lights)
            ? lightRestoreMessages(pending.saved.lights, s.lights) : [];
        sendRestoreMessages([...lights, ...pending.messages]);
    }
}

/** Shows the light list of a state; edits still in the outbox are newer than it and stay applied. */
function showLights(lights, s, { expectAdded = false }) {
    const previousIds = state.lights.map((l) => l.id ?? null);
    state.lights = lights.map((l) => {
        const pending = pendingLight(l.id);
        return pending ? applyLightChanges(l, pending) : l;
    });
    state.lightList = Array.isArray(s.lights);
    if (s.lighting) state.lighting = s.lighting;
    state.selectedLightId = pickSelection(previousIds, state.lights, state.selectedLightId, { expectAdded });
    store.emit('lights');
    store.emit('lighting', state.lastDrawn?.stats?.lighting ?? state.lighting);
    gizmo.render();
}

function sendPing() {
    if (connection.isOpen) send(pingMsg(performance.now()));
}

// ---------------------------------------------------------------------------------------------
// Stats

function recordDraw(frame, decodeMs, frameBytes) {
    const now = performance.now();
    const stats = frame.entry?.stats ?? null;
    state.framesDrawn += 1;
    state.lastDrawn = { frame: frame.header.frame, width: frame.header.width, height: frame.header.height, stats,
        arrivedAt: frame.arrivedAt, drawnAt: now, decodeMs };
    ui.canvas.dataset.frame = String(frame.header.frame);
    rate.tick(now);
    if (stats && !stats.snapshot) {
        latency.frameDrawn(frame.arrivedAt, now, stats, state.rttMs ?? 0);
        passes.push(now / 1000, stats.passes);
        refine.stats(stats, now);
    }
    watch.frameDrawn(estimatedRenderStart(frame.arrivedAt, stats, state.rttMs ?? 0), now, stats?.input_seq);
    // A viewer follows what the controller does; a controller's own choice is already shown (and
    // frames of the previous choice may still be on their way).
    if (state.viewer && stats?.technique && stats.technique !== state.technique && state.techniques.has(stats.technique)) {
        state.params = { ...(stats.params ?? {}) };
        showTechnique(stats.technique);
    }
    if (state.viewer && stats?.scene && stats.scene !== state.scene) {
        state.scene = stats.scene;
        store.emit('scenes');
    }
    overlay.frameDrawn(now);
    // A refining image's patches show their figures at most as often as the overlay's tick
    // (frames.js, figuresDue): each set shown lays out and paints the page again, main-thread time
    // that input then waits for (docs/interactive.md, "The page's figures while the view refines").
    // The last patch held back is shown when the period ends, so the figures end on the image's.
    if (!figuresDue(stats, now, state.figuresShownAt, OVERLAY_TICK_MS)) {
        heldFigures = [frame, decodeMs, frameBytes];
        heldFiguresTimer ||= setTimeout(() => {
            heldFiguresTimer = 0;
            const held = heldFigures;
            heldFigures = null;
            if (held) showFigures(...held);
        }, Math.max(0, OVERLAY_TICK_MS - (now - state.figuresShownAt)));
        return;
    }
    heldFigures = null;
    showFigures(frame, decodeMs, frameBytes);
}

let heldFigures = null; // [frame, decodeMs, frameBytes] of the last patch whose figures wait
let heldFiguresTimer = 0;

/** The overlay's frame lines, the Stats details and what else follows a drawn frame's figures. */
function showFigures(frame, decodeMs, frameBytes) {
    const stats = frame.entry?.stats ?? null;
    // When they are shown, not when the frame was drawn: the work between the two (the chart, the
    // latency figures) varies, and the period is the page's, between two shows.
    state.figuresShownAt = performance.now();
    const net = networkMs(state.rttMs, frame.entry?.arrivedAt, frame.arrivedAt);
    showFrameStats(frame.header, stats, { decodeMs, net, bytes: stats?.bytes ?? frameBytes });
    noteDefaultLighting(stats?.lighting);
    store.emit('lighting', stats?.lighting ?? state.lighting);
    store.emit('frame', stats);
    gizmo.render();
    showProgress();
}

// ---------------------------------------------------------------------------------------------
// Role and session controls

/** Viewers watch: the steering controls are hidden and input on the view sends nothing. */
function setRole(viewer) {
    state.viewer = viewer;
    document.body.classList.toggle('viewer', viewer);
    showRoleBadge();
    store.emit('role', viewer);
    gizmo.enabled = !viewer;
    gizmo.render();
}

function toggleSession() {
    if (state.deadView) {
        openOwnSession();
    } else if (connection.socket || state.connState === 'waiting') {
        // A deliberate end: close with 1000 so the server frees the session now, and the next
        // Connect starts afresh instead of restoring it.
        sessionStorage.removeItem(RESUME_KEY);
        state.restore = null;
        connection.close();
    } else {
        hideNotice();
        connection.connect();
    }
}

/** This page without the dead view token: a session of one's own. */
function openOwnSession() {
    window.location.assign(`${window.location.origin}${window.location.pathname}${window.location.search}`);
}

function showRoleBadge() {
    const closed = state.connState === 'closed';
    ui.role.textContent = closed ? 'disconnected' : state.viewer ? 'viewing' : 'controlling';
    ui.role.dataset.state = closed ? 'closed' : state.viewer ? 'viewer' : 'controller';
}

function showConnectionState(connState, delayMs) {
    state.connState = connState;
    hook.states.push(connState);
    if (hook.states.length > 20) hook.states.shift();
    state.retryAt = connState === 'waiting' ? performance.now() + delayMs : null;
    ui.connDot.dataset.state = connState;
    ui.connText.textContent = connState === 'waiting'
        ? `disconnected, retrying in ${formatCountdown(delayMs)}`
        : connState === 'open' ? 'connected' : connState;
    ui.retryNow.hidden = connState !== 'waiting';
    ui.sessionToggle.textContent = state.deadView ? 'New session' : connState === 'closed' ? 'Connect' : 'Disconnect';
    showRoleBadge();
    showProgress();
}

function showMessage(text, kind = 'error') {
    const { entry, added, dropped } = toasts.add(text, kind, performance.now());
    for (const old of dropped) ui.messages.querySelector(`.message[data-id="${old.id}"]`)?.remove();
    let item = ui.messages.querySelector(`.message[data-id="${entry.id}"]`);
    if (added || !item) {
        item = document.createElement('div');
        item.className = `message ${kind}`;
        item.dataset.id = String(entry.id);
        item.append(block('span', 'message-text', text), block('span', 'message-count'));
    }
    // Newest last: a repeated message moves down to where the eye expects the latest one.
    ui.messages.append(item);
    const count = item.querySelector('.message-count');
    count.textContent = entry.count > 1 ? `×${entry.count}` : '';
    item.dataset.count = String(entry.count);
}

/** A persistent explanation over the view, with the one thing to do about it. */
function showNotice(notice, details) {
    ui.noticeTitle.textContent = notice.title;
    ui.noticeText.textContent = notice.text;
    ui.notice.dataset.details = details ?? '';
    ui.notice.title = details ?? '';
    const labels = { connect: 'Connect', 'own-session': 'Start my own session', reload: 'Reload' };
    ui.noticeAction.hidden = !notice.action;
    ui.noticeAction.textContent = labels[notice.action] ?? '';
    ui.noticeAction.dataset.action = notice.action ?? '';
    ui.notice.hidden = false;
}

function hideNotice() {
    ui.notice.hidden = true;
}

function noticeAction() {
    const action = ui.noticeAction.dataset.action;
    if (action === 'own-session') openOwnSession();
    else if (action === 'reload') window.location.reload();
    else if (action === 'connect') {
        hideNotice();
        connection.connect();
    }
}

let lastLightingNote = null;

/** Says once per scene when the server lights it with its default key light, and why (stats.lighting). */
function noteDefaultLighting(lighting) {
    if (lighting?.source !== 'default' || !lighting.note) {
        lastLightingNote = null;
        return;
    }
    const key = `${state.scene}:${lighting.note}`;
    if (key === lastLightingNote) return;
    lastLightingNote = key;
    showMessage(`Default lighting: ${lighting.note}. Ctrl-drag moves it, like any light.`, 'info');
}

// ---------------------------------------------------------------------------------------------
// Sidebar sections

// What the sections get: the page's parts and the actions they may take. Sections never call each
// other: what one changes reaches the rest as a store topic.
const app = {
    ui, state, settings, saveSettings, store, camera, chart, authHeaders,
    actions: {
        send, steer, flushOutbox, queueParams, sendQuality, sendResize, showMessage, showTechnique,
        forgetTechniqueParams, resetParams, addLight, removeSelectedLight, changeLight, selectLight,
        scheduleCamera, resetCamera, frameModel, copyShareLink, requestSnapshot,
    },
};
store.on('gizmo', () => {
    gizmo.visible = settings.gizmo;
    gizmo.render();
});
createSceneSection(app);

createTechniqueSection(app);

/** A technique message makes the server forget explicit technique parameters; frame parameters stay. */
function forgetTechniqueParams() {
    const frame = state.welcome?.frame_params_schema?.properties ?? {};
    state.explicit = new Set([...state.explicit].filter((k) => Object.hasOwn(frame, k)));
}

/**
 * "Reset parameters" without making every value explicit (explicit values win over the adaptive
 * presets): the current technique again resets its parameters and forgets the explicit ones, and
 * only frame parameters off their default are sent (see params.js resetPlan for the limit).
 */
function resetParams() {
    if (state.viewer) return;
    flushOutbox();
    const technique = state.techniques.get(state.technique);
    const plan = resetPlan({
        techniqueSchema: technique?.params_schema, frameSchema: state.welcome?.frame_params_schema,
        params: state.params, explicit: state.explicit,
    });
    if (plan.technique && steer(techniqueMsg(state.technique))) {
        Object.assign(state.params, plan.techniqueDefaults);
        forgetTechniqueParams();
    }
    if (Object.keys(plan.frame).length > 0) sendParamsNow(plan.frame);
    store.emit('params', state.params, { force: true });
    if (!plan.technique && Object.keys(plan.frame).length === 0) showMessage('Every parameter is at its default.', 'info');
}

/** Technique `name` with the session's values: its section rebuilds the parameter folders. */
function showTechnique(name) {
    state.technique = name;
    store.emit('technique', name);
}

createQualitySection(app);

createLightSection(app);

createCameraSection(app);

function resetCamera() {
    camera.reset();
    scheduleCamera();
}

/** Fits the orbit camera to the scene's bounds, seen from the current direction. */
function frameModel() {
    if (state.viewer || !state.bounds) return;
    const aspect = ui.viewport.clientWidth / Math.max(1, ui.viewport.clientHeight);
    if (camera.frame(state.bounds, aspect)) scheduleCamera();
}

/** The view (stream, gizmo, overlay) fills the screen; F or the ⛶ button again leaves. */
function toggleFullscreen() {
    if (document.fullscreenElement) {
        Promise.resolve(document.exitFullscreen?.()).then(showFullscreenState, () => {});
        return;
    }
    const view = ui.viewport;
    // Safari before 16.4 has only the prefixed form.
    const request = view.requestFullscreen ?? view.webkitRequestFullscreen;
    if (!request) {
        showMessage('This browser cannot show the view fullscreen.');
        return;
    }
    // The fullscreenchange event also updates the button; the promise covers browsers that fire it late.
    Promise.resolve(request.call(view)).then(showFullscreenState,
        (e) => showMessage(`Fullscreen was refused: ${e.message}`));
}

function showFullscreenState() {
    const on = document.fullscreenElement === ui.viewport;
    ui.fullscreen.setAttribute('aria-pressed', String(on));
    ui.fullscreen.title = on ? 'leave fullscreen (F or Esc)' : 'show the view fullscreen (F)';
    // Keys go to the view: the canvas keeps focus across the switch.
    ui.canvas.focus({ preventScroll: true });
}

createStatsSection(app);

createAccuracySection(app);

createShareSection(app);

async function copyShareLink() {
    const token = state.welcome?.view_token;
    if (!token) {
        showMessage('No view token yet: wait for the connection.');
        return;
    }
    const link = shareLink(window.location, token);
    // The link is always shown too: the clipboard may be refused (plain http on another host).
    store.emit('share-link', link);
    try {
        await navigator.clipboard.writeText(link);
        showMessage('View-only link copied.', 'info');
    } catch {
        showMessage('Copy the view-only link from the Share section.', 'info');
    }
}

function requestSnapshot() {
    if (send(snapshotMsg('png'))) {
        state.snapshotWanted = true;
        showMessage('Snapshot requested: rendering at final quality…', 'info');
    }
}

// ---------------------------------------------------------------------------------------------
// Accuracy

function authHeaders() {
    return page.token ? { Authorization: `Bearer ${page.token}` } : {};
}

// ---------------------------------------------------------------------------------------------
// Light gizmo and view input

const gizmo = new LightGizmo(ui.gizmo, {
    getCamera: () => (state.viewer ? null : camera.toCamera()),
    getLight: () => state.light,
    getFrameSize: () => [ui.canvas.width, ui.canvas.height],
    onMove: (position) => changeLight({ position }),
    onAim: (direction) => changeLight({ direction }),
});
gizmo.visible = settings.gizmo;

/** Ctrl-drag (aim) and Ctrl+Shift-drag (move) of the selected light, as far as its type has them. */
function onLightDrag(gesture, dx, dy) {
    const light = state.light;
    if (!light) return;
    const kinds = gizmoKinds(light);
    const cam = camera.toCamera();
    if (gesture === 'light-move') {
        if (kinds.move && light.position) {
            changeLight({ position: moveLight(light.position, cam, dx, dy, ui.canvas.clientHeight) });
        }
    } else if (kinds.aim && light.direction) {
        changeLight({ direction: aimLight(light, cam, dx, dy, ui.canvas.clientHeight) });
    }
}

// ---------------------------------------------------------------------------------------------
// Layout: the sidebar collapses on wide screens and is a drawer on narrow ones

const narrow = window.matchMedia(NARROW_QUERY);
function setSidebar(open) {
    ui.app.classList.toggle('sidebar-closed', !open);
    ui.sidebarToggle.setAttribute('aria-expanded', String(open));
    ui.backdrop.hidden = !(open && narrow.matches);
}
function sidebarOpen() {
    return !ui.app.classList.contains('sidebar-closed');
}

// ---------------------------------------------------------------------------------------------
// Start

function debounce(fn, ms) {
    let timer = null;
    return () => {
        clearTimeout(timer);
        timer = setTimeout(fn, ms);
    };
}

function start() {
    setRole(state.viewer);
    setSidebar(!narrow.matches);
    narrow.addEventListener('change', () => setSidebar(!narrow.matches));
    ui.sidebarToggle.addEventListener('click', () => setSidebar(!sidebarOpen()));
    ui.backdrop.addEventListener('click', () => setSidebar(false));
    attachViewControls(ui.canvas, {
        camera,
        getTool: () => settings.tool,
        onCamera: scheduleCamera,
        onLight: onLightDrag,
        onHome: resetCamera,
        flySpeed: () => settings.flySpeed * camera.sceneScale,
        shortcuts: { KeyF: toggleFullscreen, Period: frameModel, NumpadDecimal: frameModel },
    });
    ui.sessionToggle.addEventListener('click', toggleSession);
    ui.retryNow.addEventListener('click', () => connection.connect());
    ui.noticeAction.addEventListener('click', noticeAction);
    ui.fullscreen.addEventListener('click', toggleFullscreen);
    ui.fullscreen.hidden = !(ui.viewport.requestFullscreen || ui.viewport.webkitRequestFullscreen);
    document.addEventListener('fullscreenchange', showFullscreenState);
    bindUploads(app, { isOpen: () => connection.isOpen, serverToken: page.token });
    // The viewport changes size with the window and when the sidebar opens or closes.
    new ResizeObserver(debounce(() => {
        sendResize();
        chart.resize();
        gizmo.render();
    }, RESIZE_DEBOUNCE_MS)).observe(ui.viewport);
    setInterval(showRate, OVERLAY_TICK_MS);
    setInterval(sendPing, PING_INTERVAL_MS);
    connection.connect();
}

start();
