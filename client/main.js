// App wiring: connection, frame display, side panel and stats.

import {
    ackMsg, cameraMsg, CODEC_MIME, frameSizeFor, helloMsg, paramsMsg, parseFrameHeader,
    parseServerMessage, resizeMsg, sceneMsg, techniqueMsg, validateClientMessage, validateParamValues,
} from './protocol.js';
import { CLIENT_SCHEMAS } from './schemas.js';
import { OrbitCamera, attachOrbitControls } from './camera.js';
import { StreamConnection, streamUrl } from './connection.js';
import { buildParamPanel } from './controls.js';

const RESIZE_DEBOUNCE_MS = 200;
const MESSAGE_HIDE_MS = 6000;
const FPS_WINDOW_MS = 1000;

const $ = (id) => document.getElementById(id);
const ui = {
    canvas: $('view'),
    viewport: $('viewport'),
    connDot: $('conn-dot'),
    connText: $('conn-text'),
    messages: $('messages'),
    scene: $('scene'),
    technique: $('technique'),
    techniqueInfo: $('technique-info'),
    params: $('params'),
    resetCamera: $('reset-camera'),
    fps: $('fps'),
    statsLine: $('stats-line'),
    passes: $('passes'),
    plan: $('plan'),
};
const ctx = ui.canvas.getContext('2d');

const state = {
    welcome: null,
    techniques: new Map(), // name -> technique description from welcome
    technique: null,
    paramPanel: null,
    lastParams: null, // the parameter values of the latest stats
    lastSize: null, // the last size sent, "WxH"
    statsByFrame: new Map(),
    drawTimes: [],
    decoding: false,
    pending: null, // the newest frame that arrived while another was decoding
};

const camera = new OrbitCamera();
const connection = new StreamConnection(streamUrl(window.location), {
    onOpen: handleOpen,
    onText: handleText,
    onBinary: handleBinary,
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

function sendCamera() {
    send(cameraMsg(camera.toCamera()));
}

function sendResize(force = false) {
    const [w, h] = frameSizeFor(ui.viewport.clientWidth, ui.viewport.clientHeight, window.devicePixelRatio);
    const key = `${w}x${h}`;
    if (!force && key === state.lastSize) return;
    if (send(resizeMsg(w, h))) state.lastSize = key;
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

// ---------------------------------------------------------------------------------------------
// Receiving

function handleOpen() {
    state.lastSize = null;
    state.statsByFrame.clear();
    state.pending = null;
    send(helloMsg());
    sendResize(true);
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
    // Not in PROTOCOL.md v0 yet: the server sends the session state after a scene change.
    case 'state': applyState(msg.state ?? {}); break;
    case 'error': showMessage(`${msg.code}${msg.where ? ` at ${msg.where}` : ''}: ${msg.message}`); break;
    case 'pong': break;
    default: console.warn('unhandled server message', msg);
    }
}

function handleWelcome(msg) {
    connection.markHealthy();
    state.welcome = msg;
    state.techniques = new Map((msg.techniques ?? []).map((t) => [t.name, t]));
    const s = msg.state ?? {};
    fillSelect(ui.scene, msg.scenes ?? [], s.scene);
    fillSelect(ui.technique, [...state.techniques.keys()], s.technique);
    state.lastParams = s.params ?? null;
    applyState(s);
}

/** Shows a session state (welcome.state); its camera becomes the one "Reset camera" returns to. */
function applyState(s) {
    if (s.scene !== undefined) ui.scene.value = s.scene;
    if (s.camera) camera.setHome(s.camera);
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
    if (msg.camera) camera.set(msg.camera);
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
    const frame = { header, buffer, connection: connection.socket };
    if (state.decoding) {
        // The server sends one frame at a time, so this only happens with a misbehaving server;
        // keep the newest and acknowledge the skipped one so the stream cannot stall.
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
    // An ack belongs to the session that sent the frame; after a reconnect it means nothing.
    if (frame.connection === connection.socket) send(ackMsg(frame.header.frame));
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

function onSceneSelected() {
    send(sceneMsg(ui.scene.value));
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
        `${header.width}×${header.height} ${header.codec}`,
        stats?.timing ? `(${stats.timing})` : '',
    ].filter(Boolean).join(' · ');
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
}

function showMessage(text) {
    const item = document.createElement('div');
    item.className = 'message';
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
    attachOrbitControls(ui.canvas, camera, sendCamera);
    ui.resetCamera.addEventListener('click', () => {
        camera.reset();
        sendCamera();
    });
    ui.technique.addEventListener('change', onTechniqueSelected);
    ui.scene.addEventListener('change', onSceneSelected);
    // The viewport changes size with the window and when the panel moves below it.
    new ResizeObserver(debounce(() => sendResize(), RESIZE_DEBOUNCE_MS)).observe(ui.viewport);
    setInterval(showFps, FPS_WINDOW_MS / 4);
    connection.connect();
}

start();
