// Measures what one gi-server session costs, for sizing pods (docs/operations.md, "Sizing"):
// resident memory per session, CPU time per frame and frames per second while users steer
// continuously (adaptive quality renders the interactive preset), then the CPU time of one frame at
// each preset with gi-render (found next to gi-server). Starts a fresh gi-server per row, on
// 127.0.0.1 only; bounded in time; a benchmark, not a test: the numbers depend on the machine.
//
//   node deploy/sizing.mjs [--server build/dev/bin/gi-server] [--sessions 1,2,4] [--seconds 20]
//                          [--size 512x512] [--technique rsm_gather] [--final-size 128x128]
//                          [--no-presets] [--json FILE]
//
// CPU is the server process's utime + stime from /proc/PID/stat over the measured window (all its
// threads: llvmpipe's rasteriser threads, encoders, the loop); memory is VmRSS after the window minus
// the idle server's VmRSS, divided by the sessions.
import { appendFileSync, readFileSync } from 'node:fs';
import { execFileSync, spawnSync } from 'node:child_process';
import os from 'node:os';
import path from 'node:path';

const args = process.argv.slice(2);
function option(name, fallback) {
    const i = args.indexOf(name);
    return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
}
if (args.includes('--help')) {
    console.log(readFileSync(new URL(import.meta.url), 'utf8').split('\n').slice(0, 16).join('\n'));
    process.exit(0);
}
const serverPath = path.resolve(option('--server', process.env.GI_SERVER ?? 'build/dev/bin/gi-server'));
process.env.GI_SERVER = serverPath; // helpers.mjs starts $GI_SERVER, read when it is imported
const { Client, ServerProcess, sleep } = await import('../tests/e2e/helpers.mjs');
const sessionCounts = option('--sessions', '1,2,4').split(',').map(Number);
const seconds = Number(option('--seconds', '20'));
const [width, height] = option('--size', '512x512').split('x').map(Number);
const technique = option('--technique', 'rsm_gather');
const jsonFile = option('--json', '');
const finalSize = option('--final-size', '128x128'); // the final preset costs minutes per 512x512 frame on llvmpipe
if (sessionCounts.some((n) => !(n >= 1 && n <= 32)) || !(seconds >= 5 && seconds <= 600)) {
    console.error('sizing: --sessions 1..32 each, --seconds 5..600');
    process.exit(2);
}
const TICKS = Number(execFileSync('getconf', ['CLK_TCK']).toString().trim());

function procStat(pid) {
    const stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
    const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
    const status = readFileSync(`/proc/${pid}/status`, 'utf8');
    const kib = (key) => Number(status.match(new RegExp(`^${key}:\\s+(\\d+) kB`, 'm'))[1]);
    return { cpuS: (Number(fields[11]) + Number(fields[12])) / TICKS, rssMiB: kib('VmRSS') / 1024, threads: Number(fields[17]) };
}

const camera = (i, t) => {
    const a = 0.6 * Math.sin(t / 700 + i);
    return { type: 'camera', position: [3.6 * Math.sin(a), 1 + 0.2 * Math.cos(t / 900 + i), 3.6 * Math.cos(a)], target: [0, 1, 0] };
};

/** One row: `sessions` clients steering continuously (interactive frames) for `seconds` after a warm-up. */
async function measure(sessions) {
    const server = await ServerProcess.start(['--max-sessions', String(sessions), '--technique', technique,
        '--size', `${width}x${height}`, '--drain-seconds', '0']);
    const pid = server.proc.pid;
    try {
        await sleep(1000);
        const idle = procStat(pid);
        const clients = [];
        for (let i = 0; i < sessions; ++i)
            clients.push(await Client.open(server, { adaptive: true, size: [width, height], codecs: ['jpeg'] }));
        const frameMs = [];
        let frames = 0;
        let measuring = false;
        let stop = false;
        const runners = clients.map(async (client, i) => {
            const sender = setInterval(() => client.send(camera(i, Date.now())), 50);
            try {
                while (!stop) {
                    const { stats } = await client.frame('interactive frame', () => true, 60000);
                    if (measuring) {
                        ++frames;
                        frameMs.push(stats.frame_ms);
                    }
                }
            } finally {
                clearInterval(sender);
            }
        });
        await sleep(3000); // warm-up: shader compilation, first frames, allocator growth
        const start = procStat(pid);
        const t0 = Date.now();
        measuring = true;
        await sleep(seconds * 1000);
        measuring = false;
        const end = procStat(pid);
        const elapsed = (Date.now() - t0) / 1000;
        stop = true;
        await Promise.race([Promise.allSettled(runners), sleep(5000)]);
        await Promise.all(clients.map((c) => c.close()));
        const cpu = end.cpuS - start.cpuS;
        frameMs.sort((a, b) => a - b);
        return {
            sessions, seconds: elapsed, size: `${width}x${height}`, technique, frames,
            fps_per_session: frames / elapsed / sessions,
            cpu_cores_used: cpu / elapsed,
            cpu_s_per_frame: frames ? cpu / frames : null,
            median_frame_ms: frameMs.length ? frameMs[Math.floor(frameMs.length / 2)] : null,
            rss_idle_mib: idle.rssMiB, rss_mib: end.rssMiB,
            rss_per_session_mib: (end.rssMiB - idle.rssMiB) / sessions, threads: end.threads,
        };
    } finally {
        await server.stop();
    }
}

/** CPU seconds of one gi-render run (user + system, all threads), from /usr/bin/time. */
function renderCpu(preset, size, frames) {
    const render = path.join(path.dirname(serverPath), 'gi-render');
    const run = spawnSync('/usr/bin/time', ['-f', '%U %S %M', render, '--technique', technique, '--preset', preset,
        '--size', size, '--frames', String(frames), '--quiet'], { stdio: ['ignore', 'ignore', 'pipe'] });
    if (run.status !== 0) throw new Error(`gi-render --preset ${preset} failed (${run.status}): ${run.stderr}`);
    const [user, sys, maxKiB] = run.stderr.toString().trim().split('\n').at(-1).split(' ').map(Number);
    return { cpu: user + sys, maxRssMiB: maxKiB / 1024 };
}

/** CPU seconds per frame of a preset: the difference of two runs, so start-up cancels out. */
function presetCost(preset, size, [fewer, more]) {
    const a = renderCpu(preset, size, fewer);
    const b = renderCpu(preset, size, more);
    return { preset, size, cpu_s_per_frame: (b.cpu - a.cpu) / (more - fewer), max_rss_mib: b.maxRssMiB };
}

const rows = [];
const f = (x, d = 2) => (x === null || x === undefined ? '-' : x.toFixed(d));
console.log(`gi-server sizing on ${os.cpus().length} cores (${os.cpus()[0].model}), viewport ${width}x${height}, ${technique}, ${seconds} s per row`);
console.log('\nSessions steering continuously (adaptive quality: every frame is the interactive preset at --interactive-scale):\n');
console.log('| sessions | frames/s per session | cores used | CPU s per frame | median frame ms | RSS idle MiB | RSS MiB | RSS per session MiB |');
console.log('|---|---|---|---|---|---|---|---|');
for (const n of sessionCounts) {
    const r = await measure(n);
    rows.push(r);
    console.log(`| ${n} | ${f(r.fps_per_session)} | ${f(r.cpu_cores_used)} | ${f(r.cpu_s_per_frame, 3)} | ${f(r.median_frame_ms, 0)} | `
        + `${f(r.rss_idle_mib, 0)} | ${f(r.rss_mib, 0)} | ${f(r.rss_per_session_mib, 0)} |`);
}
const presets = [];
if (!args.includes('--no-presets')) {
    // The sizes adaptive quality renders for this viewport: interactive at half size, the others at full.
    const half = `${Math.round(width / 2)}x${Math.round(height / 2)}`;
    console.log(`\nOne frame per preset (gi-render, CPU seconds per frame from two --frames counts: interactive 2 vs 42, balanced 2 vs 12, final 1 vs 2 at ${finalSize}):\n`);
    console.log('| preset | size | CPU s per frame | max RSS MiB |');
    console.log('|---|---|---|---|');
    for (const [preset, size, counts] of [['interactive', half, [2, 42]], ['balanced', `${width}x${height}`, [2, 12]],
        ['final', finalSize, [1, 2]]]) {
        const r = presetCost(preset, size, counts);
        presets.push(r);
        console.log(`| ${preset} | ${size} | ${f(r.cpu_s_per_frame, 3)} | ${f(r.max_rss_mib, 0)} |`);
    }
}
const summary = JSON.stringify({ date: new Date().toISOString(), cores: os.cpus().length, rows, presets });
console.log(summary);
if (jsonFile) appendFileSync(jsonFile, `${summary}\n`);
process.exit(0);
