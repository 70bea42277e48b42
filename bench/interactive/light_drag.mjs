// Light-drag benchmark (not a test): what a user dragging a light sees, with the server's levels of
// detail on and off side by side in one run. A WebSocket client (no browser: the frames are not
// decoded) opens a live-view session on a big scene, then repeatedly
//   - drags the scene's first light for --drag-s seconds: every interactive frame it receives is
//     acknowledged and answered with the light turned a little further, as the client's gizmo does,
//     so each frame draws the light views again;
//   - lets go, waits for the refinement to start (its first tile draws the light views at full
//     detail) and --press-ms later moves the camera, timing how long that input waited for the work
//     in progress (`stats.input.wait_ms`) and how long its answer took to arrive.
// Reported per server setting: the drag's frames per second, their render time p50 / p95, size and
// light-view triangles, and the press's wait and answer time p50 / max; then the ratios.
//
// --technique and --params (JSON, frame or technique parameters) are set once the scene shows, for
// example the largest light views: --params '{"shadow_map_size": 4096, "rsm_size": 1024}'.
//
//   node bench/interactive/light_drag.mjs [--server build/ci/bin/gi-server] [--scene builtin:atrium]
//       [--rounds 3] [--drag-s 4] [--press-ms 60] [--settings "--interactive-lod-px 1|--interactive-lod-px 0"]
//       [--technique T] [--params JSON]
import { connectClient, DEFAULT_SERVER, jsonOption, parseOptions, percentile, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, scene: 'builtin:atrium', rounds: 3, 'drag-s': 4, 'press-ms': 60,
    settings: '--interactive-lod-px 1|--interactive-lod-px 0', size: '960x800', technique: '', params: '' },
'usage: node bench/interactive/light_drag.mjs [--server PATH] [--scene NAME] [--rounds N] [--drag-s S] [--press-ms MS] [--size WxH] [--settings "FLAGS|FLAGS"] [--technique T] [--params JSON]');
const [width, height] = opts.size.split('x').map(Number);
const params = jsonOption(opts, 'params', 'light_drag', null);

// The light `angle` into the drag: a directional light's direction turned about the vertical, another
// light moved sideways by up to a twentieth of the scene's extent (a light on the vertical axis
// would not move if turned about it).
function turned(light, bounds, angle) {
    if (light.type === 'directional') {
        const [x, y, z] = light.direction;
        return { direction: [x * Math.cos(angle) - z * Math.sin(angle), y, x * Math.sin(angle) + z * Math.cos(angle)] };
    }
    const extent = bounds ? Math.hypot(...bounds.max.map((v, i) => v - bounds.min[i])) : 1;
    const [x, y, z] = light.position;
    return { position: [x + 0.05 * extent * Math.sin(4 * angle), y, z] };
}

async function measure(flags) {
    const { server, port } = await startServer(opts.server, flags.split(' ').filter(Boolean));
    try {
        const link = await connectClient(port, { client: 'light_drag', adaptive: true, size: [width, height] });
        await link.until('the welcome', () => link.state);
        link.send({ type: 'scene', name: opts.scene });
        await link.until(`frames of ${opts.scene}`, () => link.stats?.scene === opts.scene, 120000);
        if (opts.technique) {
            link.send({ type: 'technique', name: opts.technique });
            await link.until(`frames of ${opts.technique}`, () => link.stats?.technique === opts.technique, 60000);
        }
        if (params) {
            const asked = link.frames.length;
            link.send({ type: 'params', values: params });
            await link.until('the parameters', () => link.frames.slice(asked).some((f) => f.stats.quality === 'interactive'), 60000);
        }
        await link.until('a refined frame', () => link.stats?.refine?.complete || link.stats?.quality === 'final', 60000)
            .catch(() => {});
        const light = link.state.lights[0];
        const camera = link.state.camera;
        const drag = [], presses = [];
        let angle = 0;
        for (let round = 0; round < opts.rounds; round++) {
            // The drag: each interactive frame answered by the next step.
            const from = link.frames.length;
            const start = performance.now();
            link.onFrame = (s) => {
                if (s?.quality !== 'interactive' || performance.now() - start > opts['drag-s'] * 1000) return;
                angle += 0.01;
                link.send({ type: 'light', id: light.id, light: turned(light, link.state.bounds, angle) });
            };
            angle += 0.01;
            link.send({ type: 'light', id: light.id, light: turned(light, link.state.bounds, angle) });
            await sleep(opts['drag-s'] * 1000);
            link.onFrame = null;
            // Frames after the first second (the budget settles), interactive only.
            const frames = link.frames.slice(from).filter((f) => f.at - start > 1000 && f.stats.quality === 'interactive');
            if (frames.length > 1) {
                drag.push({ fps: (frames.length - 1) / ((frames.at(-1).at - frames[0].at) / 1000),
                    ms: frames.map((f) => f.stats.frame_ms), sizes: frames.map((f) => f.stats.size[0]),
                    lightTriangles: frames.map((f) => f.stats.counts?.triangles_light_views ?? 0),
                    lightSimplified: frames.map((f) => f.stats.counts?.triangles_light_views_simplified ?? 0) });
            }
            // Let go; the refinement's first tile draws the light views at full detail.
            const released = performance.now();
            await link.until('the refinement to start', () => link.progress.some((p) => p.at > released && p.state === 'refining'), 20000);
            await sleep(opts['press-ms']);
            const pressed = performance.now();
            const nudge = 0.02 * (round % 2 ? 1 : -1);
            link.send({ type: 'camera', position: camera.position.map((v, i) => v + (i === 0 ? nudge : 0)), target: camera.target });
            const before = link.frames.length;
            await link.until('the answer to the press', () => link.frames.slice(before).some((f) => f.stats.quality === 'interactive'), 30000);
            const answer = link.frames.slice(before).find((f) => f.stats.quality === 'interactive');
            presses.push({ waitMs: answer.stats.input?.wait_ms ?? null, answerMs: answer.at - pressed, frameMs: answer.stats.frame_ms });
            if (process.env.LIGHT_DRAG_VERBOSE) {
                // The refinement frames before the answer: what the input may have waited for.
                const tiles = link.frames.slice(0, before).filter((f) => f.at > released && f.stats.quality !== 'interactive');
                console.error(JSON.stringify(presses.at(-1)), 'after', tiles.length, 'refinement frames; the last:',
                    tiles.slice(-1).map((f) => `${f.stats.frame_ms.toFixed(1)} ms: ` + (f.stats.passes ?? [])
                        .filter((p) => p.gpu_ms > 3).map((p) => `${p.name} ${p.gpu_ms.toFixed(1)}`).join(', ')).join(''));
            }
            await sleep(500);
        }
        link.ws.close();
        const all = (k) => drag.flatMap((d) => d[k]);
        const r = (v) => (v === null || v === undefined ? null : +v.toFixed(1));
        return {
            settings: flags, scene: opts.scene, technique: link.stats?.technique, params, rounds: opts.rounds,
            drag_fps: r(percentile(drag.map((d) => d.fps), 0.5)),
            drag_frame_ms: { p50: r(percentile(all('ms'), 0.5)), p95: r(percentile(all('ms'), 0.95)) },
            drag_width_p50: percentile(all('sizes'), 0.5),
            drag_light_view_triangles_p50: percentile(all('lightTriangles'), 0.5),
            drag_light_view_simplified_p50: percentile(all('lightSimplified'), 0.5),
            press_wait_ms: { p50: r(percentile(presses.map((p) => p.waitMs), 0.5)), max: r(Math.max(...presses.map((p) => p.waitMs))) },
            press_answer_ms: { p50: r(percentile(presses.map((p) => p.answerMs), 0.5)), max: r(Math.max(...presses.map((p) => p.answerMs))) },
            press_frame_ms_p50: r(percentile(presses.map((p) => p.frameMs), 0.5)),
        };
    } finally {
        server.kill('SIGINT');
        await sleep(500);
    }
}

const settings = opts.settings.split('|');
const results = [];
for (const flags of settings) {
    const result = await measure(flags);
    results.push(result);
    console.log(JSON.stringify(result));
}
if (results.length > 1) {
    const [a, b] = results;
    console.log(JSON.stringify({ ratios: `${a.settings} against ${b.settings}`,
        drag_fps: +(a.drag_fps / b.drag_fps).toFixed(2),
        drag_frame_ms_p50: +(a.drag_frame_ms.p50 / b.drag_frame_ms.p50).toFixed(2),
        drag_width: +(a.drag_width_p50 / b.drag_width_p50).toFixed(2),
        press_wait_p50: +(a.press_wait_ms.p50 / Math.max(b.press_wait_ms.p50, 0.1)).toFixed(2) }));
}
process.exit(0);
