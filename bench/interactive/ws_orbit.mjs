// Interactive benchmark (not a test), without a browser: starts gi-server, connects one WebSocket client
// that asks for a 960x800 view of a scene, orbits the camera around its target (a camera message every
// 30 ms, frames acknowledged as they arrive) and reports the interactive frames' rate against their own
// render time (frame_ms): a rate below 1000 / frame_ms is time the server spends outside the frame.
// Also the frame budget's last reason, size and VPLs, how often the size changed and how many frames
// of other qualities (refinement steps) came between; with
// WS_ORBIT_DUMP=1 the last frame's passes and timings as well. usage:
//   node bench/interactive/ws_orbit.mjs [--server build/ci/bin/gi-server] [--scene builtin:cornell]
//        [--seconds 10] [--server-args "--technique hier_isr"]
import WebSocket from 'ws';

import { DEFAULT_SERVER, parseOptions, percentile, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:cornell', seconds: 10, 'server-args': '' },
    'usage: node bench/interactive/ws_orbit.mjs [--server PATH] [--scene NAME] [--seconds S] [--server-args "FLAGS"]');
const { server, port, log } = await startServer(opts.server,
    opts['server-args'] ? opts['server-args'].split(' ').filter(Boolean) : []);
const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
let camera = null, shown = false, angle = 0;
const frames = [];
const others = []; // frames of other qualities (refinement steps) while orbiting
ws.on('open', () => {
    ws.send(JSON.stringify({ type: 'hello', protocol: 2, size: [960, 800], dpr: 1, max_in_flight: 2, codecs: ['jpeg'] }));
    ws.send(JSON.stringify({ type: 'scene', name: opts.scene }));
});
ws.on('message', (data, binary) => {
    if (binary) {
        ws.send(JSON.stringify({ type: 'ack', frame: data.readUInt32LE(4) }));
        return;
    }
    const m = JSON.parse(data.toString());
    if (m.type === 'state' && m.state?.camera) camera = m.state.camera;
    if (m.type === 'error') console.error(`server: ${m.message}`);
    if (m.type !== 'stats' || m.scene !== opts.scene) return;
    // Two seconds of orbit before counting: the budget settles on its size and VPLs.
    if (!shown) setTimeout(() => { frames.splice(0); others.splice(0); }, 2000);
    shown = true;
    if (m.quality === 'interactive') frames.push({ t: Date.now(), ms: m.frame_ms, m });
    else others.push(m.quality);
});
const orbit = setInterval(() => {
    if (!shown || !camera) return;
    angle += 0.05;
    const t = camera.target, p = camera.position;
    const r = Math.hypot(p[0] - t[0], p[2] - t[2]), a = Math.atan2(p[2] - t[2], p[0] - t[0]) + angle;
    ws.send(JSON.stringify({ type: 'camera', position: [t[0] + r * Math.cos(a), p[1], t[2] + r * Math.sin(a)],
        target: t, up: [0, 1, 0], fov_deg: camera.fov_deg }));
}, 30);
setTimeout(() => {
    clearInterval(orbit);
    if (frames.length < 2) {
        console.error(`no interactive frames of ${opts.scene}; the server's log:\n${log()}`);
        server.kill();
        process.exit(1);
    }
    const span = (frames.at(-1).t - frames[0].t) / 1000;
    const last = frames.at(-1).m;
    const report = { scene: opts.scene, frames: frames.length, fps: +((frames.length - 1) / span).toFixed(2),
        cadence_ms: +(1000 * span / (frames.length - 1)).toFixed(1),
        frame_ms_p50: +percentile(frames.map((f) => f.ms), 0.5).toFixed(1),
        size: last.size, vpls: last.counts?.vpl_count ?? null, budget: last.budget?.reason ?? null,
        // Frames whose size differs from the frame before: each resizes the technique's targets.
        other_frames: others.length,
        size_changes: frames.filter((f, i) => i > 0 && String(f.m.size) !== String(frames[i - 1].m.size)).length };
    console.log(JSON.stringify(report));
    if (process.env.WS_ORBIT_DUMP) console.log(JSON.stringify({ passes: last.passes, timing: last.timing, input: last.input, readback: last.readback_ms, technique_ms: last.technique_ms }));
    server.kill();
    process.exit(0);
}, (opts.seconds + 4) * 1000);
