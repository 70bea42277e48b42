// App wiring: connection and session role, frame display, side panel and stats.

import {
    ackMsg, cameraMsg, CLIENT_NAME, CODEC_MIME, helloMsg, paramsMsg, parseFrameHeader, parseServerMessage,
    qualityMsg, resizeMsg, sceneMsg, snapshotMsg, techniqueMsg, validateClientMessage, validateParamValues,
    viewportFor,
} from './protocol.js';
import { CLIENT_SCHEMAS } from './schemas.js';
import { OrbitCamera, attachOrbitControls } from './camera.js';
import { StreamConnection, pageOptions, shareLink, streamUrl } from './connection.js';
import { buildParamPanel } from './controls.js';

const RESIZE_DEBOUNCE_MS = 200;
const MESSAGE_HIDE_MS = 6000;
const FPS_WINDOW_MS = 1000;
// WebP first: about a third smaller than JPEG at the same quality; JPEG for browsers without it.
const CODECS = ['webp', 'jpeg'];
// Two frames in flight: the next frame travels while this one decodes, without building a queue.
const MAX_IN_FLIGHT = 2;
// sessionStorage, not localStorage: the token belongs to this tab's session (it survives a reload,
// which then resumes the session) and another tab must start its own.
const RESUME_KEY = 'gi-resume-token';

// Errors after which the server closes the connection and retrying the same hello cannot help.
const FATAL_ERRORS = new Set(['hello_required', 'protocol_mismatch', 'unauthorized', 'unknown_view_token',
    'session_ended', 'idle_timeout']);

const $ = (id) => document.getElementById(id);
const ui = {
    canvas: $('view'),
    viewport: $('viewport'),
    connDot: $('conn-dot'),
    connText: $('conn-text'),
    role: $('role'),
    messages: $('messages'),
    scene: $('scene'),
    technique: $('technique'),
    techniqueInfo: $('technique-info'),
    params: $('params'),
    adaptive: $('adaptive'),
    resetCamera: $('reset-camera'),
    snapshot: $('snapshot'),
    share: $('share'),
    shareUrl: $('share-url'),
    sessionToggle: $('session-toggle'),
    fps: $('fps'),
    statsLine: $('stats-line'),
    qualityLine: $('quality-line'),
    passes: $('passes'),
    plan: $('plan'),
};
const ctx = ui.canvas.getContext('2d');

const page = pageOptions(window.location);
const state = {
    viewer: page.view !== undefined, // joined with a view token: watch only
    welcome: null,
    techniques: new Map(), // name -> technique description from welcome
    technique: null,
    paramPanel: null,
    lastParams: null, // the parameter values of the latest stats
    lastSize: null, // the last viewport sent, "WxH@dpr"
    statsByFrame: new Map(),
    drawTimes: [],
    decoding: false,
    pending: null, // the newest frame that arrived while another was decoding
    snapshotWanted: false, // a snapshot was asked for and has not arrived yet
};

const camera = new OrbitCamera();
const connection = new StreamConnection(streamUrl(window.location), {
    onOpen: handleOpen,
    onText: handleText,
    onBinary: handleBinary,
    onClose: handleClose,
    onState: showConnectionState,
});

// ---------------------------------------------------------------------------------------------
// Sending

/** Validates like the server would and sends; an invalid message is shown, never sent. */
function send(msg) {
    const problem = validateClientMessage(msg, CLIENT_SCHEMAS);
    if (problem) {
        showMessage(`not sent (${problem.code}): ${problem.where || '/'}: ${problem.message}`);
        return false;
    }
    return connection.send(msg);
}

function currentViewport() {
    return viewportFor(ui.viewport.clientWidth, ui.viewport.clientHeight, window.devicePixelRatio);
}

function sendCamera() {
    if (!state.viewer) send(cameraMsg(camera.toCamera()));
}

function sendResize(force = false) {
    if (state.viewer) return;
    const { size, dpr } = currentViewport();
    const key = `${size[0]}x${size[1]}@${dpr}`;
    if (!force && key === state.lastSize) return;
    if (send(resizeMsg(size[0], size[1], dpr))) state.lastSize = key;
}

function sendParam(name, value) {
    const technique = state.techniques.get(state.technique);
    const problem = validateParamValues({ [name]: value }, technique?.params_schema, state.welcome?.frame_params_schema);
    if (problem) {
        showMessage(`${problem.where}: ${problem.message}`);
        state.paramPanel?.update(state.lastParams ?? {});
        return;
    }
    send(paramsMsg({ [name]: value }));
}

/** hello for this page: a viewer names the view token, a controller its viewport and a resume token if it has one. */
function buildHello() {
    const common = { client: CLIENT_NAME, token: page.token, codecs: CODECS, max_in_flight: MAX_IN_FLIGHT };
    if (state.viewer) return helloMsg({ ...common, view: page.view });
    const { size, dpr } = currentViewport();
    state.lastSize = `${size[0]}x${size[1]}@${dpr}`;
    return helloMsg({ ...common, resume: sessionStorage.getItem(RESUME_KEY) ?? undefined, size, dpr });
}

// ---------------------------------------------------------------------------------------------
// Receiving

function handleOpen() {
    state.statsByFrame.clear();
    state.pending = null;
    state.snapshotWanted = false;
    send(buildHello());
}

function handleClose(code) {
    if (code === 1013) showMessage('the server is busy (session limit reached); retrying');
}

function handleText(text) {
    const msg = parseServerMessage(text);
    if (!msg) {
        showMessage('the server sent a message that is not a JSON object with a type');
        return;
    }
    switch (msg.type) {
    case 'welcome': handleWelcome(msg); break;
    case 'stats': handleStats(msg); break;
    case 'state': applyState(msg.state ?? {}); break;
    case 'error': handleError(msg); break;
    case 'pong': break;
    default: console.warn('unhandled server message', msg);
    }
}

function handleError(msg) {
    showMessage(`${msg.code}${msg.where ? ` at ${msg.where}` : ''}: ${msg.message}`);
    if (msg.code === 'resume_failed') {
        // The session is gone (grace period over, server restarted): the reconnect that follows
        // the close starts a new one.
        sessionStorage.removeItem(RESUME_KEY);
        connection.markHealthy();
    } else if (FATAL_ERRORS.has(msg.code)) {
        if (msg.code === 'session_ended' || msg.code === 'idle_timeout') sessionStorage.removeItem(RESUME_KEY);
        connection.stopReconnecting();
    }
}

function handleWelcome(msg) {
    connection.markHealthy();
    state.welcome = msg;
    setRole(msg.role === 'viewer');
    if (msg.resume_token) sessionStorage.setItem(RESUME_KEY, msg.resume_token);
    state.techniques = new Map((msg.techniques ?? []).map((t) => [t.name, t]));
    const s = msg.state ?? {};
    fillSelect(ui.scene, msg.scenes ?? [], s.scene);
    fillSelect(ui.technique, [...state.techniques.keys()], s.technique);
    ui.adaptive.checked = msg.adaptive !== false;
    state.lastParams = s.params ?? null;
    applyState(s, { resumed: msg.resumed === true });
    // A resumed session still has the viewport of before the outage (or the reload).
    if (msg.resumed) sendResize(true);
}

/**
 * Shows a session state (welcome.state, state messages). A new session's camera becomes the one
 * "Reset camera" returns to; a resumed one keeps the home it had.
 */
function applyState(s, { resumed = false } = {}) {
    if (s.scene !== undefined) ui.scene.value = s.scene;
    if (s.camera) {
        if (resumed) camera.set(s.camera);
        else camera.setHome(s.camera);
    }
    if (s.technique !== undefined) {
        ui.technique.value = s.technique;
        showTechnique(s.technique, s.params);
    }
}

function handleStats(msg) {
    state.statsByFrame.set(msg.frame, msg);
    // Stats whose frame never arrives (a reconnect in between) must not pile up.
    for (const frame of state.statsByFrame.keys()) if (frame < msg.frame - 8) state.statsByFrame.delete(frame);
    if (msg.technique && msg.technique !== state.technique && state.techniques.has(msg.technique)) {
        ui.technique.value = msg.technique;
        showTechnique(msg.technique, msg.params);
    }
    if (msg.scene && state.welcome?.scenes?.includes(msg.scene)) ui.scene.value = msg.scene;
    if (msg.params) {
        state.lastParams = msg.params;
        state.paramPanel?.update(msg.params);
    }
}

function handleBinary(buffer) {
    let header;
    try {
        header = parseFrameHeader(buffer);
    } catch (e) {
        showMessage(`bad frame from the server: ${e.message}`);
        return;
    }
    // The snapshot is saved as it arrives: the draw queue below may skip frames.
    if (state.snapshotWanted && state.statsByFrame.get(header.frame)?.snapshot) {
        state.snapshotWanted = false;
        saveSnapshot(header, buffer);
    }
    const frame = { header, buffer, connection: connection.socket };
    if (state.decoding) {
        // With two frames in flight the next one can arrive while this one decodes; keep only the
        // newest and acknowledge the skipped one so that its slot frees.
        if (state.pending) acknowledge(state.pending);
        state.pending = frame;
        return;
    }
    decodeAndDraw(frame);
}

async function decodeAndDraw(frame) {
    state.decoding = true;
    const { header, buffer } = frame;
    try {
        const payload = new Uint8Array(buffer, header.payloadOffset);
        const bitmap = await createImageBitmap(new Blob([payload], { type: CODEC_MIME[header.codec] }));
        if (ui.canvas.width !== header.width || ui.canvas.height !== header.height) {
            ui.canvas.width = header.width;
            ui.canvas.height = header.height;
        }
        ctx.drawImage(bitmap, 0, 0, header.width, header.height);
        bitmap.close();
        recordDraw(header, buffer.byteLength);
    } catch (e) {
        showMessage(`frame ${header.frame} could not be decoded: ${e.message}`);
    } finally {
        // Acknowledge even a frame that failed to decode, else the server would wait forever.
        acknowledge(frame);
        state.decoding = false;
        const next = state.pending;
        state.pending = null;
        if (next) decodeAndDraw(next);
    }
}

function acknowledge(frame) {
    // An ack belongs to the connection that received the frame; after a reconnect it means nothing.
    if (frame.connection === connection.socket) send(ackMsg(frame.header.frame));
}

function saveSnapshot(header, buffer) {
    const blob = new Blob([new Uint8Array(buffer, header.payloadOffset)], { type: CODEC_MIME[header.codec] });
    const scene = (ui.scene.value || 'scene').replace(/[^A-Za-z0-9_-]+/g, '-');
    const link = Object.assign(document.createElement('a'), {
        href: URL.createObjectURL(blob),
        download: `gi-${scene}-${state.technique ?? 'frame'}-${header.frame}.${header.codec}`,
    });
    link.click();
    // The download has started from the object URL by the time the timer runs.
    setTimeout(() => URL.revokeObjectURL(link.href), 1000);
}

// ---------------------------------------------------------------------------------------------
// Role and session controls

/** Viewers watch: the steering controls are hidden and input on the view sends nothing. */
function setRole(viewer) {
    state.viewer = viewer;
    document.body.classList.toggle('viewer', viewer);
    ui.role.textContent = viewer ? 'viewing' : 'controlling';
    ui.share.hidden = viewer;
}

async function copyShareLink() {
    const token = state.welcome?.view_token;
    if (!token) {
        showMessage('no view token yet: wait for the connection');
        return;
    }
    const link = shareLink(window.location, token);
    try {
        await navigator.clipboard.writeText(link);
        showMessage('view-only link copied', 'info');
    } catch {
        // No clipboard (plain http on another host, or permission refused): show the link to copy by hand.
        ui.shareUrl.value = link;
        ui.shareUrl.hidden = false;
        ui.shareUrl.select();
    }
}

function requestSnapshot() {
    if (send(snapshotMsg('png'))) state.snapshotWanted = true;
}

function toggleSession() {
    if (connection.socket || ui.connDot.dataset.state === 'waiting') {
        // A deliberate end: close with 1000 so the server frees the session now.
        sessionStorage.removeItem(RESUME_KEY);
        connection.close();
    } else {
        connection.connect();
    }
}

// ---------------------------------------------------------------------------------------------
// Panel

function fillSelect(select, names, selected) {
    select.replaceChildren(...names.map((n) => new Option(n, n)));
    if (selected !== undefined) select.value = selected;
}

function showTechnique(name, values) {
    state.technique = name;
    const technique = state.techniques.get(name);
    ui.techniqueInfo.textContent = technique
        ? [technique.description, technique.paper ? `(${technique.paper})` : ''].filter(Boolean).join(' ')
        : '';
    const groups = [
        { title: `${name ?? 'technique'} parameters`, schema: technique?.params_schema },
        { title: 'frame parameters', schema: state.welcome?.frame_params_schema },
    ];
    // Frame parameters keep their values across a technique switch; the technique's reset.
    const merged = { ...(state.lastParams ?? {}), ...(values ?? {}) };
    state.paramPanel = buildParamPanel(ui.params, groups, merged, sendParam);
}

function onTechniqueSelected() {
    const name = ui.technique.value;
    if (!send(techniqueMsg(name))) return;
    const technique = state.techniques.get(name);
    const defaults = Object.fromEntries(
        Object.entries(technique?.params_schema?.properties ?? {}).map(([k, s]) => [k, s.default]));
    showTechnique(name, defaults);
}

// ---------------------------------------------------------------------------------------------
// Stats and status

function recordDraw(header, frameBytes) {
    state.drawTimes.push(performance.now());
    const stats = state.statsByFrame.get(header.frame);
    state.statsByFrame.delete(header.frame);
    showStats(header, stats, frameBytes);
}

// Also runs on a timer so that the rate falls to 0 while nothing is drawn.
function showFps() {
    const now = performance.now();
    while (state.drawTimes.length && state.drawTimes[0] < now - FPS_WINDOW_MS) state.drawTimes.shift();
    ui.fps.textContent = `${state.drawTimes.length} fps`;
}

function formatMs(v) {
    return typeof v === 'number' ? v.toFixed(1) : '–';
}

function showStats(header, stats, frameBytes) {
    const bytes = stats?.bytes ?? frameBytes;
    showFps();
    ui.statsLine.textContent = [
        `render ${formatMs(stats?.frame_ms)} ms`,
        `encode ${formatMs(stats?.encode_ms)} ms`,
        `${(bytes / 1024).toFixed(1)} KB`,
        `${header.width}×${header.height} ${stats?.codec ?? header.codec}`,
        stats?.timing ? `(${stats.timing})` : '',
    ].filter(Boolean).join(' · ');
    ui.qualityLine.textContent = [
        `${stats?.quality ?? '–'}${stats?.refined ? ' (refined)' : ''}${stats?.snapshot ? ' snapshot' : ''}`,
        `queue ${formatMs(stats?.queue_ms)} ms`,
        `dropped ${stats?.dropped_frames ?? 0}`,
        `viewers ${stats?.viewers ?? 0}`,
    ].join(' · ');
    ui.passes.replaceChildren(...(stats?.passes ?? []).map((p) => {
        const li = document.createElement('li');
        li.append(Object.assign(document.createElement('span'), { textContent: p.name }),
            Object.assign(document.createElement('span'), { textContent: `${formatMs(p.gpu_ms)} ms` }));
        return li;
    }));
    showPlan(stats?.plan);
}

// The effect plan (frame parameter `effects`): each effect on or off, forced or decided, with the
// server's reason as the tooltip.
function showPlan(plan) {
    const decisions = plan && plan.mode !== 'manual' ? plan.decisions ?? [] : [];
    ui.plan.replaceChildren(...decisions.map((d) => {
        const li = document.createElement('li');
        li.title = d.reason ?? '';
        li.append(Object.assign(document.createElement('span'), { textContent: d.effect }),
            Object.assign(document.createElement('span'), {
                textContent: `${d.enabled ? 'on' : 'off'}${d.forced ? ' (forced)' : ''}`,
            }));
        return li;
    }));
}

function showConnectionState(connState, delayMs) {
    ui.connDot.dataset.state = connState;
    ui.connText.textContent = connState === 'waiting'
        ? `disconnected, retrying in ${(delayMs / 1000).toFixed(1)} s`
        : connState;
    ui.sessionToggle.textContent = connState === 'closed' ? 'Connect' : 'Disconnect';
}

function showMessage(text, kind = 'error') {
    const item = document.createElement('div');
    item.className = `message ${kind}`;
    item.textContent = text;
    ui.messages.append(item);
    // Older messages go first so that a burst of errors cannot fill the view.
    while (ui.messages.children.length > 4) ui.messages.firstChild.remove();
    setTimeout(() => item.remove(), MESSAGE_HIDE_MS);
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
    attachOrbitControls(ui.canvas, camera, sendCamera);
    ui.resetCamera.addEventListener('click', () => {
        camera.reset();
        sendCamera();
    });
    ui.technique.addEventListener('change', onTechniqueSelected);
    ui.scene.addEventListener('change', () => send(sceneMsg(ui.scene.value)));
    ui.adaptive.addEventListener('change', () => send(qualityMsg(ui.adaptive.checked)));
    ui.snapshot.addEventListener('click', requestSnapshot);
    ui.share.addEventListener('click', copyShareLink);
    ui.sessionToggle.addEventListener('click', toggleSession);
    // The viewport changes size with the window and when the panel moves below it.
    new ResizeObserver(debounce(() => sendResize(), RESIZE_DEBOUNCE_MS)).observe(ui.viewport);
    setInterval(showFps, FPS_WINDOW_MS / 4);
    connection.connect();
}

start();
