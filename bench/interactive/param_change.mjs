// What a parameter change costs the live view (not a test): starts gi-server, opens one WebSocket
// session (960 x 800, no browser), shows --scene with --technique, sends --params and reports the
// frame that answers them (render time, the environment probes' plan), then the answers to --moves
// camera moves 2 s apart, then drags the scene's first light for --drag-s seconds (each interactive
// frame answered with the light moved a little, so every frame draws the light views again): the
// drag's frame times p50 / p95 (after its first second) and the size the frame budget rendered at,
// and its first frame apart, each with the light views' sides (shadow/rsm texels, and the
// parameters' when the budget drew them smaller).
// docs/interactive.md, "The costliest frame parameters".
// usage: node bench/interactive/param_change.mjs [--server PATH] [--scene builtin:gallery]
//        [--technique multires_gather] [--params '{"env_size": 512, "env_samples": 256}'] [--moves 3] [--drag-s 6]
import { connectClient, DEFAULT_SERVER, jsonOption, parseOptions, percentile, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:gallery', technique: 'multires_gather',
    params: '{"env_size": 512, "env_samples": 256}', moves: 3, 'drag-s': 6, 'server-args': '' },
'usage: node bench/interactive/param_change.mjs [--server PATH] [--scene S] [--technique T] [--params JSON] [--moves N] [--drag-s S] [--server-args "FLAGS"]');
const params = jsonOption(opts, 'params', 'param_change');
const { server, port } = await startServer(opts.server, opts['server-args'].split(' ').filter(Boolean));
const link = await connectClient(port, { size: [960, 800], adaptive: true });
const interactiveAfter = async (what, frame, timeoutMs = 120000) => {
    await link.until(what, () => link.frames.some((f) => f.stats.frame > frame && f.stats.quality === 'interactive'), timeoutMs);
    return link.frames.find((f) => f.stats.frame > frame && f.stats.quality === 'interactive').stats;
};
// The light views' sides the frame drew or kept, "shadow/rsm", with the parameters' when larger.
const maps = (s) => {
    const l = s.lighting ?? {};
    const drawn = `${l.shadow_side}/${l.rsm_side}`;
    return l.shadow_side_asked ? `${drawn} of ${l.shadow_side_asked}/${l.rsm_side_asked}` : drawn;
};
const summary = (s) => ({ frame_ms: +s.frame_ms.toFixed(1), size: s.size, input_wait_ms: s.input?.wait_ms ?? null,
    maps: maps(s), maps_kept: Boolean(s.counts?.light_views_reused),
    env: s.counts?.env_probes ? `${s.counts.env_probes} of ${s.counts.env_probes_wanted} probes at ${s.counts.env_size}` : null });
try {
    await link.until('the first frame', () => link.stats);
    link.send({ type: 'scene', name: opts.scene });
    await link.until(`scene ${opts.scene}`, () => link.stats?.scene === opts.scene);
    link.send({ type: 'technique', name: opts.technique });
    await sleep(2000);
    let last = link.stats.frame;
    link.send({ type: 'params', values: params });
    const answer = await interactiveAfter('the answer to the parameters', last);
    const report = { scene: opts.scene, technique: opts.technique, params, answer: { ...summary(answer),
        env_plan: answer.nondiffuse?.env?.split('; ').at(-1) ?? null }, moves: [] };
    const camera = structuredClone(link.state.camera);
    for (let i = 0; i < opts.moves; i++) {
        await sleep(2000);
        camera.position[0] += 0.05;
        last = link.stats.frame;
        link.send({ type: 'camera', ...camera });
        report.moves.push(summary(await interactiveAfter('the answer to a camera move', last)));
    }
    const light = link.state.lights?.[0] ?? link.state.light;
    if (opts['drag-s'] > 0 && light?.position) {
        const id = light.id ?? 'light0';
        const base = light.position;
        const times = [];
        let first = null; // the drag's first frame: the light views drawn again after kept ones
        let step = 0;
        const dragStart = performance.now();
        link.onFrame = (s) => {
            if (s.quality !== 'interactive') return;
            first ??= s;
            if (performance.now() - dragStart > 1000) times.push(s.frame_ms); // the first second settles the budget
            step += 1;
            link.send({ type: 'light', id, light: { position: [base[0] + 0.05 * Math.sin(step / 5), base[1], base[2] + 0.05 * Math.cos(step / 5)] } });
        };
        link.send({ type: 'light', id, light: { position: [base[0] + 0.01, base[1], base[2]] } });
        await sleep(opts['drag-s'] * 1000);
        link.onFrame = null;
        report.drag = { frames: times.length, frame_ms_p50: +percentile(times, 0.5).toFixed(1),
            frame_ms_p95: +percentile(times, 0.95).toFixed(1), last_size: link.stats.size, last_maps: maps(link.stats),
            first: first && summary(first) };
    }
    console.log(JSON.stringify(report));
} finally {
    server.kill();
}
process.exit(0);
