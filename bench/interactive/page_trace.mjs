// The page's main-thread work while a configuration refines (not a test): starts gi-server, opens the
// real client in headless Chromium (1280 x 800), sets a technique and parameters, waits --wait-s for
// refinement to run, records Chromium's devtools.timeline trace for --seconds and sums the renderer's
// main thread: busy time (top-level tasks), the rendering updates, layout (and how many objects each
// layout found dirty), paint. Figures of one run; compare clients side by side with
// --server-args "--client-dir DIR". docs/interactive.md, "The page's figures while the view refines".
// usage: node bench/interactive/page_trace.mjs [--server PATH] [--technique rsm_gather]
//        [--params '{"vpl_grid": 256}'] [--wait-s 4] [--seconds 5] [--server-args "FLAGS"] [--out trace.json]
import { writeFileSync } from 'node:fs';

import { DEFAULT_SERVER, jsonOption, parseOptions, sleep, startServer } from '../lib.mjs';

const opts = parseOptions({ server: DEFAULT_SERVER, technique: 'rsm_gather', params: '{"vpl_grid": 256}', 'wait-s': 4,
    seconds: 5, 'server-args': '', out: '', chromium: process.env.GI_CHROMIUM ?? '/usr/bin/chromium' },
'usage: node bench/interactive/page_trace.mjs [--server PATH] [--technique T] [--params JSON] [--wait-s S] [--seconds S] [--server-args "FLAGS"] [--out FILE]');
const params = jsonOption(opts, 'params', 'page_trace');
const { server, port } = await startServer(opts.server, opts['server-args'].split(' ').filter(Boolean));
const { chromium } = await import('playwright-core');
const browser = await chromium.launch({ executablePath: opts.chromium,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--disable-background-timer-throttling',
        '--disable-renderer-backgrounding'] });
const page = await (await browser.newContext({ viewport: { width: 1280, height: 800 } })).newPage();
await page.goto(`http://127.0.0.1:${port}/`);
await page.waitForFunction(() => window.giClient?.framesDrawn > 0, null, { timeout: 60000 });
await page.evaluate(({ technique, params }) => {
    window.giClient.send({ type: 'technique', name: technique });
    window.giClient.send({ type: 'params', values: params });
}, { technique: opts.technique, params });
await sleep(opts['wait-s'] * 1000);
await browser.startTracing(page, { categories: ['devtools.timeline', 'disabled-by-default-devtools.timeline', 'toplevel', 'blink', 'cc'] });
await sleep(opts.seconds * 1000);
const trace = await browser.stopTracing();
await browser.close();
server.kill();
if (opts.out) writeFileSync(opts.out, trace);

const parsed = JSON.parse(trace.toString());
const events = Array.isArray(parsed) ? parsed : parsed.traceEvents;
const threads = events.filter((e) => e.ph === 'M' && e.name === 'thread_name' && e.args?.name === 'CrRendererMain');
// The page's renderer: the main thread with the most events.
const count = new Map(threads.map((t) => [`${t.pid}/${t.tid}`, 0]));
for (const e of events) if (count.has(`${e.pid}/${e.tid}`)) count.set(`${e.pid}/${e.tid}`, count.get(`${e.pid}/${e.tid}`) + 1);
const main = [...count].sort((a, b) => b[1] - a[1])[0]?.[0];
const slices = events.filter((e) => `${e.pid}/${e.tid}` === main && e.ph === 'X' && e.dur !== undefined);
const sumMs = (name) => slices.filter((e) => e.name === name).reduce((a, e) => a + e.dur, 0) / 1000;
const tasks = slices.filter((e) => e.name === 'ThreadControllerImpl::RunTask').map((e) => e.dur / 1000).sort((a, b) => a - b);
const layouts = slices.filter((e) => e.name === 'Layout');
const dirty = {};
for (const l of layouts) {
    const n = l.args?.beginData?.dirtyObjects ?? '?';
    dirty[n] = (dirty[n] ?? 0) + 1;
}
const round = (v) => +v.toFixed(1);
console.log(JSON.stringify({ technique: opts.technique, params, seconds: opts.seconds,
    main_busy_ms: round(tasks.reduce((a, b) => a + b, 0)), tasks: tasks.length,
    task_p95_ms: round(tasks[Math.floor(tasks.length * 0.95)] ?? 0), task_max_ms: round(tasks.at(-1) ?? 0),
    rendering_updates_ms: round(sumMs('ProxyMain::BeginMainFrame')), layout_ms: round(sumMs('Layout')),
    paint_ms: round(sumMs('Paint')), layouts: layouts.length, layouts_by_dirty_objects: dirty }));
process.exit(0);
