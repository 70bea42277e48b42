// Load test for a running gi-server (protocol v1); a benchmark, not a test. Two modes:
//
//   sessions (default): N concurrent sessions each orbit the camera for S seconds (a `camera`
//     message every 50 ms), acknowledge every frame and record fps, input-to-frame latency,
//     dropped frames and errors.
//   --cycles N: N times in a row open a session, wait for welcome and the first frame, close with
//     1000; reports the time per cycle and the server's memory before, after and after a settle,
//     to show that sessions leave nothing behind.
//
// usage: node bench/load/load.mjs --url ws://127.0.0.1:8080/ws [--sessions 8] [--seconds 60]
//          [--size 256x256] [--adaptive] [--in-flight 1] [--token T] [--pid PID]
//          [--cycles N] [--settle 3] [--json FILE]
// Exits 1 when the server sent any error message, a connection failed or a session got no frame.
import { appendFileSync, existsSync, readFileSync } from 'node:fs';
import WebSocket from 'ws';

import { ackMsg, cameraMsg, helloMsg, parseFrameHeader, SUBPROTOCOL } from '../../client/protocol.js';

const CAMERA_INTERVAL_MS = 50;
const CONNECT_TIMEOUT_MS = 10000;
const FRAME_TIMEOUT_MS = 30000;
// Hard bounds, so that a typo cannot open a thousand sessions or run for a day.
const LIMITS = { sessions: [1, 256], seconds: [1, 3600], cycles: [1, 100000], 'in-flight': [1, 4], settle: [0, 600] };

const USAGE = `usage: node bench/load/load.mjs --url ws://HOST:PORT/ws [--sessions N] [--seconds S]
       [--size WxH] [--adaptive] [--in-flight N] [--token T] [--pid PID]
       [--cycles N] [--settle S] [--json FILE]`;

function parseArgs(argv) {
    const opts = { url: 'ws://127.0.0.1:8080/ws', sessions: 8, seconds: 60, size: '256x256', adaptive: false,
        'in-flight': 1, token: undefined, pid: undefined, cycles: 0, settle: 3, json: undefined };
    for (let i = 0; i < argv.length; ++i) {
        const key = argv[i].replace(/^--/, '');
        if (key === 'help') {
            console.log(USAGE);
            process.exit(0);
        }
        if (!(key in opts) || !argv[i].startsWith('--')) throw new Error(`unknown option ${argv[i]}\n${USAGE}`);
        if (key === 'adaptive') {
            opts.adaptive = true;
            continue;
        }
        const value = argv[++i];
        if (value === undefined) throw new Error(`--${key} needs a value`);
        opts[key] = typeof opts[key] === 'number' || key === 'pid' ? Number(value) : value;
    }
    for (const [key, [lo, hi]] of Object.entries(LIMITS)) {
        if (key === 'cycles' && opts.cycles === 0) continue;
        if (!Number.isInteger(opts[key]) || opts[key] < lo || opts[key] > hi) {
            throw new Error(`--${key} must be an integer in ${lo}..${hi}, got ${opts[key]}`);
        }
    }
    const size = /^(\d+)x(\d+)$/.exec(opts.size);
    if (!size) throw new Error(`--size must be WxH, got ${opts.size}`);
    opts.size = [Number(size[1]), Number(size[2])];
    if (opts.pid !== undefined && !existsSync(`/proc/${opts.pid}/status`)) {
        throw new Error(`--pid ${opts.pid}: no such process (or no /proc)`);
    }
    return opts;
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

function percentile(values, p) {
    if (values.length === 0) return null;
    const sorted = [...values].sort((a, b) => a - b);
    return sorted[Math.min(sorted.length - 1, Math.floor((p / 100) * sorted.length))];
}

const round1 = (v) => (v === null ? null : Math.round(v * 10) / 10);

/** The server's resident memory in MiB from /proc/PID/status, or null without --pid. */
function serverRssMiB(pid) {
    if (pid === undefined) return null;
    const match = /^VmRSS:\s+(\d+)\s+kB/m.exec(readFileSync(`/proc/${pid}/status`, 'utf8'));
    return match ? Math.round((Number(match[1]) / 1024) * 10) / 10 : null;
}

/**
 * One client connection: sends hello, then calls handlers.onWelcome(msg), onFrame(stats, header,
 * arrivalMs), onError(msg); rejects `ready` when welcome does not come.
 */
class Client {
    constructor(opts, handlers) {
        this.handlers = handlers;
        this.errors = [];
        this.pendingStats = null;
        this.closedUnexpectedly = null;
        const headers = opts.token ? { Authorization: `Bearer ${opts.token}` } : undefined;
        this.ws = new WebSocket(opts.url, SUBPROTOCOL, { headers });
        this.ready = new Promise((resolve, reject) => {
            const timer = setTimeout(() => reject(new Error(`no welcome within ${CONNECT_TIMEOUT_MS} ms`)), CONNECT_TIMEOUT_MS);
            this.ws.once('open', () => this.send(helloMsg({
                client: 'gi-load/1', token: opts.token, codecs: ['jpeg'], adaptive: opts.adaptive,
                max_in_flight: opts['in-flight'], size: opts.size, dpr: 1,
            })));
            this.ws.on('error', (e) => {
                clearTimeout(timer);
                reject(e);
            });
            this.ws.on('close', (code) => {
                clearTimeout(timer);
                if (!this.closing) this.closedUnexpectedly = code;
                reject(new Error(`closed (${code}) before welcome`));
            });
            this.ws.on('message', (data, isBinary) => this.receive(data, isBinary, () => {
                clearTimeout(timer);
                resolve();
            }));
        });
    }

    send(msg) {
        if (this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(msg));
    }

    receive(data, isBinary, onWelcome) {
        const now = performance.now();
        if (isBinary) {
            const header = parseFrameHeader(data);
            const stats = this.pendingStats?.frame === header.frame ? this.pendingStats : null;
            this.pendingStats = null;
            // Acknowledge at once: the load script does not decode, so this is "drawn".
            this.send(ackMsg(header.frame));
            this.handlers.onFrame?.(stats, header, now);
            return;
        }
        const msg = JSON.parse(data.toString('utf8'));
        if (msg.type === 'welcome') {
            this.handlers.onWelcome?.(msg);
            onWelcome();
        } else if (msg.type === 'stats') {
            this.pendingStats = msg;
        } else if (msg.type === 'error') {
            this.errors.push(`${msg.code}: ${msg.message}`);
        }
    }

    /** Closes with 1000 (the session ends on the server at once) and waits for the close. */
    close() {
        this.closing = true;
        if (this.ws.readyState === WebSocket.CLOSED) return Promise.resolve();
        return new Promise((resolve) => {
            const timer = setTimeout(() => {
                this.ws.terminate();
                resolve();
            }, 5000);
            this.ws.once('close', () => {
                clearTimeout(timer);
                resolve();
            });
            this.ws.close(1000, 'done');
        });
    }
}

// ---------------------------------------------------------------------------------------------
// Sessions mode

/**
 * Input-to-frame latency. A frame reflects the camera messages that reached the server before its
 * render began; the render began about frame_ms + readback_ms + encode_ms (from its stats) before
 * the frame arrived. For a frame that reflects at least one camera message not reflected by an
 * earlier frame, the latency is its arrival time minus the send time of the oldest such message;
 * frames that reflect no new input (refinement, a second frame in flight) give no sample.
 */
class LatencyTracker {
    constructor() {
        this.unreflected = []; // send times, oldest first
        this.samples = [];
    }

    sent(t) {
        this.unreflected.push(t);
    }

    frame(stats, arrival) {
        const work = (stats?.frame_ms ?? 0) + (stats?.readback_ms ?? 0) + (stats?.encode_ms ?? 0);
        const renderStart = arrival - work;
        let reflected = 0;
        while (reflected < this.unreflected.length && this.unreflected[reflected] <= renderStart) ++reflected;
        if (reflected === 0) return;
        this.samples.push(arrival - this.unreflected[0]);
        this.unreflected.splice(0, reflected);
    }
}

async function runSession(index, opts, deadline) {
    const result = { session: index, frames: 0, bytes: 0, dropped: 0, errors: [], qualities: {} };
    const latency = new LatencyTracker();
    let client;
    try {
        client = new Client(opts, {
            onFrame: (stats, header, arrival) => {
                result.frames += 1;
                result.bytes += stats?.bytes ?? 0;
                result.dropped = stats?.dropped_frames ?? result.dropped;
                if (stats?.quality) result.qualities[stats.quality] = (result.qualities[stats.quality] ?? 0) + 1;
                latency.frame(stats, arrival);
            },
        });
        await client.ready;
    } catch (e) {
        result.errors.push(`connection failed: ${e.message}`);
        client?.ws.terminate();
        return { ...result, fps: 0, latency_p50_ms: null, latency_p95_ms: null, latency_samples: 0, samples: [] };
    }
    const started = performance.now();
    // Each session orbits at its own phase so that no two render the same view; each message
    // is a little further along the orbit, so every one is a real change.
    let angle = (2 * Math.PI * index) / opts.sessions;
    const timer = setInterval(() => {
        angle += 0.01;
        client.send(cameraMsg({ position: [3.9 * Math.sin(angle), 1, 3.9 * Math.cos(angle)], target: [0, 1, 0] }));
        latency.sent(performance.now());
    }, CAMERA_INTERVAL_MS);
    await sleep(Math.max(0, deadline - Date.now()));
    clearInterval(timer);
    const elapsed = (performance.now() - started) / 1000;
    if (client.closedUnexpectedly !== null) result.errors.push(`connection lost (${client.closedUnexpectedly})`);
    await client.close();
    result.errors.push(...client.errors);
    if (result.frames === 0) result.errors.push('no frame');
    return {
        ...result,
        fps: round1(result.frames / elapsed),
        latency_p50_ms: round1(percentile(latency.samples, 50)),
        latency_p95_ms: round1(percentile(latency.samples, 95)),
        latency_samples: latency.samples.length,
        samples: latency.samples,
    };
}

async function sessionsMode(opts) {
    const rssBefore = serverRssMiB(opts.pid);
    const deadline = Date.now() + opts.seconds * 1000;
    const sessions = await Promise.all(Array.from({ length: opts.sessions }, (_, i) => runSession(i, opts, deadline)));
    const samples = sessions.flatMap((s) => s.samples);
    for (const s of sessions) delete s.samples;
    await sleep(500); // let the server free the sessions before measuring
    const rssAfter = serverRssMiB(opts.pid);
    const all = sessions.flatMap((s) => s.errors);
    printTable(['session', 'fps', 'p50 ms', 'p95 ms', 'frames', 'dropped', 'MB', 'errors'], sessions.map((s) => [
        s.session, s.fps, s.latency_p50_ms ?? '–', s.latency_p95_ms ?? '–', s.frames, s.dropped,
        (s.bytes / 1e6).toFixed(1), s.errors.length,
    ]));
    const totalFps = round1(sessions.reduce((sum, s) => sum + s.fps, 0));
    const p50 = round1(percentile(samples, 50));
    const p95 = round1(percentile(samples, 95));
    console.log(`total ${totalFps} fps over ${opts.sessions} sessions, ${opts.seconds} s, ${opts.size.join('x')}, `
        + `adaptive ${opts.adaptive}; latency p50 ${p50 ?? '–'} ms, p95 ${p95 ?? '–'} ms; `
        + `server RSS ${rssBefore ?? '?'} -> ${rssAfter ?? '?'} MiB`);
    for (const s of sessions) for (const e of s.errors) console.log(`session ${s.session}: ${e}`);
    return {
        mode: 'sessions', url: opts.url, sessions: opts.sessions, seconds: opts.seconds, size: opts.size,
        adaptive: opts.adaptive, max_in_flight: opts['in-flight'], total_fps: totalFps,
        latency_p50_ms: p50, latency_p95_ms: p95,
        rss_before_mib: rssBefore, rss_after_mib: rssAfter, errors: all.length, per_session: sessions,
    };
}

// ---------------------------------------------------------------------------------------------
// Cycles mode

async function oneCycle(opts) {
    let gotFrame;
    const firstFrame = new Promise((resolve) => { gotFrame = resolve; });
    const client = new Client(opts, { onFrame: () => gotFrame() });
    try {
        await client.ready;
        let timer;
        await Promise.race([firstFrame, new Promise((resolve, reject) => {
            timer = setTimeout(() => reject(new Error(`no frame within ${FRAME_TIMEOUT_MS} ms`)), FRAME_TIMEOUT_MS);
        })]).finally(() => clearTimeout(timer));
    } finally {
        await client.close();
    }
    return client.errors;
}

async function cyclesMode(opts) {
    const rssBefore = serverRssMiB(opts.pid);
    const times = [];
    const errors = [];
    const started = performance.now();
    for (let i = 0; i < opts.cycles; ++i) {
        const t0 = performance.now();
        try {
            errors.push(...await oneCycle(opts));
        } catch (e) {
            errors.push(`cycle ${i}: ${e.message}`);
        }
        times.push(performance.now() - t0);
        // A server that stopped answering would make every further cycle wait for its timeout.
        if (errors.length >= 10) {
            errors.push(`stopped after cycle ${i}: too many errors`);
            break;
        }
    }
    const total = (performance.now() - started) / 1000;
    const rssAfter = serverRssMiB(opts.pid);
    await sleep(opts.settle * 1000);
    const rssSettled = serverRssMiB(opts.pid);
    const result = {
        mode: 'cycles', url: opts.url, cycles: times.length, size: opts.size, seconds_total: round1(total),
        cycle_ms_mean: round1(times.reduce((a, b) => a + b, 0) / Math.max(1, times.length)),
        cycle_ms_p50: round1(percentile(times, 50)), cycle_ms_p95: round1(percentile(times, 95)),
        rss_before_mib: rssBefore, rss_after_mib: rssAfter, rss_settled_mib: rssSettled, settle_s: opts.settle,
        errors: errors.length, error_messages: errors.slice(0, 20),
    };
    printTable(['cycles', 'mean ms', 'p50 ms', 'p95 ms', 'RSS before', 'after', `after ${opts.settle} s`, 'errors'], [[
        result.cycles, result.cycle_ms_mean, result.cycle_ms_p50, result.cycle_ms_p95,
        rssBefore ?? '?', rssAfter ?? '?', rssSettled ?? '?', errors.length,
    ]]);
    for (const e of result.error_messages) console.log(e);
    return result;
}

// ---------------------------------------------------------------------------------------------

function printTable(columns, rows) {
    const cells = [columns, ...rows].map((r) => r.map(String));
    const widths = columns.map((_, i) => Math.max(...cells.map((r) => r[i].length)));
    for (const r of cells) console.log(r.map((c, i) => c.padStart(widths[i])).join('  '));
}

async function main() {
    let opts;
    try {
        opts = parseArgs(process.argv.slice(2));
    } catch (e) {
        console.error(e.message);
        process.exit(2);
    }
    // A server that hangs must not hang the script: give up well after the planned run time.
    const budgetS = opts.cycles ? opts.cycles * 40 + opts.settle + 30 : opts.seconds + 60;
    setTimeout(() => {
        console.error(`load.mjs: still running after ${budgetS} s, giving up`);
        process.exit(1);
    }, budgetS * 1000).unref();
    const result = opts.cycles ? await cyclesMode(opts) : await sessionsMode(opts);
    const line = JSON.stringify(result);
    console.log(line);
    if (opts.json) appendFileSync(opts.json, `${line}\n`);
    process.exit(result.errors > 0 ? 1 : 0);
}

main().catch((e) => {
    console.error(e);
    process.exit(1);
});
