// Input during refinement, server side (not a test): starts gi-server, connects one WebSocket client
// (no browser) with a 960x800 view, sets a technique and parameters, and while the view refines in
// tiles moves the camera a little at random moments; each move's answer reports how long the input
// waited for the tile in progress (`stats.input.wait_ms`) and how long from its arrival to the frame
// about to be encoded (`rendered_ms`). Reports p50, p95 and the largest of each, and with --verbose 1
// the slowest presses with the tiles and progress messages just before them. Without a browser on
// the same cores the figures are the server's own (orbit.mjs measures the whole path in the page).
//
// With --between JSON each press meets a fresh start of --params: before it, the --between values
// are set and their refinement awaited, then --params are set again and the press comes at a random
// moment up to --window-ms after their answer (what refinement makes once per configuration, such
// as the light tree's buffer for the largest maps, is then made again before every press).
// usage: node bench/interactive/refine_waits.mjs [--server build/ci/bin/gi-server] [--technique hier_isr]
//        [--params '{"tau": 0}'] [--presses 40] [--scene builtin:cornell] [--server-args "FLAGS"] [--verbose 1]
//        [--between '{"rsm_size": 256}' [--window-ms 800]]
import { connectClient, DEFAULT_SERVER, jsonOption, parseOptions, percentile, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, technique: 'hier_isr', params: '{"tau": 0}', presses: 40,
    scene: '', 'server-args': '', verbose: 0, between: '', 'window-ms': 800 },
'usage: node bench/interactive/refine_waits.mjs [--server PATH] [--technique T] [--params JSON] [--presses N] [--scene S] [--server-args "FLAGS"] [--verbose 1] [--between JSON [--window-ms MS]]');
const params = jsonOption(opts, 'params', 'refine_waits');
const between = jsonOption(opts, 'between', 'refine_waits', null);
const { server, port, log } = await startServer(opts.server, opts['server-args'].split(' ').filter(Boolean));
const link = await connectClient(port, { size: [960, 800] });
try {
    await link.until('the first frame', () => link.state && link.stats);
    if (opts.scene) {
        link.send({ type: 'scene', name: opts.scene });
        await link.until(`scene ${opts.scene}`, () => link.stats?.scene === opts.scene);
    }
    link.send({ type: 'technique', name: opts.technique });
    link.send({ type: 'params', values: params });
    await link.until('a refinement tile', () => link.frames.some((f) => f.stats.technique === opts.technique && f.stats.tile));
    const camera = structuredClone(link.state.camera);
    const presses = [];
    // Sets `values` and waits for the interactive frame that answers them.
    const setParams = async (values) => {
        const asked = performance.now();
        link.send({ type: 'params', values });
        await link.until('the answer to the parameters', () => link.frames.some((f) => f.at > asked && f.stats.input), 60000);
    };
    for (let i = 0; i < opts.presses; i++) {
        let delay = null;
        if (between) {
            await setParams(between);
            const settled = performance.now();
            await link.until('the refinement of --between', () => link.frames.some((f) => f.at > settled &&
                (f.stats.refine?.complete || f.stats.quality === 'final')), 60000).catch(() => {});
            await setParams(params);
            delay = Math.random() * opts['window-ms'];
            await sleep(delay);
        } else {
            // Somewhere inside a step: long enough for refinement to start again after the last answer.
            await sleep(400 + Math.random() * 900);
        }
        const t = performance.now();
        const context = {
            tiles: link.frames.filter((f) => f.at > t - 400 && f.stats.tile).map((f) => ({ ago_ms: Math.round(t - f.at),
                step: f.stats.refine?.step, tile: f.stats.tile.size, frame_ms: f.stats.frame_ms })),
            progress: link.progress.filter((p) => p.at > t - 1500).map((p) => ({ ago_ms: Math.round(t - p.at),
                state: p.state, step: p.step, reason: p.reason })),
        };
        camera.position[0] += i % 2 ? -0.01 : 0.01; // a move too small to change what the view needs
        link.send({ type: 'camera', ...camera });
        await link.until('the answer to a camera move', () => link.frames.some((f) => f.at > t && f.stats.input), 30000);
        const answer = link.frames.find((f) => f.at > t && f.stats.input);
        presses.push({ ...(delay !== null ? { delay_ms: Math.round(delay) } : {}), wait: answer.stats.input.wait_ms, rendered: answer.stats.input.rendered_ms,
            frame: answer.stats.frame_ms, refining: context.tiles.length > 0, context });
    }
    const pcts = (v) => ({ p50: percentile(v, 0.5), p95: percentile(v, 0.95), max: v.length ? Math.max(...v) : null });
    const report = { technique: opts.technique, params, ...(between ? { between, window_ms: opts['window-ms'] } : {}),
        presses: presses.length,
        presses_after_a_tile: presses.filter((p) => p.refining).length,
        input_wait_ms: pcts(presses.map((p) => p.wait)), arrival_to_encode_ms: pcts(presses.map((p) => p.rendered)),
        answer_frame_ms_p50: percentile(presses.map((p) => p.frame), 0.5) };
    if (opts.verbose)
        for (const p of [...presses].sort((a, b) => b.wait - a.wait).slice(0, 5)) console.error(JSON.stringify(p));
    console.log(JSON.stringify(report));
} catch (e) {
    console.error(`refine_waits: ${e.message}\n-- the server's log, last 40 lines:\n${log().split('\n').slice(-40).join('\n')}`);
    process.exitCode = 1;
}
link.ws.close();
server.kill('SIGINT');
