// Interactive benchmark (not a test), without a browser: starts gi-server, connects one WebSocket client
// that asks for a 960x800 view of a scene, orbits the camera around its target (a camera message every
// 30 ms, frames acknowledged as they arrive) and reports the interactive frames' rate against their own
// render time (frame_ms): a rate below 1000 / frame_ms is time the server spends outside the frame.
// Also the frame budget's last reason, size and VPLs, how often the size changed and how many frames
// of other qualities (refinement steps) came between; with WS_ORBIT_DUMP=1 the last frame's passes and
// timings as well. usage:
//   node bench/interactive/ws_orbit.mjs [--server build/ci/bin/gi-server] [--scene builtin:cornell]
//        [--seconds 10] [--server-args "--technique hier_isr"]
import { DEFAULT_SERVER, connectClient, parseOptions, percentile, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:cornell', seconds: 10, 'server-args': '' },
    'usage: node bench/interactive/ws_orbit.mjs [--server PATH] [--scene NAME] [--seconds S] [--server-args "FLAGS"]');
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

// The orbit: the camera turned about the vertical through its target, a step every 30 ms.
const camera = link.state.camera;
let angle = 0;
const orbit = setInterval(() => {
    angle += 0.05;
    const t = camera.target, p = camera.position;
    const r = Math.hypot(p[0] - t[0], p[2] - t[2]), a = Math.atan2(p[2] - t[2], p[0] - t[0]) + angle;
    link.send({ type: 'camera', position: [t[0] + r * Math.cos(a), p[1], t[2] + r * Math.sin(a)], target: t,
        up: [0, 1, 0], fov_deg: camera.fov_deg });
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
console.log(JSON.stringify({ scene: opts.scene, frames: frames.length, fps: +((frames.length - 1) / span).toFixed(2),
    cadence_ms: +(1000 * span / (frames.length - 1)).toFixed(1),
    frame_ms_p50: +percentile(frames.map((f) => f.stats.frame_ms), 0.5).toFixed(1),
    size: last.size, vpls: last.counts?.vpl_count ?? null, budget: last.budget?.reason ?? null,
    other_frames: seen.length - frames.length,
    // Frames whose size differs from the frame before: each resizes the technique's targets.
    size_changes: frames.filter((f, i) => i > 0 && String(f.stats.size) !== String(frames[i - 1].stats.size)).length }));
if (process.env.WS_ORBIT_DUMP)
    console.log(JSON.stringify({ passes: last.passes, timing: last.timing, input: last.input,
        readback: last.readback_ms, technique_ms: last.technique_ms }));
link.ws.close();
server.kill();
process.exit(0);
