// End-to-end test of gi-server: starts the binary, talks protocol v0 over a real WebSocket and
// checks the HTTP side. Run: GI_SERVER=build/dev/bin/gi-server node --test tests/e2e/
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import http from 'node:http';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import WebSocket from 'ws';

import { parseFrameHeader } from '../../client/protocol.js';

const REPO = fileURLToPath(new URL('../../', import.meta.url));
const SERVER = path.resolve(REPO, process.env.GI_SERVER ?? 'build/ci/bin/gi-server');
const STARTUP_TIMEOUT_MS = 20000;
const FRAME_TIMEOUT_MS = 20000;
const REPLY_TIMEOUT_MS = 5000;

let server = null;
let serverLog = '';
let port = 0;
let ws = null;
let inbox = null;
let lastFrame = null; // {header, payload, stats}

function freePort() {
    return new Promise((resolve, reject) => {
        const probe = net.createServer();
        probe.once('error', reject);
        probe.listen(0, '127.0.0.1', () => {
            const { port: p } = probe.address();
            probe.close(() => resolve(p));
        });
    });
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** A raw HTTP GET: node's http client sends the path as given, so traversal attempts reach the server unchanged. */
function httpGet(pathname, timeoutMs = 3000) {
    return new Promise((resolve, reject) => {
        const req = http.get({ host: '127.0.0.1', port, path: pathname, timeout: timeoutMs }, (res) => {
            const chunks = [];
            res.on('data', (c) => chunks.push(c));
            res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body: Buffer.concat(chunks) }));
        });
        req.on('timeout', () => req.destroy(new Error(`GET ${pathname} timed out`)));
        req.on('error', reject);
    });
}

async function waitForHealthy() {
    const deadline = Date.now() + STARTUP_TIMEOUT_MS;
    let lastError = null;
    while (Date.now() < deadline) {
        if (server.exitCode !== null || server.signalCode !== null) {
            throw new Error(`gi-server exited (${server.exitCode ?? server.signalCode}) during startup:\n${serverLog}`);
        }
        try {
            const res = await httpGet('/healthz', 1000);
            if (res.status === 200) return;
            lastError = new Error(`/healthz answered ${res.status}`);
        } catch (e) {
            lastError = e;
        }
        await sleep(100);
    }
    throw new Error(`gi-server not healthy after ${STARTUP_TIMEOUT_MS} ms (${lastError?.message}):\n${serverLog}`);
}

function stopServer() {
    if (!server || server.exitCode !== null || server.signalCode !== null) return Promise.resolve();
    return new Promise((resolve) => {
        const killer = setTimeout(() => server.kill('SIGKILL'), 3000);
        server.once('exit', () => {
            clearTimeout(killer);
            resolve();
        });
        server.kill('SIGTERM');
    });
}

/**
 * Collects everything the socket receives, so that a test can wait for the next message of a
 * kind without losing ones that arrive early. Text messages are parsed JSON; binary ones are
 * {binary: Buffer}.
 */
class Inbox {
    constructor(socket) {
        this.queue = [];
        this.waiters = [];
        this.closed = null;
        socket.on('message', (data, isBinary) => {
            const item = isBinary ? { binary: Buffer.from(data) } : JSON.parse(data.toString('utf8'));
            this.queue.push(item);
            this.flush();
        });
        socket.on('close', (code, reason) => {
            this.closed = `socket closed (${code} ${reason})`;
            for (const w of this.waiters.splice(0)) w.reject(new Error(`${w.what}: ${this.closed}`));
        });
    }

    flush() {
        for (const w of [...this.waiters]) {
            const i = this.queue.findIndex(w.match);
            if (i < 0) continue;
            const [item] = this.queue.splice(i, 1);
            this.waiters.splice(this.waiters.indexOf(w), 1);
            clearTimeout(w.timer);
            w.resolve(item);
        }
    }

    /** The first message (queued or yet to come) for which match(msg) holds. */
    next(match, what, timeoutMs = REPLY_TIMEOUT_MS) {
        return new Promise((resolve, reject) => {
            if (this.closed) {
                reject(new Error(`${what}: ${this.closed}`));
                return;
            }
            const waiter = { match, what, resolve, reject };
            waiter.timer = setTimeout(() => {
                this.waiters.splice(this.waiters.indexOf(waiter), 1);
                const seen = this.queue.map((m) => (m.binary ? `<binary ${m.binary.length} B>` : JSON.stringify(m)));
                reject(new Error(`${what}: nothing within ${timeoutMs} ms; unclaimed: [${seen.join(', ')}]`));
            }, timeoutMs);
            this.waiters.push(waiter);
            this.flush();
        });
    }

    nextOfType(type, what, timeoutMs) {
        return this.next((m) => m.type === type, what, timeoutMs);
    }

    /** Types of the messages nobody has waited for yet. */
    unclaimed() {
        return this.queue.map((m) => (m.binary ? 'binary' : m.type));
    }
}

function send(msg) {
    ws.send(typeof msg === 'string' ? msg : JSON.stringify(msg));
}

/** Waits for a stats message and the binary frame after it; checks the frame and returns it. */
async function receiveFrame(what) {
    const stats = await inbox.nextOfType('stats', `${what}: stats`, FRAME_TIMEOUT_MS);
    const { binary } = await inbox.next((m) => m.binary !== undefined, `${what}: binary frame`, FRAME_TIMEOUT_MS);
    const header = parseFrameHeader(binary);
    assert.equal(header.frame, stats.frame, `${what}: frame id in the header equals stats.frame`);
    assert.deepEqual([header.width, header.height], stats.size, `${what}: header size equals stats.size`);
    assert.equal(header.codec, 'jpeg', `${what}: codec 1 (JPEG)`);
    const payload = binary.subarray(header.payloadOffset);
    assert.ok(payload.length > 4, `${what}: payload present`);
    assert.deepEqual([...payload.subarray(0, 3)], [0xff, 0xd8, 0xff], `${what}: payload starts with a JPEG SOI marker`);
    assert.deepEqual([...payload.subarray(-2)], [0xff, 0xd9], `${what}: payload ends with a JPEG EOI marker`);
    // PROTOCOL.md does not say whether `bytes` counts the 16-byte header; accept either.
    assert.ok([payload.length, binary.length].includes(stats.bytes),
        `${what}: stats.bytes (${stats.bytes}) is the size of the JPEG (${payload.length}) or of the message`);
    return { header, payload, stats };
}

function ack(frame) {
    send({ type: 'ack', frame: frame.header.frame });
}

async function expectError(msg, code, what) {
    send(msg);
    const error = await inbox.nextOfType('error', `${what}: error reply`);
    assert.equal(error.code, code, `${what}: error code (message: ${error.message})`);
    assert.equal(typeof error.message, 'string', `${what}: error has a message`);
    return error;
}

before(async () => {
    port = await freePort();
    server = spawn(SERVER, ['--host', '127.0.0.1', '--port', String(port), '--scene', 'builtin:cornell',
        '--client-dir', path.join(REPO, 'client')], { stdio: ['ignore', 'pipe', 'pipe'] });
    const collect = (chunk) => {
        serverLog += chunk.toString();
        if (serverLog.length > 200000) serverLog = serverLog.slice(-100000);
    };
    server.stdout.on('data', collect);
    server.stderr.on('data', collect);
    await new Promise((resolve, reject) => {
        server.once('spawn', resolve);
        server.once('error', (e) => reject(new Error(`cannot start ${SERVER} (set GI_SERVER): ${e.message}`)));
    });
    await waitForHealthy();
});

after(async () => {
    if (ws && ws.readyState <= WebSocket.OPEN) ws.close();
    await stopServer();
});

test('gi-server streams frames over the gi-stream WebSocket', async (t) => {
    let anyFailed = false;
    t.after(() => {
        if (anyFailed) console.error(`--- gi-server log ---\n${serverLog}`);
    });

    // Each stream step builds on the one before; after a failure the rest would only time out.
    let streamBroken = false;
    const step = (name, fn, { independent = false } = {}) => t.test(name, async (st) => {
        if (streamBroken && !independent) {
            st.skip('an earlier stream step failed');
            return;
        }
        try {
            await fn();
        } catch (e) {
            anyFailed = true;
            if (!independent) streamBroken = true;
            throw e;
        }
    });

    let welcome = null;
    await step('a. welcome arrives on connect', async () => {
        ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
        inbox = new Inbox(ws);
        await new Promise((resolve, reject) => {
            ws.once('open', resolve);
            ws.once('error', reject);
        });
        assert.equal(ws.protocol, 'gi-stream', 'server selected the gi-stream sub-protocol');
        welcome = await inbox.nextOfType('welcome', 'welcome');
        assert.equal(welcome.protocol, 0, 'welcome.protocol is 0');
        assert.ok(Array.isArray(welcome.techniques), 'welcome.techniques is a list');
        const names = welcome.techniques.map((x) => x.name);
        for (const name of ['rsm_gather', 'none']) assert.ok(names.includes(name), `techniques include ${name}: ${names}`);
        for (const technique of welcome.techniques) {
            assert.equal(technique.params_schema?.type, 'object', `${technique.name} has a params_schema object`);
        }
        assert.equal(welcome.frame_params_schema?.type, 'object', 'welcome has frame_params_schema');
        assert.ok(welcome.scenes?.includes('builtin:cornell'), 'scenes include builtin:cornell');
        assert.equal(welcome.state?.scene, 'builtin:cornell', 'the session starts on --scene');
    });

    await step('b. resize to 256x256 gives stats and a JPEG frame', async () => {
        send({ type: 'resize', size: [256, 256] });
        // The first frame may have been rendered at the default size before the resize arrived;
        // take frames until one is 256x256.
        let frame = await receiveFrame('first frame');
        for (let i = 0; i < 3 && frame.header.width !== 256; ++i) {
            ack(frame);
            frame = await receiveFrame('frame after resize');
        }
        assert.deepEqual([frame.header.width, frame.header.height], [256, 256], 'frame is 256x256 after resize');
        assert.equal(frame.stats.type, 'stats');
        assert.equal(frame.stats.codec, 'jpeg', 'stats.codec is jpeg');
        assert.ok(Array.isArray(frame.stats.passes) && frame.stats.passes.length > 0, 'stats lists passes');
        assert.ok(typeof frame.stats.frame_ms === 'number', 'stats.frame_ms is a number');
        ack(frame);
        lastFrame = frame;
    });

    await step('c. a camera change renders a different frame', async () => {
        send({ type: 'camera', position: [1.2, 1.4, 3.2], target: [0, 1, 0] });
        const frame = await receiveFrame('frame after camera change');
        assert.ok(frame.header.frame > lastFrame.header.frame, 'frame ids increase');
        assert.ok(!frame.payload.equals(lastFrame.payload), 'the new camera gives different image bytes');
        ack(frame);
        lastFrame = frame;
    });

    await step('d. bad messages get errors and the session survives', async () => {
        await expectError('{not json', 'invalid_json', 'malformed JSON');
        const small = await expectError({ type: 'resize', size: [8, 8] }, 'invalid_message', 'resize 8x8');
        assert.equal(small.where, '/size/0', 'resize 8x8: where points at the first bad value');
        await expectError({ type: 'teleport' }, 'unknown_type', 'unknown message type');
        await expectError({ type: 'params', values: { vpl_grid: 100000 } }, 'invalid_param', 'out-of-range parameter');
        await expectError({ type: 'hello', protocol: 1 }, 'protocol_mismatch', 'hello with another major version');
        ws.send(Buffer.from([1, 2, 3]), { binary: true });
        await inbox.next((m) => m.type === 'error' && m.code === 'binary_not_accepted', 'binary from the client');
        send({ type: 'params', values: { vpl_grid: 8 } });
        const frame = await receiveFrame('frame after params change');
        assert.equal(frame.stats.params?.vpl_grid, 8, 'stats.params.vpl_grid is 8');
        assert.equal(frame.stats.counts?.vpl_count, 64, 'stats.counts.vpl_count is 8^2');
        ack(frame);
        // The effect plan: asked for through a frame parameter, reported in the stats.
        send({ type: 'params', values: { effects: 'auto' } });
        const planned = await receiveFrame('frame after effects=auto');
        assert.equal(planned.stats.plan?.mode, 'auto', 'stats.plan.mode is auto');
        assert.ok(Array.isArray(planned.stats.plan?.decisions) && planned.stats.plan.decisions.length >= 4,
                  'stats.plan lists the decisions');
        ack(planned);
        send({ type: 'ping', t: 42.5 });
        const pong = await inbox.nextOfType('pong', 'pong');
        assert.equal(pong.t, 42.5, 'pong echoes t');
    });

    await step('e. HTTP: client files, API, 404 and no path traversal', async () => {
        const index = await httpGet('/');
        assert.equal(index.status, 200, 'GET / is 200');
        assert.match(index.headers['content-type'] ?? '', /^text\/html/, 'GET / is text/html');
        assert.match(index.body.toString(), /<script type="module" src="main\.js">/, 'GET / is client/index.html');

        const js = await httpGet('/protocol.js');
        assert.equal(js.status, 200, 'GET /protocol.js is 200');
        assert.match(js.headers['content-type'] ?? '', /javascript/, 'ES modules are served as JavaScript');

        const api = await httpGet('/api/techniques');
        assert.equal(api.status, 200, 'GET /api/techniques is 200');
        assert.match(api.headers['content-type'] ?? '', /json/, '/api/techniques is JSON');
        const body = JSON.parse(api.body.toString());
        const list = Array.isArray(body) ? body : body.techniques;
        assert.ok(Array.isArray(list), '/api/techniques lists techniques');
        const names = list.map((x) => (typeof x === 'string' ? x : x.name));
        assert.ok(names.includes('rsm_gather') && names.includes('none'), `/api/techniques names: ${names}`);

        assert.equal((await httpGet('/nonexistent')).status, 404, 'GET /nonexistent is 404');
        for (const attempt of ['/../etc/passwd', '/../../../../etc/passwd', '/%2e%2e/%2e%2e/etc/passwd',
            '/..%2f..%2f..%2fetc%2fpasswd', '/test/../../protocol/PROTOCOL.md']) {
            const res = await httpGet(attempt);
            assert.ok([400, 403, 404].includes(res.status), `GET ${attempt} is refused (got ${res.status})`);
            assert.ok(!res.body.toString().includes('root:'), `GET ${attempt} does not leak /etc/passwd`);
        }
    }, { independent: true });

    assert.deepEqual(inbox?.unclaimed().filter((type) => type === 'error') ?? [], [], 'no unexpected error messages');
});
