// Shared pieces of the end-to-end tests: start a real gi-server, talk protocol v1 to it over a
// WebSocket, make HTTP requests. Not a test file itself (node --test runs *.test.mjs only).
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import http from 'node:http';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { inflateSync } from 'node:zlib';
import WebSocket from 'ws';

import { helloMsg, parseFrameHeader, SUBPROTOCOL, validateServerMessage } from '../../client/protocol.js';

export const REPO = fileURLToPath(new URL('../../', import.meta.url));
export const SERVER = path.resolve(REPO, process.env.GI_SERVER ?? 'build/ci/bin/gi-server');
export const STARTUP_TIMEOUT_MS = 20000;
export const FRAME_TIMEOUT_MS = 15000;
export const REPLY_TIMEOUT_MS = 5000;

export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/**
 * A presets file (for GI_PRESETS) that is the committed presets/presets.json with `overrides`
 * ({technique: {preset: {param: value}}}) merged in, so a test that depends on what a preset sets
 * does not depend on what the latest measurement chose. Returns its path.
 */
export function presetsFileWith(overrides) {
    const presets = JSON.parse(readFileSync(path.join(REPO, 'presets/presets.json'), 'utf8'));
    for (const [technique, named] of Object.entries(overrides)) {
        presets.techniques[technique] ??= {};
        for (const [name, params] of Object.entries(named)) {
            presets.techniques[technique][name] = { ...(presets.techniques[technique][name] ?? {}), ...params };
        }
    }
    const file = path.join(mkdtempSync(path.join(os.tmpdir(), 'gi-presets-')), 'presets.json');
    writeFileSync(file, JSON.stringify(presets));
    return file;
}

/**
 * Tests whose connections are closed (code 1000) when each test ends, and which remember whether any
 * failed so the file can print the server log once at the end. (Not an afterEach hook: those run
 * after every subtest too.) `test` is node:test's.
 */
export function testGroup(test) {
    const clients = new Set();
    let failed = false;
    return {
        clients,
        failed: () => failed,
        check(name, fn) {
            test(name, async (t) => {
                try {
                    await fn(t);
                } catch (e) {
                    failed = true;
                    throw e;
                } finally {
                    await Promise.all([...clients].map((c) => c.close()));
                    clients.clear();
                }
            });
        },
    };
}

export function freePort() {
    return new Promise((resolve, reject) => {
        const probe = net.createServer();
        probe.once('error', reject);
        probe.listen(0, '127.0.0.1', () => {
            const { port } = probe.address();
            probe.close(() => resolve(port));
        });
    });
}

/**
 * A raw HTTP request: node's http client sends the path as given (traversal attempts reach the
 * server unchanged) and hands back the body as bytes. Resolves {status, headers, body: Buffer}.
 */
export function httpRequest(port, pathname, { method = 'GET', headers = {}, body, timeoutMs = 10000 } = {}) {
    return new Promise((resolve, reject) => {
        const req = http.request({ host: '127.0.0.1', port, path: pathname, method, headers, timeout: timeoutMs }, (res) => {
            const chunks = [];
            res.on('data', (c) => chunks.push(c));
            res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body: Buffer.concat(chunks) }));
        });
        req.on('timeout', () => req.destroy(new Error(`${method} ${pathname} timed out`)));
        req.on('error', reject);
        req.end(body);
    });
}

/**
 * A gi-server process, on a free port unless `port` is given; `log` keeps the tail of its output
 * for failure reports. restart() stops it and starts it again on the same port.
 */
export class ServerProcess {
    constructor(args, { port = 0, env = {} } = {}) {
        this.args = args;
        this.env = env;
        this.log = '';
        this.port = port;
        this.proc = null;
    }

    static async start(args, options) {
        const server = new ServerProcess(args, options);
        await server.launch();
        return server;
    }

    /** Stops the server and starts a new process with the same arguments on the same port. */
    async restart() {
        await this.stop();
        // The listening socket is closed with the process; retry briefly should the port be slow to free.
        for (let attempt = 1; ; ++attempt) {
            try {
                await this.launch();
                return;
            } catch (e) {
                if (attempt >= 5 || !this.exited) throw e;
                await sleep(300 * attempt);
            }
        }
    }

    get wsUrl() {
        return `ws://127.0.0.1:${this.port}/ws`;
    }

    get exited() {
        return this.proc.exitCode !== null || this.proc.signalCode !== null;
    }

    async launch() {
        if (!this.port) this.port = await freePort();
        this.proc = spawn(SERVER, ['--host', '127.0.0.1', '--port', String(this.port), ...this.args],
            { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, ...this.env } });
        const collect = (chunk) => {
            this.log += chunk.toString();
            if (this.log.length > 200000) this.log = this.log.slice(-100000);
        };
        this.proc.stdout.on('data', collect);
        this.proc.stderr.on('data', collect);
        await new Promise((resolve, reject) => {
            this.proc.once('spawn', resolve);
            this.proc.once('error', (e) => reject(new Error(`cannot start ${SERVER} (set GI_SERVER): ${e.message}`)));
        });
        await this.waitForHealthy();
    }

    async waitForHealthy() {
        const deadline = Date.now() + STARTUP_TIMEOUT_MS;
        let lastError = null;
        while (Date.now() < deadline) {
            if (this.exited) {
                throw new Error(`gi-server ${this.args.join(' ')} exited (${this.proc.exitCode ?? this.proc.signalCode}) `
                    + `during startup:\n${this.log}`);
            }
            try {
                const res = await httpRequest(this.port, '/healthz', { timeoutMs: 1000 });
                if (res.status === 200) return;
                lastError = new Error(`/healthz answered ${res.status}`);
            } catch (e) {
                lastError = e;
            }
            await sleep(100);
        }
        throw new Error(`gi-server not healthy after ${STARTUP_TIMEOUT_MS} ms (${lastError?.message}):\n${this.log}`);
    }

    http(pathname, options) {
        return httpRequest(this.port, pathname, options);
    }

    /** GET /healthz as JSON. */
    async health() {
        const res = await this.http('/healthz');
        assert.equal(res.status, 200, '/healthz is 200');
        return JSON.parse(res.body.toString());
    }

    /** Waits until /healthz reports `sessions` sessions: the server frees closed sessions asynchronously. */
    async waitForSessions(sessions, timeoutMs = 5000) {
        const deadline = Date.now() + timeoutMs;
        let last = null;
        while (Date.now() < deadline) {
            last = (await this.health()).sessions;
            if (last === sessions) return;
            await sleep(50);
        }
        assert.fail(`/healthz sessions is ${last}, expected ${sessions} within ${timeoutMs} ms`);
    }

    stop() {
        if (!this.proc || this.exited) return Promise.resolve();
        return new Promise((resolve) => {
            const killer = setTimeout(() => this.proc.kill('SIGKILL'), 3000);
            this.proc.once('exit', () => {
                clearTimeout(killer);
                resolve();
            });
            this.proc.kill('SIGTERM');
            // A second signal ends the drain at once: tests do not wait for sessions to finish.
            setTimeout(() => { if (!this.exited) this.proc.kill('SIGTERM'); }, 300);
        });
    }
}

/**
 * Collects everything a socket receives, so that a test can wait for the next message of a kind
 * without losing ones that arrive early. Text messages are parsed JSON; binary ones are
 * {binary: Buffer}.
 */
/**
 * Every text message any test receives is checked against protocol/schema/server/<type>.json; a
 * message that does not conform fails the waits that follow and, at the latest, the test file's exit.
 */
const schemaViolations = [];
process.on('exit', () => {
    if (schemaViolations.length === 0) return;
    console.error(`server messages that break their schema (protocol/schema/server):\n  ${schemaViolations.join('\n  ')}`);
    process.exitCode = 1;
});

export class Inbox {
    constructor(socket) {
        this.queue = [];
        this.waiters = [];
        this.closed = null;
        /** When each text message arrived (performance.now()), for tests of message order. */
        this.arrivedAt = new WeakMap();
        socket.on('message', (data, isBinary) => {
            const item = isBinary ? { binary: Buffer.from(data) } : JSON.parse(data.toString('utf8'));
            const violation = isBinary ? null : validateServerMessage(item);
            if (violation) {
                const text = `${item.type}${violation.where}: ${violation.message} in ${JSON.stringify(item).slice(0, 300)}`;
                schemaViolations.push(text);
                this.violation ??= text;
                for (const w of this.waiters.splice(0)) {
                    clearTimeout(w.timer);
                    w.reject(new Error(`${w.what}: the server sent ${text}`));
                }
            }
            if (!isBinary) this.arrivedAt.set(item, performance.now());
            this.queue.push(item);
            this.flush();
        });
        socket.on('close', (code, reason) => {
            this.closed = `socket closed (${code} ${reason})`;
            for (const w of this.waiters.splice(0)) {
                clearTimeout(w.timer);
                w.reject(new Error(`${w.what}: ${this.closed}`));
            }
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

    describe() {
        return this.queue.map((m) => (m.binary ? `<binary ${m.binary.length} B>` : JSON.stringify(m).slice(0, 200)));
    }

    /** The first message (queued or yet to come) for which match(msg) holds. */
    next(match, what, timeoutMs = REPLY_TIMEOUT_MS) {
        return new Promise((resolve, reject) => {
            if (this.violation) {
                reject(new Error(`${what}: the server sent ${this.violation}`));
                return;
            }
            const i = this.queue.findIndex(match);
            if (i >= 0) {
                resolve(this.queue.splice(i, 1)[0]);
                return;
            }
            if (this.closed) {
                reject(new Error(`${what}: ${this.closed}`));
                return;
            }
            const waiter = { match, what, resolve, reject };
            waiter.timer = setTimeout(() => {
                this.waiters.splice(this.waiters.indexOf(waiter), 1);
                reject(new Error(`${what}: nothing within ${timeoutMs} ms; unclaimed: [${this.describe().join(', ')}]`));
            }, timeoutMs);
            this.waiters.push(waiter);
        });
    }

    nextOfType(type, what, timeoutMs) {
        return this.next((m) => m.type === type, what, timeoutMs);
    }

    /** Drops everything received so far. */
    clear() {
        this.queue.length = 0;
    }

    /** Types of the messages nobody has waited for yet. */
    unclaimed() {
        return this.queue.map((m) => (m.binary ? 'binary' : m.type));
    }
}

/**
 * One protocol v1 connection. `Client.open(server, hello)` connects, sends hello (fields as for
 * helloMsg) and waits for welcome; `Client.connect` only connects. With autoAck (the default)
 * every binary frame is acknowledged as it arrives, so the server never waits for the test.
 */
export class Client {
    constructor(url, { headers, autoAck = true } = {}) {
        this.ws = new WebSocket(url, SUBPROTOCOL, headers ? { headers } : undefined);
        this.inbox = new Inbox(this.ws);
        this.autoAck = autoAck;
        this.welcome = null;
        this.closeCode = new Promise((resolve) => this.ws.on('close', (code) => resolve(code)));
        this.ws.on('message', (data, isBinary) => {
            if (isBinary && this.autoAck && data.length >= 16) this.send({ type: 'ack', frame: data.readUInt32LE(4) });
        });
        // Errors show up as a failed open or a close; without a listener ws would throw.
        this.ws.on('error', () => {});
    }

    static async connect(server, options) {
        const client = new Client(server.wsUrl ?? server, options);
        await new Promise((resolve, reject) => {
            client.ws.once('open', resolve);
            client.ws.once('close', (code) => reject(new Error(`connection closed (${code}) before open`)));
            client.ws.once('error', reject);
        });
        assert.equal(client.ws.protocol, SUBPROTOCOL, 'server selected the gi-stream sub-protocol');
        return client;
    }

    static async open(server, hello = {}, options = {}) {
        const client = await Client.connect(server, options);
        client.send(helloMsg({ client: 'gi-e2e', ...hello }));
        client.welcome = await client.inbox.nextOfType('welcome', `welcome (hello ${JSON.stringify(hello)})`);
        return client;
    }

    send(msg) {
        if (this.ws.readyState !== WebSocket.OPEN) return;
        this.ws.send(typeof msg === 'string' ? msg : JSON.stringify(msg));
    }

    /**
     * The next frame (stats, then the binary with the same id) for which match(stats) holds;
     * frames that do not match are skipped. Checks that header and stats agree.
     */
    async frame(what, match = () => true, timeoutMs = FRAME_TIMEOUT_MS) {
        const deadline = Date.now() + timeoutMs;
        for (;;) {
            const left = Math.max(1, deadline - Date.now());
            const stats = await this.inbox.nextOfType('stats', `${what}: stats`, left);
            const { binary } = await this.inbox.next((m) => m.binary !== undefined, `${what}: binary frame`, REPLY_TIMEOUT_MS);
            const header = parseFrameHeader(binary);
            assert.equal(header.frame, stats.frame, `${what}: frame id in the header equals stats.frame`);
            // A patch (asked for with hello.patches) is a region of the stats.size image.
            const expected = stats.patch ? [stats.patch.width, stats.patch.height] : stats.size;
            assert.deepEqual([header.width, header.height], expected, `${what}: header size equals stats.size or the patch's`);
            const frame = { stats, header, payload: binary.subarray(header.payloadOffset) };
            if (match(stats, frame)) return frame;
        }
    }

    /** Sends `msg` and waits for an error reply with `code`; returns the error. */
    async expectError(msg, code, what = JSON.stringify(msg).slice(0, 80)) {
        this.send(msg);
        const error = await this.inbox.nextOfType('error', `${what}: error reply`);
        assert.equal(error.code, code, `${what}: error code (message: ${error.message})`);
        assert.equal(typeof error.message, 'string', `${what}: error has a message`);
        return error;
    }

    /** ping with a unique t and wait for its pong: proves the connection is alive and answering. */
    async roundTrip(what = 'ping') {
        const t = Math.random() * 1e6;
        this.send({ type: 'ping', t });
        const pong = await this.inbox.next((m) => m.type === 'pong' && m.t === t, `${what}: pong`);
        assert.equal(pong.t, t);
    }

    /** Resolves the close code, or fails when the server does not close within timeoutMs. */
    async closedByServer(what, timeoutMs = REPLY_TIMEOUT_MS) {
        let timer;
        const timeout = new Promise((_, reject) => {
            timer = setTimeout(() => reject(new Error(`${what}: the server did not close the connection`)), timeoutMs);
        });
        try {
            return await Promise.race([this.closeCode, timeout]);
        } finally {
            clearTimeout(timer);
        }
    }

    /** A clean close (1000: the session ends at once); waits for the closing handshake. */
    async close() {
        if (this.ws.readyState === WebSocket.CLOSED) return;
        if (this.ws.readyState !== WebSocket.CLOSING) this.ws.close(1000, 'test done');
        let timer;
        await Promise.race([this.closeCode, new Promise((resolve) => {
            timer = setTimeout(() => {
                this.ws.terminate();
                resolve();
            }, 3000);
        })]);
        clearTimeout(timer);
    }

    /** Drops the TCP connection without a close frame: a lost connection, as far as the server can tell. */
    terminate() {
        this.ws.terminate();
        return this.closeCode;
    }
}

/**
 * Decodes an 8-bit non-interlaced PNG (what the server writes) to {width, height, channels, pixels
 * (the file's channels), rgba (every pixel as RGBA8)}; fails the test on anything else.
 */
export function decodePng(bytes) {
    assert.ok(isPng(bytes), 'a PNG signature');
    let width = 0, height = 0, channels = 0;
    const idat = [];
    for (let at = 8; at + 8 <= bytes.length;) {
        const length = bytes.readUInt32BE(at);
        const type = bytes.toString('latin1', at + 4, at + 8);
        const data = bytes.subarray(at + 8, at + 8 + length);
        if (type === 'IHDR') {
            width = data.readUInt32BE(0);
            height = data.readUInt32BE(4);
            assert.equal(data[8], 8, 'PNG bit depth 8');
            channels = { 0: 1, 2: 3, 4: 2, 6: 4 }[data[9]];
            assert.ok(channels, `PNG colour type ${data[9]} (grey, RGB, grey-alpha or RGBA expected)`);
            assert.equal(data[12], 0, 'PNG not interlaced');
        } else if (type === 'IDAT') {
            idat.push(data);
        }
        at += 12 + length;
    }
    const raw = inflateSync(Buffer.concat(idat));
    const stride = width * channels;
    const pixels = Buffer.alloc(stride * height);
    for (let y = 0; y < height; y++) {
        const filter = raw[y * (stride + 1)];
        const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
        for (let i = 0; i < stride; i++) {
            const a = i >= channels ? pixels[y * stride + i - channels] : 0;
            const b = y > 0 ? pixels[(y - 1) * stride + i] : 0;
            const c = y > 0 && i >= channels ? pixels[(y - 1) * stride + i - channels] : 0;
            const p = a + b - c;
            const pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
            const predictor = [0, a, b, (a + b) >> 1, pa <= pb && pa <= pc ? a : pb <= pc ? b : c][filter];
            assert.ok(predictor !== undefined, `PNG filter ${filter}`);
            pixels[y * stride + i] = (line[i] + predictor) & 0xff;
        }
    }
    const rgba = Buffer.alloc(width * height * 4, 255);
    for (let k = 0; k < width * height; k++) {
        const px = pixels.subarray(k * channels, (k + 1) * channels);
        const grey = channels < 3;
        rgba[k * 4] = px[0];
        rgba[k * 4 + 1] = grey ? px[0] : px[1];
        rgba[k * 4 + 2] = grey ? px[0] : px[2];
        if (channels === 2 || channels === 4) rgba[k * 4 + 3] = px[channels - 1];
    }
    return { width, height, channels, pixels, rgba };
}

export function isPng(bytes) {
    return bytes.length > 8 && bytes.subarray(0, 8).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]));
}

export function isJpeg(bytes) {
    return bytes.length > 4 && bytes[0] === 0xff && bytes[1] === 0xd8 && bytes.at(-2) === 0xff && bytes.at(-1) === 0xd9;
}

/**
 * A small binary glTF (.glb) for upload tests: a floor and a box, positions and normals, one
 * material, no light and no camera: the server adds its framing camera and default key light.
 */
export function makeGlb({ clearcoat = false } = {}) {
    const positions = [];
    const normals = [];
    const quad = (corners, normal) => {
        for (const i of [0, 1, 2, 0, 2, 3]) {
            positions.push(...corners[i]);
            normals.push(...normal);
        }
    };
    quad([[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]], [0, 1, 0]);
    const [x0, x1, y0, y1, z0, z1] = [-0.5, 0.5, 0, 1, -0.5, 0.5];
    quad([[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], [0, 0, 1]);
    quad([[x1, y0, z0], [x0, y0, z0], [x0, y1, z0], [x1, y1, z0]], [0, 0, -1]);
    quad([[x1, y0, z1], [x1, y0, z0], [x1, y1, z0], [x1, y1, z1]], [1, 0, 0]);
    quad([[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]], [-1, 0, 0]);
    quad([[x0, y1, z1], [x1, y1, z1], [x1, y1, z0], [x0, y1, z0]], [0, 1, 0]);
    const count = positions.length / 3;
    const bin = Buffer.alloc(positions.length * 4 * 2);
    positions.forEach((v, i) => bin.writeFloatLE(v, i * 4));
    normals.forEach((v, i) => bin.writeFloatLE(v, positions.length * 4 + i * 4));
    const gltf = {
        asset: { version: '2.0', generator: 'gi e2e' },
        scene: 0,
        scenes: [{ nodes: [0] }],
        nodes: [{ mesh: 0 }],
        meshes: [{ primitives: [{ attributes: { POSITION: 0, NORMAL: 1 }, material: 0 }] }],
        materials: [{ name: 'clay', pbrMetallicRoughness: { baseColorFactor: [0.8, 0.6, 0.4, 1], metallicFactor: 0 },
            // An optional extension the renderer does not show (stats.not_shown lists it).
            ...(clearcoat ? { extensions: { KHR_materials_clearcoat: { clearcoatFactor: 1 } } } : {}) }],
        ...(clearcoat ? { extensionsUsed: ['KHR_materials_clearcoat'] } : {}),
        buffers: [{ byteLength: bin.length }],
        bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: bin.length / 2 },
            { buffer: 0, byteOffset: bin.length / 2, byteLength: bin.length / 2 }],
        accessors: [
            { bufferView: 0, componentType: 5126, count, type: 'VEC3', min: [-2, 0, -2], max: [2, 1, 2] },
            { bufferView: 1, componentType: 5126, count, type: 'VEC3' },
        ],
    };
    let json = Buffer.from(JSON.stringify(gltf));
    json = Buffer.concat([json, Buffer.alloc((4 - (json.length % 4)) % 4, 0x20)]);
    const chunk = (type, data) => {
        const head = Buffer.alloc(8);
        head.writeUInt32LE(data.length, 0);
        head.write(type, 4, 'latin1');
        return Buffer.concat([head, data]);
    };
    const body = Buffer.concat([chunk('JSON', json), chunk('BIN\0', bin)]);
    const header = Buffer.alloc(12);
    header.write('glTF', 0, 'latin1');
    header.writeUInt32LE(2, 4);
    header.writeUInt32LE(12 + body.length, 8);
    return Buffer.concat([header, body]);
}
