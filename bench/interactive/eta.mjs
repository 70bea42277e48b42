// Refinement time-left benchmark (not a test): starts gi-server, connects one WebSocket client with a
// 960x800 view of a scene, leaves the view still and reports, for each refinement step, what the
// server said before it began (the VPLs it renders and why, or that it skipped the step) and how long
// it took, and the time left it announced (stats.refine.eta_ms) against the time the step really had
// left, at a quarter, half and three quarters of its image. usage:
//   node bench/interactive/eta.mjs [--server build/ci/bin/gi-server] [--scene builtin:cornell]
//        [--technique T] [--params '{"vpl_grid": 64}'] [--seconds 60] [--verbose 1]
//        [--server-args "--scene-dir tests/data/corpus"] (then --scene file:colonnade.glb)
import WebSocket from 'ws';

import { DEFAULT_SERVER, parseOptions, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:cornell', technique: '', params: '', seconds: 60, verbose: 0, 'server-args': '' },
    'usage: node bench/interactive/eta.mjs [--server PATH] [--scene NAME] [--technique T] [--params JSON] [--seconds S] [--verbose 1] [--server-args "FLAGS"]');
const { server, port } = await startServer(opts.server, opts['server-args'].split(' ').filter(Boolean));
const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
const steps = new Map(); // step -> {announced, vpls, parts, sends: [{t, share, eta}], end}
const stepOf = (name) => {
    if (!steps.has(name)) steps.set(name, { announced: null, vpls: null, parts: 0, sends: [], end: null, start: null });
    return steps.get(name);
};
ws.on('open', () => {
    ws.send(JSON.stringify({ type: 'hello', protocol: 2, size: [960, 800], dpr: 1, max_in_flight: 2,
        codecs: ['webp', 'jpeg'], patches: true }));
    ws.send(JSON.stringify({ type: 'scene', name: opts.scene }));
    if (opts.technique) ws.send(JSON.stringify({ type: 'technique', name: opts.technique }));
    if (opts.params) ws.send(JSON.stringify({ type: 'params', values: JSON.parse(opts.params) }));
});
ws.on('message', (data, isBinary) => {
    if (isBinary) return;
    const m = JSON.parse(data.toString());
    const now = Date.now();
    if (m.type === 'stats' && m.frame !== undefined) ws.send(JSON.stringify({ type: 'ack', frame: m.frame }));
    if (m.type === 'progress' && m.step !== 'scene' && ['refining', 'skipped'].includes(m.state)
        && !/measuring the scene/.test(m.reason)) {
        const s = stepOf(m.step);
        s.announced = { state: m.state, eta: m.eta_ms, reason: m.reason };
        s.start = now;
        s.sends = [];
        s.end = null;
    }
    if (m.type === 'stats' && m.refine && m.scene === opts.scene) {
        const s = stepOf(m.refine.step);
        s.vpls = m.counts?.vpl_count ?? s.vpls;
        s.parts = Math.max(s.parts, m.refine.vpl_parts ?? 1);
        s.sends.push({ t: now, share: m.refine.share, eta: m.refine.eta_ms });
        if (m.refine.complete) s.end = now;
        if (opts.verbose) console.log(JSON.stringify({ step: m.refine.step, share: m.refine.share, eta_ms: m.refine.eta_ms }));
    }
});
await sleep(opts.seconds * 1000);
const rows = [];
for (const [name, s] of steps) {
    const at = (share) => {
        const send = s.sends.find((x) => x.share >= share);
        if (!send || s.end === null) return null;
        return { said_s: send.eta === null ? null : +(send.eta / 1000).toFixed(1), left_s: +((s.end - send.t) / 1000).toFixed(1) };
    };
    rows.push({ scene: opts.scene, step: name, announced: s.announced?.state ?? null,
        announced_eta_s: s.announced?.eta == null ? null : +(s.announced.eta / 1000).toFixed(1),
        reason: s.announced?.reason ?? null, vpls: s.vpls, max_vpl_parts: s.parts,
        took_s: s.end !== null && s.start !== null ? +((s.end - s.start) / 1000).toFixed(1) : null,
        quarter: at(0.25), half: at(0.5), three_quarters: at(0.75) });
}
for (const r of rows) console.log(JSON.stringify(r));
server.kill();
process.exit(0);
