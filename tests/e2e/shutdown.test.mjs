// Graceful shutdown (docs/operations.md, "Graceful drain"): on SIGTERM gi-server refuses new sessions,
// tells its clients `shutdown`, answers /healthz with 503 "draining", keeps rendering running sessions
// until they end or --drain-seconds pass, then closes them with 1001 and exits 0. A second signal ends
// the drain at once. Each case starts its own server: the signal is the thing under test.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { Client, ServerProcess, sleep } from './helpers.mjs';

const SIZE = [64, 64];
const BASE_ARGS = ['--size', `${SIZE[0]}x${SIZE[1]}`, '--settle-ms', '0'];

/** Resolves {code, signal, ms} when the process exits, ms counted from now; fails after timeoutMs. */
function exitOf(server, timeoutMs) {
    const started = Date.now();
    return new Promise((resolve, reject) => {
        if (server.exited) {
            resolve({ code: server.proc.exitCode, signal: server.proc.signalCode, ms: 0 });
            return;
        }
        const timer = setTimeout(() => reject(new Error(`gi-server still running ${timeoutMs} ms after the signal:\n${server.log}`)),
            timeoutMs);
        server.proc.once('exit', (code, signal) => {
            clearTimeout(timer);
            resolve({ code, signal, ms: Date.now() - started });
        });
    });
}

async function openSession(server) {
    const client = await Client.open(server, { adaptive: false, size: SIZE });
    await client.frame('first frame');
    return client;
}

test('SIGTERM with a running session: shutdown message, 503 health, new hellos refused, the session goes on; exit 0 once it ends', async () => {
    const server = await ServerProcess.start([...BASE_ARGS, '--drain-seconds', '15']);
    let client;
    try {
        client = await openSession(server);
        const exited = exitOf(server, 15000 + 5000);
        server.proc.kill('SIGTERM');

        const notice = await client.inbox.nextOfType('shutdown', 'shutdown message after SIGTERM');
        assert.equal(notice.grace_s, 15, 'shutdown.grace_s is --drain-seconds');
        assert.equal(typeof notice.message, 'string');

        const health = await server.http('/healthz');
        assert.equal(health.status, 503, '/healthz is 503 while draining (readiness fails)');
        const body = JSON.parse(health.body.toString());
        assert.equal(body.status, 'draining');
        assert.equal(body.sessions, 1);
        assert.ok(body.drain_remaining_s > 0 && body.drain_remaining_s <= 15, `drain_remaining_s ${body.drain_remaining_s}`);

        const metrics = (await server.http('/metrics')).body.toString();
        assert.match(metrics, /^gis_draining 1$/m, 'gis_draining is 1');

        const newcomer = await Client.connect(server);
        await newcomer.expectError({ type: 'hello', protocol: 1 }, 'shutting_down', 'hello during the drain');
        assert.equal(await newcomer.closedByServer('after shutting_down'), 1001, 'refused with close 1001 (going away)');

        const render = await server.http('/api/render', {
            method: 'POST',
            body: JSON.stringify({ scene: 'builtin:cornell', technique: 'rsm_gather', size: SIZE, format: 'png' }),
        });
        assert.equal(render.status, 503, 'POST /api/render is refused while draining');
        assert.equal(JSON.parse(render.body.toString()).error, 'shutting_down');

        // The running session is still served.
        client.send({ type: 'camera', position: [0.4, 1.1, 3.6], target: [0, 1, 0] });
        const frame = await client.frame('a frame during the drain');
        assert.ok(frame.stats.frame > 1, `frame ${frame.stats.frame} rendered during the drain`);

        // The last session ends on its own: the server need not wait for the drain bound.
        await client.close();
        const { code, signal, ms } = await exited;
        assert.equal(signal, null, `exited by itself, not by ${signal}`);
        assert.equal(code, 0, `exit code 0:\n${server.log}`);
        assert.ok(ms < 10000, `exited ${ms} ms after the signal, well before the 15 s bound, once the session ended`);
        assert.match(server.log, /draining: new sessions are refused/);
    } finally {
        await client?.close();
        await server.stop();
    }
});

test('a session still open when --drain-seconds run out is closed with shutting_down (1001); exit 0 within the bound', async () => {
    const server = await ServerProcess.start([...BASE_ARGS, '--drain-seconds', '2']);
    let client;
    try {
        client = await openSession(server);
        const exited = exitOf(server, 2000 + 4000);
        const signalled = Date.now();
        server.proc.kill('SIGTERM');
        await client.inbox.nextOfType('shutdown', 'shutdown message');
        const error = await client.inbox.nextOfType('error', 'shutting_down at the end of the drain', 6000);
        assert.equal(error.code, 'shutting_down');
        assert.equal(await client.closedByServer('after the drain', 4000), 1001);
        const waited = Date.now() - signalled;
        assert.ok(waited >= 1500, `the session was served for the drain period (${waited} ms)`);
        const { code, signal } = await exited;
        assert.equal(signal, null);
        assert.equal(code, 0, `exit code 0:\n${server.log}`);
    } finally {
        await client?.close();
        await server.stop();
    }
});

test('SIGTERM with no sessions exits 0 promptly', async () => {
    const server = await ServerProcess.start([...BASE_ARGS, '--drain-seconds', '20']);
    try {
        const exited = exitOf(server, 3000);
        server.proc.kill('SIGTERM');
        const { code, signal, ms } = await exited;
        assert.equal(signal, null);
        assert.equal(code, 0, `exit code 0:\n${server.log}`);
        assert.ok(ms < 2000, `exited in ${ms} ms`);
    } finally {
        await server.stop();
    }
});

test('a second signal ends the drain at once, without waiting for a frame still rendering', async () => {
    const server = await ServerProcess.start([...BASE_ARGS, '--drain-seconds', '60']);
    let client;
    try {
        client = await openSession(server);
        server.proc.kill('SIGTERM');
        await client.inbox.nextOfType('shutdown', 'shutdown message');
        // A frame of several seconds on llvmpipe (65,536 VPLs gathered at 256x256) is rendering when
        // the second signal comes.
        client.send({ type: 'resize', size: [256, 256] });
        client.send({ type: 'params', values: { vpl_grid: 256 } });
        await sleep(400);
        const exited = exitOf(server, 4000);
        server.proc.kill('SIGINT');
        assert.equal(await client.closedByServer('after the second signal', 4000), 1001);
        const { code, signal, ms } = await exited;
        assert.equal(signal, null);
        assert.equal(code, 0, `exit code 0:\n${server.log}`);
        console.log(`exited ${ms} ms after the second signal, a frame rendering`);
        assert.ok(ms < 1500, `exited ${ms} ms after the second signal`);
    } finally {
        await client?.close();
        await server.stop();
    }
});
