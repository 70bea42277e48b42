// Interactive benchmark (not a test): starts gi-server with its defaults, opens the real browser
// client (headless Chromium over loopback) in a 960x800 viewport and measures, per built-in scene:
//   - orbit fps: frames drawn per second while the arrow key orbits the camera,
//   - input -> frame from a still view: from a key press (after refinement finished) to the first
//     interactive frame drawn, p50 and p95, against that frame's own render + encode time,
//   - input during refinement: the same, pressed while a slow configuration (rsm_gather with 65,536
//     VPLs, hier_isr with tau 0) refines in tiles (`--refinement 0` leaves these out),
//   - the page's own work while orbiting: the share of one core its main thread was busy
//     (`orbit_page_busy`, Chromium's TaskDuration), time the server's two cores did not get.
// Each press is timed twice: from this script's key dispatch to the page's next animation frame after
// the draw (`still_input_to_frame_ms`, `input_to_frame_ms`), and in the page, from the key event to the
// frame drawn on the canvas (`still_in_page`, `in_page`, with where the time went: `decodeDraw` from the
// frame's arrival to its draw, `decode` the decode alone, `sockets` both ways through the sockets, and
// `socketIn` / `socketOut` the same split by the server's wall clock at the input's arrival).
// Figures are measured side by side in one run on whatever machine runs it; docs/interactive.md has
// the ones recorded. usage:
//   node bench/interactive/orbit.mjs [--server build/ci/bin/gi-server] [--scenes a,b] [--presses 10]
//        [--orbit-s 6] [--still-s 3] [--chromium /usr/bin/chromium] [--out report.json]
//        [--server-args "--slice-ms 20"] [--server-nice 10] [--refinement 0]
//        [--refine-cases rsm_gather,hier_isr] (which slow configurations; --scenes none: only those)
import { writeFileSync } from 'node:fs';

import { DEFAULT_SERVER, parseOptions, percentile, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scenes: '', presses: 10, 'orbit-s': 6, 'still-s': 3,
    chromium: process.env.GI_CHROMIUM ?? '/usr/bin/chromium', out: '', 'server-args': '', verbose: 0, 'server-nice': 0, refinement: 1,
    'refine-cases': 'rsm_gather,hier_isr' },
'usage: node bench/interactive/orbit.mjs [--server PATH] [--scenes a,b] [--presses N] [--orbit-s S] [--still-s S] [--chromium PATH] [--out FILE] [--server-args "FLAGS"] [--server-nice 0..19] [--refinement 0|1] [--refine-cases rsm_gather,hier_isr]');
// The slow configurations pressed during refinement: the slowest each parameter table allows.
const refineCases = { rsm_gather: { vpl_grid: 256 }, hier_isr: { tau: 0 } };
const chosenCases = opts['refine-cases'].split(',').filter(Boolean);
for (const name of chosenCases)
    if (!refineCases[name]) {
        console.error(`orbit: unknown --refine-cases entry '${name}' (known: ${Object.keys(refineCases).join(', ')})`);
        process.exit(2);
    }

const serverArgs = opts['server-args'] ? opts['server-args'].split(' ').filter(Boolean) : [];
// --server-nice N: the server below the browser's CPU priority (bench/lib.mjs, startServer).
const { server, port, log: serverLog } = await startServer(opts.server, serverArgs, { nice: opts['server-nice'] });

const { chromium } = await import('playwright-core');
const browser = await chromium.launch({ executablePath: opts.chromium,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--disable-background-timer-throttling',
        '--disable-renderer-backgrounding'] });
const page = await (await browser.newContext({ viewport: { width: 960 + 320, height: 800 } })).newPage();
// The socket's traffic as this process sees it (through the browser's debugging protocol, so a few ms
// late): when camera messages left and when interactive frames' stats arrived, for the breakdown.
const wire = { cameraSent: [], interactiveStats: [], errors: [] };
page.on('websocket', (ws) => {
    ws.on('framesent', ({ payload }) => {
        if (typeof payload === 'string' && payload.includes('"camera"')) wire.cameraSent.push(Date.now());
    });
    ws.on('framereceived', ({ payload }) => {
        if (typeof payload === 'string' && payload.includes('"stats"') && payload.includes('"interactive"'))
            wire.interactiveStats.push(Date.now());
        if (typeof payload === 'string' && payload.includes('"error"')) {
            try {
                const m = JSON.parse(payload);
                if (m.type === 'error') wire.errors.push({ t: Date.now(), message: m.message ?? payload, request: m.request });
            } catch { /* not JSON: not an error message */ }
        }
    });
});
await page.goto(`http://127.0.0.1:${port}/`);
const until = async (what, fn, arg, timeoutMs = 120000) => {
    try {
        await page.waitForFunction(fn, arg, { timeout: timeoutMs, polling: 20 });
    } catch (e) {
        throw new Error(`timed out waiting for ${what}`);
    }
};
await until('the first frame', () => window.giClient?.framesDrawn > 0);
// Every drawn frame with its time (epoch ms) and stats, recorded in the page.
await page.evaluate(() => {
    window.benchDraws = [];
    let seen = window.giClient.framesDrawn;
    const poll = () => {
        const n = window.giClient.framesDrawn;
        if (n !== seen) {
            seen = n;
            const s = window.giClient.lastStats ?? {};
            const timing = window.giClient.lastDrawTiming;
            window.benchDraws.push({ t: performance.timeOrigin + performance.now(), quality: s.quality,
                ms: (s.frame_ms ?? 0) + (s.encode_ms ?? 0), refine: s.refine ?? null, size: s.size,
                vpls: s.counts?.vpl_count ?? null,
                input: s.input ?? null, encode: s.encode_ms ?? 0, drawnAt: timing.drawnAt,
                arrivedAt: timing.arrivedAt, decodeMs: timing.decodeMs });
        }
        requestAnimationFrame(poll);
    };
    requestAnimationFrame(poll);
    // Each key press as the page received it (the event's own time), and when the client's camera
    // message for it left: this listener runs after the view's, whose message goes out in a microtask
    // of the same event.
    window.benchKeys = [];
    window.addEventListener('keydown', (e) => {
        if (!e.repeat) window.benchKeys.push({ at: performance.timeOrigin + e.timeStamp,
            steerAt: window.giClient.lastDrawTiming.steerAt });
    });
});
// The renderer's main-thread time (script, style, layout, paint), cumulative seconds.
const cdp = await page.context().newCDPSession(page);
await cdp.send('Performance.enable');
const pageTaskS = async () => (await cdp.send('Performance.getMetrics')).metrics
    .find((m) => m.name === 'TaskDuration')?.value ?? null;
const view = await page.$('canvas') ?? await page.$('#view');
const box = await view.boundingBox();
await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2); // focus for the keys
const scenes = opts.scenes === 'none' ? [] : opts.scenes ? opts.scenes.split(',') : (await page.evaluate(() => window.giClient.welcome.scenes))
    .filter((s) => s.startsWith('builtin:'));
const viewport = await page.evaluate(() => window.giClient.viewport);
const draws = (since) => page.evaluate((t) => window.benchDraws.filter((d) => d.t >= t), since);
// A still view: refinement finished, or (a final step can take the refinement budget, 30 s) at most
// --still-s seconds after the last input, when the view refines in tiles.
const still = async () => until('refinement done',
    () => { const d = window.benchDraws.at(-1); return d && d.quality === 'final' && d.refine?.complete; }, null,
    opts['still-s'] * 1000).catch(() => {});

async function pressLatency(key) {
    // The view moves while a key is held, one step per animation frame: hold it for two frames.
    const t0 = Date.now();
    await page.keyboard.down(key);
    await sleep(40);
    await page.keyboard.up(key);
    await until('an interactive frame', (t) => window.benchDraws.some((d) => d.t > t && d.quality === 'interactive'), t0, 30000);
    const d = (await draws(t0)).find((x) => x.quality === 'interactive');
    const sent = wire.cameraSent.find((t) => t >= t0);
    const arrived = wire.interactiveStats.find((t) => t >= t0);
    const keyEvent = await page.evaluate((t) => window.benchKeys.find((k) => k.at >= t - 5) ?? null, t0);
    // Measured in the page from the key event (as the browser's own input-latency metrics count it):
    // the harness's dispatch of the key through the DevTools protocol is left out, and the frame counts
    // as shown when drawn on the canvas rather than at the page's next animation frame.
    const inPage = keyEvent && d.drawnAt ? {
        fromKey: d.drawnAt - keyEvent.at,
        client: keyEvent.steerAt !== null && keyEvent.steerAt >= keyEvent.at - 1 ? keyEvent.steerAt - keyEvent.at : null,
        server: keyEvent.steerAt !== null && d.arrivedAt ? d.arrivedAt - keyEvent.steerAt : null,
        decodeDraw: d.arrivedAt ? d.drawnAt - d.arrivedAt : null,
        // Of that, the decode itself (createImageBitmap); the rest waited for a decode ahead of it.
        decode: d.decodeMs ?? null,
        dispatch: keyEvent.at - t0, toAnimationFrame: d.t - d.drawnAt,
        // The camera message's way to the server and the frame's way back (both sockets, the server's
        // network thread and the page's message handling): the server part less the server's own time
        // from the input's arrival to the encoded frame.
        sockets: keyEvent.steerAt !== null && d.arrivedAt && d.input?.rendered_ms !== undefined
            ? d.arrivedAt - keyEvent.steerAt - d.input.rendered_ms - d.encode : null,
        // The same split by the server's wall clock at the input's arrival (one machine, one clock):
        // the camera message's way in, and the encoded frame's way out to the page's handler.
        socketIn: keyEvent.steerAt !== null && d.input?.arrived_unix_ms !== undefined
            ? d.input.arrived_unix_ms - keyEvent.steerAt : null,
        socketOut: d.arrivedAt && d.input?.arrived_unix_ms !== undefined
            ? d.arrivedAt - d.input.arrived_unix_ms - d.input.rendered_ms - d.encode : null,
    } : null;
    return { latency: d.t - t0, frameMs: d.ms, inputWait: d.input?.wait_ms ?? null, windowWait: d.input?.window_wait_ms ?? null, toSend: sent ? sent - t0 : null,
        toStats: arrived && sent ? arrived - sent : null, toDraw: arrived ? d.t - arrived : null, inPage };
}

// The in-page figures of a set of presses: from the key event to the frame drawn, that less the frame's
// own render + encode, and where the time went (p50 and p95 of each part).
function inPageSummary(results) {
    const pressed = results.filter((r) => r.inPage);
    if (!pressed.length) return null;
    const pcts = (v) => ({ p50: percentile(v, 0.5), p95: percentile(v, 0.95) });
    const parts = {};
    for (const k of ['dispatch', 'client', 'server', 'sockets', 'socketIn', 'socketOut', 'decodeDraw', 'decode', 'toAnimationFrame']) {
        const v = pressed.map((r) => r.inPage[k]).filter((x) => x !== null && x !== undefined);
        if (v.length) parts[k] = pcts(v);
    }
    return { from_key_to_drawn_ms: pcts(pressed.map((r) => r.inPage.fromKey)),
        beyond_frame_ms: pcts(pressed.map((r) => r.inPage.fromKey - r.frameMs)), parts_ms: parts,
        presses: pressed.length };
}

// A built-in scene may be named without its prefix on the command line; the server knows it with it.
const sceneName = (name) => (name.includes(':') || /\.(glb|gltf|zip)$/i.test(name) ? name : `builtin:${name}`);

// Frames of `scene` are being drawn (a name the server refuses would otherwise leave the previous scene
// measured under the new name).
async function untilSceneShown(scene, since) {
    const refusal = () => wire.errors.find((x) => x.t >= since && x.request === 'scene');
    for (const end = Date.now() + 60000; Date.now() < end;) {
        if (await page.evaluate((name) => window.giClient.lastStats?.scene === name, scene)) return;
        // The server's refusal (an unknown name, a file that failed to load) ends the wait.
        if (refusal()) throw new Error(`${scene}: the server said "${refusal().message}"`);
        await sleep(100);
    }
    throw new Error(`timed out waiting for frames of ${scene} (is the name right?)`);
}

async function measureScene(requested, technique, params) {
    const scene = sceneName(requested);
    const asked = Date.now();
    await page.evaluate(({ scene, technique, params }) => {
        window.giClient.send?.({ type: 'scene', name: scene });
        // No technique: the server's default (presets/presets.json's measured default_technique).
        if (technique) window.giClient.send?.({ type: 'technique', name: technique });
        if (params) window.giClient.send?.({ type: 'params', values: params });
    }, { scene, technique, params });
    await untilSceneShown(scene, asked);
    await sleep(1500);
    technique ??= await page.evaluate(() => window.giClient.lastStats?.technique ?? null);
    // Orbit: hold the left arrow.
    const orbitStart = Date.now();
    await page.keyboard.down('ArrowLeft');
    await sleep(1000);
    const busyFrom = { task: await pageTaskS(), at: Date.now() };
    await sleep(opts['orbit-s'] * 1000 - 1000);
    const busyTo = { task: await pageTaskS(), at: Date.now() };
    await page.keyboard.up('ArrowLeft');
    const pageBusy = busyFrom.task !== null && busyTo.task !== null && busyTo.at > busyFrom.at
        ? (busyTo.task - busyFrom.task) / ((busyTo.at - busyFrom.at) / 1000) : null;
    const orbit = (await draws(orbitStart + 1000)).filter((d) => d.t <= orbitStart + opts['orbit-s'] * 1000);
    const fps = orbit.length > 1 ? (orbit.length - 1) / ((orbit.at(-1).t - orbit[0].t) / 1000) : 0;
    const frameMs = orbit.map((d) => d.ms);
    // Input from a still view.
    const stillLat = [], stillFrame = [], parts = { toSend: [], inputWait: [], toStats: [], toDraw: [] };
    const results = [];
    for (let i = 0; i < opts.presses; i++) {
        await still();
        const r = await pressLatency(i % 2 ? 'ArrowLeft' : 'ArrowRight');
        results.push(r);
        if (opts.verbose) console.error('still press', JSON.stringify(r));
        stillLat.push(r.latency);
        stillFrame.push(r.frameMs);
        for (const k of Object.keys(parts)) if (r[k] !== null) parts[k].push(r[k]);
    }
    // Where the time goes, medians: key press -> camera message on the socket -> the frame's stats
    // back -> the frame drawn.
    const breakdown = Object.fromEntries(Object.entries(parts).map(([k, v]) => [k, percentile(v, 0.5)]));
    // Each press's time beyond its own frame (render + encode): what the bound's 30 ms allows.
    const over = stillLat.map((l, i) => l - stillFrame[i]);
    return { scene, technique, params: params ?? {}, orbit_fps: +fps.toFixed(2), orbit_frame_ms_p50: percentile(frameMs, 0.5),
        still_input_to_frame_ms: { p50: percentile(stillLat, 0.5), p95: percentile(stillLat, 0.95) },
        still_frame_ms_p50: percentile(stillFrame, 0.5),
        still_over_frame_ms: { p50: percentile(over, 0.5), p95: percentile(over, 0.95) },
        still_input_wait_ms: { p50: percentile(parts.inputWait, 0.5), p95: percentile(parts.inputWait, 0.95) },
        still_breakdown_ms_p50: breakdown, still_in_page: inPageSummary(results), presses: stillLat.length,
        last_size: orbit.at(-1)?.size,
        orbit_page_busy: pageBusy === null ? null : +pageBusy.toFixed(3),
        // The VPLs the frame budget left the orbit's frames (p50): with the size, what its time bought.
        orbit_vpls_p50: percentile(orbit.map((d) => d.vpls).filter((v) => v !== null), 0.5) ?? null };
}

async function duringRefinement(scene, technique, params) {
    const asked = Date.now();
    await page.evaluate(({ scene, technique, params }) => {
        window.giClient.send?.({ type: 'scene', name: scene });
        window.giClient.send?.({ type: 'technique', name: technique });
        window.giClient.send?.({ type: 'params', values: params });
    }, { scene, technique, params });
    await untilSceneShown(scene, asked);
    const lat = [], frame = [], waits = [], results = [];
    let refining = 0;
    for (let i = 0; i < opts.presses; i++) {
        const t = Date.now();
        // A step over the refinement budget that cannot be made cheaper is skipped: then the input
        // comes to a still view.
        const tile = await until('a refinement tile', (s) => window.benchDraws.some((d) => d.t > s && d.refine && !d.refine.complete), t, 20000)
            .then(() => true, () => false);
        if (tile) refining++;
        await sleep(50 + 37 * (i % 3)); // somewhere inside a tile
        const r = await pressLatency(i % 2 ? 'ArrowLeft' : 'ArrowRight');
        results.push(r);
        if (opts.verbose) console.error('refining press', JSON.stringify(r));
        lat.push(r.latency);
        frame.push(r.frameMs);
        if (r.inputWait !== null) waits.push(r.inputWait);
    }
    const over = lat.map((l, i) => l - frame[i]);
    return { scene, technique, params, input_to_frame_ms: { p50: percentile(lat, 0.5), p95: percentile(lat, 0.95) },
        over_frame_ms: { p50: percentile(over, 0.5), p95: percentile(over, 0.95) },
        input_wait_ms: { p50: percentile(waits, 0.5), p95: percentile(waits, 0.95) },
        in_page: inPageSummary(results), frame_ms_p50: percentile(frame, 0.5), presses: lat.length,
        presses_during_refinement: refining };
}

const report = { viewport, machine: process.env.GI_BENCH_MACHINE ?? null, server_nice: opts['server-nice'], scenes: [], refinement: [] };
try {
    for (const scene of scenes) {
        const r = await measureScene(scene, null);
        report.scenes.push(r);
        console.log(JSON.stringify(r));
    }
    for (const [technique, params] of opts.refinement ? chosenCases.map((name) => [name, refineCases[name]]) : []) {
        const r = await duringRefinement('builtin:cornell', technique, params);
        report.refinement.push(r);
        console.log(JSON.stringify(r));
    }
} catch (e) {
    // A press that got no frame is rare and not reproducible on demand: keep what explains it (the
    // server's log, the page's last frames and the client's state) before giving up.
    const last = await page.evaluate(() => ({ draws: (window.benchDraws ?? []).slice(-8),
        connection: document.querySelector('#conn-text')?.textContent ?? null,
        busy: document.querySelector('#busy')?.textContent ?? null,
        lastStats: window.giClient?.lastStats ?? null })).catch(() => null);
    console.error(`orbit: ${e.message}\n-- the page's last frames and state:\n${JSON.stringify(last, null, 1)}` +
        `\n-- the server's log, last 60 lines:\n${serverLog().split('\n').slice(-60).join('\n')}`);
    if (process.env.GI_SERVER_LOG) writeFileSync(process.env.GI_SERVER_LOG, serverLog());
    await browser.close();
    server.kill('SIGINT');
    process.exit(1);
}
if (opts.out) writeFileSync(opts.out, JSON.stringify(report, null, 2));
if (process.env.GI_SERVER_LOG) writeFileSync(process.env.GI_SERVER_LOG, serverLog());
await browser.close();
server.kill('SIGINT');
