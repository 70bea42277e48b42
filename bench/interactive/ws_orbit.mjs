// Interactive benchmark (not a test), without a browser: starts gi-server, connects one WebSocket client
// that asks for a 960x800 view of a scene, orbits the camera around its target (a camera message every
// 30 ms, frames acknowledged as they arrive) and reports the interactive frames' rate against their own
// render time (frame_ms): a rate below 1000 / frame_ms is time the server spends outside the frame.
// Also the frame budget's last reason, size and VPLs, how often the size changed and how many frames
// of other qualities (refinement steps) came between, the frames' p95 and slowest render time, how many
// the receiver cap gave fewer VPLs, and frames rendered but never received; with WS_ORBIT_DUMP=1 the
// last frame's passes and timings as well, with --slow-ms each frame slower than that, with --first N
// the session's first N interactive frames (how the budget starts); with --technique (and --params)
// the client switches to that technique once the scene is up, as a user does, and --first lists the
// frames from the switch on. usage:
//   node bench/interactive/ws_orbit.mjs [--server build/ci/bin/gi-server] [--scene builtin:cornell]
//        [--seconds 10] [--server-args "--technique hier_isr"] [--slow-ms 150] [--first 12]
//        [--technique hier_isr] [--params '{"tau": 0}']
import { DEFAULT_SERVER, connectClient, jsonOption, parseOptions, percentile, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:cornell', seconds: 10, 'server-args': '', 'slow-ms': 0,
    first: 0, technique: '', params: '' },
'usage: node bench/interactive/ws_orbit.mjs [--server PATH] [--scene NAME] [--seconds S] [--server-args "FLAGS"] [--slow-ms MS] [--first N] [--technique T] [--params JSON]');
const params = jsonOption(opts, 'params', 'ws_orbit');
const { server, port, log } = await startServer(opts.server,
    opts['server-args'] ? opts['server-args'].split(' ').filter(Boolean) : []);
const link = await connectClient(port, { client: 'ws_orbit', size: [960, 800] });
try {
    await link.until('the welcome', () => link.state);
    link.send({ type: 'scene', name: opts.scene });
    await link.until(`frames of ${opts.scene}`, () => link.stats?.scene === opts.scene, 120000);
} catch (e) {
    console.error(`${e.message}; the server's log:\n${log()}`);
    process.exit(1);
}
const switchedFrom = link.frames.length;
try {
    if (opts.technique) {
        link.send({ type: 'technique', name: opts.technique });
        if (Object.keys(params).length) link.send({ type: 'params', values: params });
        await link.until(`frames of ${opts.technique}`, () => link.stats?.technique === opts.technique, 60000);
    } else if (Object.keys(params).length) {
        link.send({ type: 'params', values: params });
    }
} catch (e) {
    console.error(`${e.message}; the server's log:\n${log()}`);
    process.exit(1);
}

// The orbit: the camera turned about the vertical through its target, a step every 30 ms.
const camera = link.state.camera;
let angle = 0;
const sent = []; // the cameras sent, with the time: a slow frame's view can be rendered again
const orbit = setInterval(() => {
    angle += 0.05;
    const t = camera.target, p = camera.position;
    const r = Math.hypot(p[0] - t[0], p[2] - t[2]), a = Math.atan2(p[2] - t[2], p[0] - t[0]) + angle;
    const view = { position: [t[0] + r * Math.cos(a), p[1], t[2] + r * Math.sin(a)], target: t, fov_deg: camera.fov_deg };
    sent.push({ at: performance.now(), ...view });
    link.send({ type: 'camera', ...view, up: [0, 1, 0] });
}, 30);
// Two seconds before counting: the budget settles on its size and VPLs.
await sleep(2000);
const from = link.frames.length;
await sleep(opts.seconds * 1000);
clearInterval(orbit);

const seen = link.frames.slice(from).filter((f) => f.stats.scene === opts.scene);
const frames = seen.filter((f) => f.stats.quality === 'interactive');
if (frames.length < 2) {
    console.error(`no interactive frames of ${opts.scene}; the server's log:\n${log()}`);
    process.exit(1);
}
const span = (frames.at(-1).at - frames[0].at) / 1000;
const last = frames.at(-1).stats;
const p50 = (pick) => {
    const values = frames.map(pick).filter((v) => typeof v === 'number');
    return values.length ? +percentile(values, 0.5).toFixed(1) : null;
};
console.log(JSON.stringify({ scene: opts.scene, frames: frames.length, fps: +((frames.length - 1) / span).toFixed(2),
    cadence_ms: +(1000 * span / (frames.length - 1)).toFixed(1),
    frame_ms_p50: +percentile(frames.map((f) => f.stats.frame_ms), 0.5).toFixed(1),
    frame_ms_p95: +percentile(frames.map((f) => f.stats.frame_ms), 0.95).toFixed(1),
    frame_ms_max: +Math.max(...frames.map((f) => f.stats.frame_ms)).toFixed(1),
    // Frames the budget's receiver cap gave fewer VPLs.
    receiver_capped: frames.filter((f) => f.stats.counts?.receiver_share_capped_vpls).length,
    size: last.size, vpls: last.counts?.vpl_count ?? null, budget: last.budget?.reason ?? null,
    // Where a frame's time goes besides rendering: encoding, the wait for the GL worker (queue), the
    // wait for input or for the client's acknowledgements (window); what remains of the cadence is
    // time the server spent outside all of them.
    encode_ms_p50: p50((f) => f.stats.encode_ms), queue_ms_p50: p50((f) => f.stats.queue_ms),
    input_wait_ms_p50: p50((f) => f.stats.input?.wait_ms), window_wait_ms_p50: p50((f) => f.stats.input?.window_wait_ms),
    other_frames: seen.length - frames.length,
    // Frames the server rendered that never reached this client (replaced in its send queue, or
    // refused by the window of unacknowledged frames): the gaps in the frame numbers received.
    dropped: seen.reduce((n, f, i) => n + (i > 0 ? Math.max(f.stats.frame - seen[i - 1].stats.frame - 1, 0) : 0), 0),
    // Frames whose size differs from the frame before: each resizes the technique's targets.
    size_changes: frames.filter((f, i) => i > 0 && String(f.stats.size) !== String(frames[i - 1].stats.size)).length }));
// Each frame over --slow-ms: its passes over 5 ms, its receivers and VPLs, and the last camera sent
// before it started (the view to render again with gi-render --request).
for (const f of opts['slow-ms'] > 0 ? frames.filter((f) => f.stats.frame_ms > opts['slow-ms']) : []) {
    const c = f.stats.counts ?? {};
    console.log(JSON.stringify({ slow_frame: f.stats.frame, frame_ms: +f.stats.frame_ms.toFixed(1), size: f.stats.size,
        passes: f.stats.passes.filter((p) => p.gpu_ms > 5).map((p) => [p.name, +p.gpu_ms.toFixed(1)]),
        receivers: c.receivers_total ?? null, vpls: c.vpl_count ?? null,
        receiver_share_capped_vpls: c.receiver_share_capped_vpls ?? null,
        camera: sent.filter((s) => s.at < f.at - f.stats.frame_ms).at(-1) ?? null }));
}
if (process.env.WS_ORBIT_DUMP)
    console.log(JSON.stringify({ passes: last.passes, timing: last.timing, input: last.input,
        readback: last.readback_ms, technique_ms: last.technique_ms }));
link.ws.close();
// The session's first interactive frames, from the connection on (from the switch to --technique on):
// what the budget chose before it had measured much.
const firstFrames = opts.technique
    ? link.frames.slice(switchedFrom).filter((x) => x.stats.technique === opts.technique)
    : link.frames;
for (const f of firstFrames.filter((x) => x.stats.quality === 'interactive').slice(0, opts.first)) {
    console.log(JSON.stringify({ first_frame: f.stats.frame, technique: f.stats.technique, size: f.stats.size,
        vpls: f.stats.counts?.vpl_count ?? null, frame_ms: +f.stats.frame_ms.toFixed(1),
        technique_ms: +(f.stats.technique_ms ?? 0).toFixed(1), budget: f.stats.budget?.reason ?? null }));
}
server.kill();
process.exit(0);
