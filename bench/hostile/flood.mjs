// The connection floods of the hostile-client report, at their full size, against a gi-server this
// script starts on loopback; a benchmark, not a test (tests/e2e/hostile.test.mjs asserts the rules
// at a small scale). Three phases, each bounded in count and time:
//
//   upgrades: N WebSocket upgrades to /ws without Sec-WebSocket-Protocol, all at once, each socket
//     held open after its answer (the report: 1,017 of them exhausted the file limit);
//   slow-bodies: N `POST /api/render` with Content-Length 100000 whose body trickles one byte every
//     3 s (the report: 1,050 of them, already answered 401, locked the server out);
//   idle: N TCP connections that send nothing.
//
// During each phase /healthz is polled from 127.0.0.2 (another loopback address, so the per-address
// cap of the flooding 127.0.0.1 does not apply to it); the server's descriptors and resident memory
// are read from /proc before, at the peak and after. Prints one table.
//
// usage: (ulimit -n 8192; node bench/hostile/flood.mjs [--server build/ci/bin/gi-server]
//          [--connections 1050] [--seconds 8] [--token T] [-- extra gi-server flags])
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const REPO = fileURLToPath(new URL('../../', import.meta.url));
const USAGE = 'usage: node bench/hostile/flood.mjs [--server PATH] [--connections N] [--seconds S] [--token T] [-- gi-server flags]';
const LIMITS = { connections: [1, 5000], seconds: [1, 120] };

function parseArgs(argv) {
    const opts = { server: path.join(REPO, 'build/ci/bin/gi-server'), connections: 1050, seconds: 8, token: 'flood-token', extra: [] };
    for (let i = 0; i < argv.length; ++i) {
        if (argv[i] === '--') {
            opts.extra = argv.slice(i + 1);
            break;
        }
        if (argv[i] === '--help') {
            console.log(USAGE);
            process.exit(0);
        }
        const key = argv[i].replace(/^--/, '');
        if (!(key in opts) || i + 1 >= argv.length) throw new Error(`unknown option ${argv[i]}\n${USAGE}`);
        opts[key] = key in LIMITS ? Number(argv[++i]) : argv[++i];
        if (key in LIMITS && !(opts[key] >= LIMITS[key][0] && opts[key] <= LIMITS[key][1]))
            throw new Error(`--${key} must be in [${LIMITS[key].join(', ')}]`);
    }
    return opts;
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

function freePort() {
    return new Promise((resolve) => {
        const probe = net.createServer().listen(0, '127.0.0.1', () => {
            const { port } = probe.address();
            probe.close(() => resolve(port));
        });
    });
}

function procFigures(pid) {
    const fds = fs.readdirSync(`/proc/${pid}/fd`).length;
    const rss = /VmRSS:\s+(\d+)/.exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
    return { fds, rssMiB: rss ? Number(rss[1]) / 1024 : NaN };
}

/** GET /healthz from 127.0.0.2; resolves {status, ms} or {status: 'timeout'|'error'}. */
function health(port) {
    const started = Date.now();
    return new Promise((resolve) => {
        const req = http.get({ host: '127.0.0.1', port, path: '/healthz', localAddress: '127.0.0.2', timeout: 2000 }, (res) => {
            res.resume();
            res.on('end', () => resolve({ status: res.statusCode, ms: Date.now() - started }));
        });
        req.on('timeout', () => req.destroy(new Error('timeout')));
        req.on('error', (e) => resolve({ status: e.message === 'timeout' ? 'timeout' : 'error', ms: Date.now() - started }));
    });
}

/** Opens `count` sockets from 127.0.0.1, each sending `request(i)` (and then `trickle` every 3 s). */
function flood(port, count, request, trickle) {
    const sockets = [];
    const answers = {};
    for (let i = 0; i < count; ++i) {
        const s = net.connect({ host: '127.0.0.1', port, localAddress: '127.0.0.1' });
        s.state = 'open';
        s.on('connect', () => {
            if (request) s.write(request(i));
            if (trickle) s.timer = setInterval(() => s.writable && s.write(trickle), 3000);
        });
        s.once('data', (d) => {
            const status = /^HTTP\/1\.[01] (\d+)/.exec(d.toString('latin1'));
            answers[status ? status[1] : 'other'] = (answers[status ? status[1] : 'other'] ?? 0) + 1;
        });
        s.on('close', () => {
            s.state = 'closed';
            clearInterval(s.timer);
        });
        s.on('error', () => {});
        sockets.push(s);
    }
    return { sockets, answers, open: () => sockets.filter((s) => s.state === 'open').length };
}

async function phase(name, port, pid, count, seconds, request, trickle) {
    const before = procFigures(pid);
    const f = flood(port, count, request, trickle);
    let peakFds = before.fds;
    let peakRss = before.rssMiB;
    const probes = [];
    const deadline = Date.now() + seconds * 1000;
    while (Date.now() < deadline) {
        await sleep(250);
        const now = procFigures(pid);
        peakFds = Math.max(peakFds, now.fds);
        peakRss = Math.max(peakRss, now.rssMiB);
        probes.push(await health(port));
    }
    const stillOpen = f.open();
    for (const s of f.sockets) s.destroy();
    await sleep(1500);
    const after = procFigures(pid);
    const ok = probes.filter((p) => p.status === 200).map((p) => p.ms).sort((a, b) => a - b);
    return {
        name, count, stillOpen, answers: f.answers, before, peakFds, peakRss, after,
        healthOk: `${ok.length}/${probes.length}`, healthP50: ok[Math.floor(ok.length / 2)] ?? NaN, healthMax: ok.at(-1) ?? NaN,
    };
}

async function main() {
    const opts = parseArgs(process.argv.slice(2));
    const port = await freePort();
    const args = ['--port', String(port), '--technique', 'none', '--size', '32x32', '--token', opts.token,
        '--client-dir', path.join(REPO, 'client'), ...opts.extra];
    // The server gets the common default of 1024 open files (as in the report), whatever this
    // script's own limit is (it needs more: run it under `ulimit -n 8192`).
    const server = spawn('bash', ['-c', 'ulimit -n 1024 && exec "$0" "$@"', opts.server, ...args],
        { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, GI_GL: process.env.GI_GL ?? 'egl' } });
    let log = '';
    server.stdout.on('data', (d) => (log += d));
    server.stderr.on('data', (d) => (log += d));
    try {
        for (let i = 0; i < 100 && (await health(port)).status !== 200; ++i) await sleep(200);
        const upgrade = () => 'GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n'
            + 'Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n';
        const slowBody = () => 'POST /api/render HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n'
            + 'Content-Length: 100000\r\n\r\n{';
        const rows = [
            await phase('upgrades without sub-protocol', port, server.pid, opts.connections, opts.seconds, upgrade),
            await phase('slow bodies, no token (401)', port, server.pid, opts.connections, opts.seconds, slowBody, ' '),
            await phase('idle connections', port, server.pid, opts.connections, opts.seconds),
        ];
        console.log(`gi-server ${args.join(' ')}\n`);
        console.log('| flood | connections | still open at the end | answers | server fds before / peak / after | RSS MiB before / peak / after | /healthz from 127.0.0.2: 200s, p50 ms, max ms |');
        console.log('|---|---|---|---|---|---|---|');
        for (const r of rows)
            console.log(`| ${r.name} | ${r.count} | ${r.stillOpen} | ${JSON.stringify(r.answers)} | ${r.before.fds} / ${r.peakFds} / ${r.after.fds} | `
                + `${r.before.rssMiB.toFixed(1)} / ${r.peakRss.toFixed(1)} / ${r.after.rssMiB.toFixed(1)} | ${r.healthOk}, ${r.healthP50}, ${r.healthMax} |`);
        const refusals = log.split('\n').filter((l) => l.includes('refused (')).length;
        console.log(`\n${refusals} refusal log lines for ${3 * opts.connections} connections (summarised per 0.5 s)`);
    } finally {
        server.kill('SIGINT');
        await sleep(300);
        server.kill('SIGINT');
    }
}

main().catch((e) => {
    console.error(e.message);
    process.exit(1);
});
