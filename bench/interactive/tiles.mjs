// Refinement tile benchmark (not a test): starts gi-server with its defaults, connects one WebSocket
// client with a 960x800 view, optionally sets a technique and parameters, leaves the view still and
// reports the render time of the refinement tiles it was sent (p50, p95, max) against --slice-ms, the
// steps' VPL counts and the most VPL parts a tile was split into; the first parts of split tiles
// (which also draw what later parts keep) and their later parts apart.
// usage: node bench/interactive/tiles.mjs [--server build/ci/bin/gi-server] [--scene builtin:NAME] [--technique T]
//        [--params '{"vpl_grid": 256}'] [--seconds 15] [--server-args "--slice-ms 20"] [--whole 1] [--nudge 8]
// --whole 1 asks for whole images instead of patches (as a client that does not draw patches); --verbose 1
// prints every tile sent (step, parts, size, ms, passes). Steps that completed are reported with their time.
// --nudge S sends the same camera again every S seconds (input, then a still view again): each
// refinement round is reported apart (its first tile's parts, the share it reached), which shows what a
// round learns from the ones before.
import WebSocket from 'ws';

import { DEFAULT_SERVER, parseOptions, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, technique: '', params: '', seconds: 15,
    'server-args': '', whole: 0, scene: '', verbose: 0, nudge: 0 },
'usage: node bench/interactive/tiles.mjs [--server PATH] [--scene S] [--technique T] [--params JSON] [--seconds S] [--server-args "FLAGS"] [--whole 1] [--verbose 1] [--nudge S]');
const { server, port } = await startServer(opts.server, opts['server-args'].split(' ').filter(Boolean));

// A built-in scene may be named without its prefix; the server knows it with it.
const sceneName = opts.scene && !opts.scene.includes(':') && !/\.(glb|gltf|zip)$/i.test(opts.scene)
    ? `builtin:${opts.scene}` : opts.scene;
const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
let stats = null;
let camera = null;
let round = 0;
const tiles = [];
const progress = [];
const stepsDone = [];
ws.on('open', () => {
    ws.send(JSON.stringify({ type: 'hello', protocol: 2, size: [960, 800], dpr: 1, max_in_flight: 2, codecs: ['webp', 'jpeg'],
        // As the web client: patches (the regions pasted since the last send) unless --whole 1.
        patches: !opts.whole }));
    if (opts.scene) ws.send(JSON.stringify({ type: 'scene', name: sceneName }));
    if (opts.technique) ws.send(JSON.stringify({ type: 'technique', name: opts.technique }));
    if (opts.params) ws.send(JSON.stringify({ type: 'params', values: JSON.parse(opts.params) }));
});
ws.on('message', (data, isBinary) => {
    if (!isBinary) {
        const m = JSON.parse(data.toString());
        if (m.type === 'stats') stats = m;
        const cam = m.state?.camera ?? m.camera;
        if (cam?.position) camera = cam; // the latest: a scene change brings its own
        else if (m.type === 'progress') progress.push(`${m.state} ${m.step}: ${m.reason}`);
        return;
    }
    ws.send(JSON.stringify({ type: 'ack', frame: data.readUInt32LE(4) }));
    // Tiles of the scene asked for only: a refused name would leave the default scene measured.
    if (sceneName && stats?.scene !== sceneName) return;
    if (stats?.refine) {
        if (stats.refine.complete) stepsDone.push({ step: stats.quality, ms: Math.round(stats.refine.elapsed_ms) });
        if (opts.verbose) console.log(JSON.stringify({ step: stats.quality, share: +stats.refine.share.toFixed(3),
            parts: `${stats.refine.vpl_parts_done}/${stats.refine.vpl_parts}`, tile: stats.tile?.size, ms: +stats.frame_ms.toFixed(1),
            passes: Object.fromEntries((stats.passes ?? []).map((x) => [x.name, +x.cpu_ms.toFixed(1)])) }));
        tiles.push({ round, share: stats.refine.share, ms: stats.frame_ms, encodeMs: stats.encode_ms ?? 0, bytes: stats.bytes ?? 0, vpls: stats.counts?.vpl_count ?? 0, step: stats.quality,
            parts: stats.refine.vpl_parts ?? 1, partsDone: stats.refine.vpl_parts_done ?? 1, index: tiles.length, tile: stats.tile?.size,
            passes: Object.fromEntries((stats.passes ?? []).map((x) => [x.name, +x.cpu_ms.toFixed(2)])) });
    }
});
if (opts.nudge > 0) {
    setInterval(() => {
        if (!camera) return;
        round += 1;
        ws.send(JSON.stringify({ type: 'camera', position: camera.position, target: camera.target, up: camera.up ?? [0, 1, 0] }));
    }, opts.nudge * 1000);
}
setTimeout(() => {
    if (sceneName && !tiles.length) {
        console.error(`no refinement tiles of ${sceneName}: is the name right? (the server's log says)`);
        process.exit(1);
    }
    const rounds = [];
    for (let r = 0; r <= round; r++) {
        const t = tiles.filter((x) => x.round === r);
        if (t.length) rounds.push({ round: r, tiles: t.length, first_tile_parts: t[0].parts, first_tile_ms: +t[0].ms.toFixed(1),
            share: +Math.max(...t.map((x) => x.share)).toFixed(3) });
    }
    if (opts.nudge > 0) console.log(JSON.stringify({ rounds }));
    const ms = tiles.map((t) => t.ms).sort((a, b) => a - b);
    const p = (q, v = ms) => (v.length ? +v[Math.min(v.length - 1, Math.floor(q * v.length))].toFixed(1) : null);
    const enc = tiles.map((t) => t.encodeMs).sort((a, b) => a - b);
    const bytes = tiles.map((t) => t.bytes).sort((a, b) => a - b);
    console.log(JSON.stringify({ technique: opts.technique || 'default', params: opts.params || null,
        tiles_sent: ms.length, tile_ms: { p50: p(0.5), p95: p(0.95), max: p(1) },
        // A split tile's first part also draws what its later parts keep: the two apart.
        first_part_ms: (() => { const v = tiles.filter((t) => t.parts > 1 && t.partsDone === 1).map((t) => t.ms).sort((a, b) => a - b);
            return { sent: v.length, p50: p(0.5, v), p95: p(0.95, v), max: p(1, v) }; })(),
        later_part_ms: (() => { const v = tiles.filter((t) => t.parts > 1 && t.partsDone > 1).map((t) => t.ms).sort((a, b) => a - b);
            return { sent: v.length, p50: p(0.5, v), p95: p(0.95, v), max: p(1, v) }; })(),
        encode_ms: { p50: p(0.5, enc), p95: p(0.95, enc), max: p(1, enc) }, bytes_p50: p(0.5, bytes),
        balanced_vpls: tiles.filter((t) => t.step === 'balanced').at(-1)?.vpls ?? null,
        final_vpls: tiles.filter((t) => t.step === 'final').at(-1)?.vpls ?? null,
        vpl_parts_max: Math.max(1, ...tiles.map((t) => t.parts)),
        slowest_tile: tiles.length ? (({ passes, ...t }) => t)(tiles.reduce((a, b) => (b.ms > a.ms ? b : a))) : null,
        last_tile: tiles.length ? { ms: tiles.at(-1).ms, parts: tiles.at(-1).parts, passes: tiles.at(-1).passes } : null,
        steps_done: stepsDone, progress }));
    ws.close(1000);
    server.kill('SIGINT');
    process.exit(0);
}, opts.seconds * 1000);
