// What the node benchmarks that drive a gi-server share: their `--name value` options, starting the
// server on a free loopback port, a WebSocket client without a browser, and percentiles.
import { spawn } from 'node:child_process';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import WebSocket from 'ws';

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
export const DEFAULT_SERVER = path.join(ROOT, 'build/ci/bin/gi-server');

/**
 * `--name value` pairs over `defaults` (a number default makes the value a number); `--help` prints
 * `usage` and exits; an unknown name or a missing value throws.
 */
export function parseOptions(defaults, usage, argv = process.argv.slice(2)) {
    const opts = { ...defaults };
    for (let i = 0; i < argv.length; i++) {
        const key = argv[i].replace(/^--/, '');
        if (key === 'help') {
            console.log(usage);
            process.exit(0);
        }
        if (!(key in opts) || argv[i + 1] === undefined) throw new Error(`unknown option or missing value: ${argv[i]}`);
        opts[key] = typeof opts[key] === 'number' ? Number(argv[++i]) : argv[++i];
    }
    return opts;
}

/**
 * The JSON option `--name` of `script` (parameters to send, say), `fallback` when it is empty; exits with
 * status 2 and a message naming the option when it is not JSON.
 */
export function jsonOption(opts, name, script, fallback = {}) {
    if (!opts[name]) return fallback;
    try {
        return JSON.parse(opts[name]);
    } catch (e) {
        console.error(`${script}: --${name} is not JSON: ${e.message}`);
        process.exit(2);
    }
}

export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

export const freePort = () => new Promise((resolve) => {
    const s = net.createServer().listen(0, '127.0.0.1', () => {
        const { port } = s.address();
        s.close(() => resolve(port));
    });
});

/**
 * Starts `serverPath` with the repository's client on a free port and `args`; resolves once it
 * listens (10 s at most) with {server (the child process), port, log () => its stderr so far}.
 * `nice` (0..19) lowers the server's CPU priority below the benchmark's browser: on one machine the
 * browser then decodes and draws as if it had a machine of its own, as a remote viewer's has.
 */
export async function startServer(serverPath, args = [], { nice = 0 } = {}) {
    const port = await freePort();
    const serverArgs = ['--port', String(port), '--client-dir', path.join(ROOT, 'client'), ...args];
    const server = nice > 0
        ? spawn('nice', ['-n', String(nice), serverPath, ...serverArgs], { stdio: ['ignore', 'ignore', 'pipe'] })
        : spawn(serverPath, serverArgs, { stdio: ['ignore', 'ignore', 'pipe'] });
    let log = '';
    server.stderr.on('data', (d) => { log += d; });
    for (let i = 0; i < 100 && !log.includes('listening'); i++) await sleep(100);
    if (!log.includes('listening')) throw new Error(`gi-server did not start:\n${log}`);
    // A benchmark that stops on an error must not leave its server running (and loading the machine
    // the next measurement runs on).
    process.on('exit', () => server.kill('SIGKILL'));
    return { server, port, log: () => log };
}

/**
 * A WebSocket client of the server on `port` (no browser): says hello (JPEG frames, dpr 1, two in
 * flight, then the fields of `hello`) and acknowledges every frame. Resolves once open with a link:
 * {ws, state (the latest welcome or state message's), stats (the latest), frames ({at, stats} per
 * frame received), progress ({at, ...message}), onFrame (called with each frame's stats when set),
 * send(message), until(what, test, timeoutMs) (waits until test() holds, or throws naming `what`)}.
 */
export function connectClient(port, hello = {}) {
    const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
    const link = { ws, stats: null, frames: [], progress: [], state: null, waiters: [] };
    const wake = () => { for (const w of link.waiters.splice(0)) w(); };
    ws.on('message', (data, isBinary) => {
        if (isBinary) {
            ws.send(JSON.stringify({ type: 'ack', frame: data.readUInt32LE(4) }));
            if (link.stats) link.frames.push({ at: performance.now(), stats: link.stats });
            link.onFrame?.(link.stats);
        } else {
            const m = JSON.parse(data.toString());
            if (m.type === 'stats') link.stats = m;
            else if (m.type === 'progress') link.progress.push({ at: performance.now(), ...m });
            else if (m.type === 'welcome' || m.type === 'state') link.state = m.state;
            else if (m.type === 'error') console.error(`server error: ${m.message}`);
        }
        wake();
    });
    link.until = async (what, test, timeoutMs = 60000) => {
        const end = performance.now() + timeoutMs;
        while (!test()) {
            if (performance.now() > end) throw new Error(`timed out waiting for ${what}`);
            await new Promise((resolve) => { link.waiters.push(resolve); setTimeout(resolve, 100); });
        }
    };
    link.send = (m) => ws.send(JSON.stringify(m));
    return new Promise((resolve, reject) => {
        ws.on('open', () => {
            link.send({ type: 'hello', protocol: 2, codecs: ['jpeg'], dpr: 1, max_in_flight: 2, ...hello });
            resolve(link);
        });
        ws.on('error', reject);
    });
}

/**
 * The p-quantile (0..1) of `values`, interpolated between the two nearest ranks (position p (n - 1),
 * the common default of numerical libraries); null when there are none. With 10 or 20 samples a p95
 * is then not simply the slowest one (rank floor(p n), used before, made it so).
 */
export function percentile(values, p) {
    if (!values.length) return null;
    const v = [...values].sort((a, b) => a - b);
    const at = Math.min(Math.max(p, 0), 1) * (v.length - 1);
    const below = Math.floor(at);
    const above = Math.min(below + 1, v.length - 1);
    return v[below] + (v[above] - v[below]) * (at - below);
}
