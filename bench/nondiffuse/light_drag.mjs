// Light-drag benchmark (not a test): starts gi-server with its defaults on a scene with environment
// probes, and for each arm opens a session (960 x 800, as the web client) that moves the first light
// every --interval-ms for --seconds, so every frame renders the probes again. Arms alternate
// (--rounds each): "budget" leaves env_budget_ms to the session (a quarter of its frame target),
// "none" sets it to 0 (every probe at env_size). Prints per arm the interactive frames' frame_ms and
// probe-pass ms (p50 / p95), frames received, and the probe plans seen.
//
// usage: node bench/nondiffuse/light_drag.mjs [--server build/ci/bin/gi-server] [--scene builtin:gallery]
//        [--technique none] [--seconds 8] [--interval-ms 120] [--rounds 2]
import WebSocket from 'ws';

import { DEFAULT_SERVER, parseOptions, percentile, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:gallery', technique: 'none',
    seconds: 8, 'interval-ms': 120, rounds: 2 },
'usage: node bench/nondiffuse/light_drag.mjs [--server PATH] [--scene S] [--technique T] [--seconds S] [--interval-ms MS] [--rounds N]');
const { server, port } = await startServer(opts.server, ['--scene', opts.scene, '--technique', opts.technique]);

const probePasses = /^env_(render|prefilter)/;

/** One session dragging the light; resolves with the interactive frames' figures. */
function drag(arm) {
    return new Promise((resolve, reject) => {
        const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
        const frames = [];
        const plans = new Map();
        let stats = null;
        let timer = null;
        let step = 0;
        ws.on('error', reject);
        ws.on('open', () => {
            ws.send(JSON.stringify({ type: 'hello', protocol: 2, size: [960, 800], dpr: 1, max_in_flight: 2, codecs: ['jpeg'] }));
            if (arm === 'none') ws.send(JSON.stringify({ type: 'params', values: { env_budget_ms: 0 } }));
            timer = setInterval(() => {
                // A slow swing of the light's direction: every message changes the light views.
                const a = 0.3 * Math.sin(step++ * 0.15);
                ws.send(JSON.stringify({ type: 'light', light: { direction: [a, -1, 0.2 * a] } }));
            }, opts['interval-ms']);
            setTimeout(() => {
                clearInterval(timer);
                ws.close(1000);
                resolve({ frames, plans });
            }, opts.seconds * 1000);
        });
        ws.on('message', (data, isBinary) => {
            if (!isBinary) {
                const m = JSON.parse(data.toString());
                if (m.type === 'stats') stats = m;
                return;
            }
            ws.send(JSON.stringify({ type: 'ack', frame: data.readUInt32LE(4) }));
            if (stats?.quality !== 'interactive') return;
            const counts = stats.counts ?? {};
            if (counts.env_cubes_reused === 1) return; // only frames that rendered the probes
            const probeMs = (stats.passes ?? []).filter((p) => probePasses.test(p.name)).reduce((s, p) => s + p.gpu_ms, 0);
            frames.push({ frameMs: stats.frame_ms, probeMs });
            const plan = `${counts.env_probes} of ${counts.env_probes_wanted} at ${counts.env_size}`;
            plans.set(plan, (plans.get(plan) ?? 0) + 1);
        });
    });
}

const q = (v, p) => {
    const x = percentile(v, p);
    return x === null ? null : +x.toFixed(1);
};
const results = { budget: [], none: [] };
for (let r = 0; r < opts.rounds; r++)
    for (const arm of ['budget', 'none']) results[arm].push(await drag(arm));
for (const arm of ['budget', 'none']) {
    const frames = results[arm].flatMap((x) => x.frames);
    const plans = {};
    for (const x of results[arm]) for (const [k, n] of x.plans) plans[k] = (plans[k] ?? 0) + n;
    console.log(JSON.stringify({ arm, frames_with_probes: frames.length,
        frame_ms: { p50: q(frames.map((f) => f.frameMs), 0.5), p95: q(frames.map((f) => f.frameMs), 0.95) },
        probe_ms: { p50: q(frames.map((f) => f.probeMs), 0.5), p95: q(frames.map((f) => f.probeMs), 0.95) },
        plans }));
}
server.kill('SIGINT');
process.exit(0);
