// Integration tests of gi-server as a service (protocol v1, PROTOCOL.md): the opening handshake,
// authentication, every client message's effect, error handling, resume, viewers, limits,
// adaptive quality and the HTTP API. Three servers, each started with the flags its tests need:
//   main:   64x64 frames, --max-size 96x96, --settle-ms 150, --interactive-scale 0.5
//   auth:   --token s3cret
//   limits: --max-sessions 2, --rate-limit 20
// Run: GI_SERVER=build/dev/bin/gi-server node --test tests/e2e/service.test.mjs
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { slowToLoadGlb, texturedQuadsGlb } from './glb.mjs';
import { Client, isPng, REPO, SERVER, ServerProcess, sleep, testGroup } from './helpers.mjs';

const TOKEN = 's3cret';
const SIZE = [64, 64];
const MAX_SIZE = [96, 96];
const COMMON = ['--scene', 'builtin:cornell', '--technique', 'none', '--size', `${SIZE[0]}x${SIZE[1]}`,
    '--client-dir', path.join(REPO, 'client')];

const servers = {};
const group = testGroup(test); // closes each test's clients; remembers failures for the log
const { clients, check } = group;
let uploadDir = null;

before(async () => {
    uploadDir = mkdtempSync(path.join(os.tmpdir(), 'gi-e2e-upload-'));
    const [main, auth, limits] = await Promise.all([
        ServerProcess.start([...COMMON, '--max-size', `${MAX_SIZE[0]}x${MAX_SIZE[1]}`, '--settle-ms', '150',
            '--interactive-scale', '0.5', '--resume-grace', '30', '--upload-dir', uploadDir]),
        ServerProcess.start([...COMMON, '--token', TOKEN]),
        ServerProcess.start([...COMMON, '--max-sessions', '2', '--rate-limit', '20']),
    ]);
    Object.assign(servers, { main, auth, limits });
});

after(async () => {
    if (group.failed()) {
        for (const [name, server] of Object.entries(servers)) console.error(`--- gi-server (${name}) log ---\n${server.log.slice(-4000)}`);
    }
    await Promise.all(Object.values(servers).map((s) => s.stop()));
    if (uploadDir) rmSync(uploadDir, { recursive: true, force: true });
});


/**
 * A connection past welcome. Controllers default to SIZE and adaptive false (each frame exactly
 * the requested state); a viewer's hello carries only what the test gives.
 */
async function open(server, hello = {}, options) {
    const defaults = hello.view === undefined ? { size: SIZE, adaptive: false } : {};
    const client = await Client.open(server, { ...defaults, ...hello }, options);
    clients.add(client);
    return client;
}

/** POST /api/upload of `body` as `name` into `client`'s session; the HTTP answer. */
function upload(client, name, body, type = 'model/gltf-binary') {
    return servers.main.http(`/api/upload?name=${name}`, {
        method: 'POST', body, headers: { 'Content-Type': type, 'X-GI-Session': client.welcome.resume_token },
    });
}

async function connect(server, options) {
    const client = await Client.connect(server, options);
    clients.add(client);
    return client;
}

/**
 * Waits until the session is quiet (no frame for quietMs) and returns the last frame seen, or
 * `last` when none came. Frames from earlier changes must not be taken for the next change's.
 */
async function settle(client, last = null, quietMs = 400) {
    for (;;) {
        try {
            last = await client.frame('settling', () => true, quietMs);
        } catch (e) {
            if (/nothing within/.test(e.message)) return last;
            throw e;
        }
    }
}

/** A first frame, then quiet: the state every effect test starts from. */
// Whether the server logged `text` within `timeoutMs`: a line written before a frame was sent can
// reach this process after the frame, its stderr and the socket being read apart.
async function logged(server, text, timeoutMs = 5000) {
    for (const until = Date.now() + timeoutMs; !server.log.includes(text) && Date.now() < until;) await sleep(50);
    return server.log.includes(text);
}

async function quietFrame(client) {
    return settle(client, await client.frame('a frame'));
}

function isWebp(bytes) {
    return bytes.length > 12 && bytes.subarray(0, 4).toString('latin1') === 'RIFF' && bytes.subarray(8, 12).toString('latin1') === 'WEBP';
}

function assertClose(actual, expected, what) {
    assert.equal(actual?.length, expected.length, `${what}: ${JSON.stringify(actual)}`);
    actual.forEach((v, i) => assert.ok(Math.abs(v - expected[i]) < 1e-5, `${what}[${i}]: ${v} vs ${expected[i]}`));
}

// ---------------------------------------------------------------------------------------------
// Opening handshake and authentication

check('hello with another protocol version is refused with protocol_mismatch, then closed', async () => {
    for (const protocol of [0, 3]) {
        const client = await connect(servers.main);
        const error = await client.expectError({ type: 'hello', protocol }, 'protocol_mismatch', `hello protocol ${protocol}`);
        assert.ok(error.message.length > 0);
        await client.closedByServer(`after protocol_mismatch (${protocol})`);
    }
});

check('a first message other than hello is answered with hello_required, then closed', async () => {
    const client = await connect(servers.main);
    await client.expectError({ type: 'camera', position: [0, 1, 3], target: [0, 1, 0] }, 'hello_required');
    await client.closedByServer('after hello_required');
    const pinger = await connect(servers.main);
    await pinger.expectError({ type: 'ping' }, 'hello_required', 'ping before hello');
    await pinger.closedByServer('after hello_required (ping)');
});

check('with --token, hello without the token or with a wrong one is unauthorized; the right one works', async () => {
    for (const token of [undefined, 'wrong']) {
        const client = await connect(servers.auth);
        const hello = { type: 'hello', protocol: 1, ...(token ? { token } : {}) };
        await client.expectError(hello, 'unauthorized', `hello with token ${token}`);
        await client.closedByServer(`after unauthorized (${token})`);
    }
    const good = await open(servers.auth, { token: TOKEN });
    assert.equal(good.welcome.role, 'controller');
    await good.frame('a frame with the right token');
    // The token may come as the handshake's Authorization header instead.
    const viaHeader = await open(servers.auth, {}, { headers: { Authorization: `Bearer ${TOKEN}` } });
    assert.equal(viaHeader.welcome.type, 'welcome');
    const wrongHeader = await connect(servers.auth, { headers: { Authorization: 'Bearer nope' } });
    await wrongHeader.expectError({ type: 'hello', protocol: 1 }, 'unauthorized', 'wrong bearer header');
});

check('with --token, the HTTP API needs the bearer token; /healthz stays open', async () => {
    const server = servers.auth;
    assert.equal((await server.http('/api/techniques')).status, 401, '/api/techniques without a token');
    assert.equal((await server.http('/api/techniques', { headers: { Authorization: 'Bearer nope' } })).status, 401,
        '/api/techniques with a wrong token');
    assert.equal((await server.http('/metrics')).status, 401, '/metrics without a token');
    const body = JSON.stringify({ scene: 'builtin:cornell', technique: 'none', size: [16, 16] });
    assert.equal((await server.http('/api/render', { method: 'POST', body, headers: { 'Content-Type': 'application/json' } })).status,
        401, 'POST /api/render without a token');
    const ok = await server.http('/api/techniques', { headers: { Authorization: `Bearer ${TOKEN}` } });
    assert.equal(ok.status, 200, '/api/techniques with the token');
    assert.ok(Array.isArray(JSON.parse(ok.body.toString()).techniques));
    const health = await server.http('/healthz');
    assert.equal(health.status, 200, '/healthz without a token');
    assert.equal(JSON.parse(health.body.toString()).status, 'ok');
});

// ---------------------------------------------------------------------------------------------
// Every client message

check('every client message type has its effect', async (t) => {
    // WebP first: the server supports it, so frames come as WebP (codec 3).
    const client = await open(servers.main, { codecs: ['webp', 'jpeg'], max_in_flight: 1 });
    assert.equal(client.welcome.codec, 'webp', 'welcome.codec is the first supported of hello.codecs');
    assert.equal(client.welcome.adaptive, false);
    let last = await quietFrame(client);
    assert.equal(last.header.codec, 'webp', 'frames are WebP');
    assert.ok(isWebp(last.payload), 'the payload is a RIFF/WEBP file');
    assert.deepEqual(last.stats.size, SIZE, 'the hello size');
    assert.equal(last.stats.quality, 'fixed', 'adaptive false renders fixed frames');

    /** Sends msg and returns the first frame after `last` for which match holds. */
    const frameAfter = async (msg, what, match = () => true) => {
        last = await settle(client, last);
        const before = last.stats.frame;
        client.send(msg);
        last = await client.frame(what, (stats) => stats.frame > before && match(stats));
        return last;
    };

    await t.test('camera renders a new frame', async () => {
        const previous = last;
        await frameAfter({ type: 'camera', position: [1.2, 1.4, 3.2], target: [0, 1, 0], fov_deg: 45 }, 'after camera');
        assert.ok(!last.payload.equals(previous.payload), 'a different image');
    });

    await t.test('light renders a new frame', async () => {
        const previous = await settle(client, last);
        await frameAfter({ type: 'light', intensity: 2, color: [1, 0.5, 0.5] }, 'after light');
        assert.ok(!last.payload.equals(previous.payload), 'a different image');
    });

    await t.test('technique switches technique', async () => {
        await frameAfter({ type: 'technique', name: 'rsm_gather' }, 'after technique', (s) => s.technique === 'rsm_gather');
        assert.equal(typeof last.stats.params?.vpl_grid, 'number', 'rsm_gather parameters in the stats');
        await client.expectError({ type: 'technique', name: 'no_such_technique' }, 'unknown_technique');
    });

    await t.test('params sets parameters', async () => {
        await frameAfter({ type: 'params', values: { vpl_grid: 4 } }, 'after params', (s) => s.params?.vpl_grid === 4);
        assert.equal(last.stats.counts?.vpl_count, 16, 'vpl_count is 4^2');
    });

    await t.test('resize renders size x dpr, capped to --max-size with the aspect kept', async () => {
        await frameAfter({ type: 'resize', size: [40, 30], dpr: 1.5 }, 'after resize 40x30@1.5',
            (s) => s.size[0] !== SIZE[0]);
        assert.deepEqual(last.stats.size, [60, 45], '40x30 CSS pixels at dpr 1.5');
        await frameAfter({ type: 'resize', size: [64, 32], dpr: 2 }, 'after resize 64x32@2', (s) => s.size[0] !== 60);
        assert.deepEqual(last.stats.size, [96, 48], '128x64 scaled down to fit 96x96');
        await frameAfter({ type: 'resize', size: SIZE }, 'after resize 64x64', (s) => s.size[1] !== 48);
        assert.deepEqual(last.stats.size, SIZE, 'dpr defaults to 1');
    });

    await t.test('scene loads the scene and sends a state message', async () => {
        client.send({ type: 'scene', name: 'builtin:cornell-empty' });
        // The load says it starts and what it cost, before the state.
        const loading = await client.inbox.next((m) => m.type === 'progress' && m.state === 'loading', 'progress loading', 15000);
        assert.equal(loading.step, 'scene');
        assert.match(loading.reason, /^loading builtin:cornell-empty/);
        const loaded = await client.inbox.next((m) => m.type === 'progress' && m.state === 'loaded', 'progress loaded', 15000);
        assert.match(loaded.reason, /^loaded builtin:cornell-empty.*: \d+ triangles in \d+ ms$/);
        const state = await client.inbox.nextOfType('state', 'state after scene', 15000);
        assert.equal(state.state?.scene, 'builtin:cornell-empty', 'state.scene');
        assert.ok(state.state.load?.triangles > 0 && state.state.load.ms >= 0, 'state.load: what the load cost');
        assert.ok(state.state.load.upload_ms >= 0, 'state.load.upload_ms: what the GL upload held the render thread');
        assert.ok(Array.isArray(state.state?.camera?.position), 'state carries the reset camera');
        last = await client.frame('frame of the new scene', (s) => s.scene === 'builtin:cornell-empty');
        await client.expectError({ type: 'scene', name: 'builtin:no-such-scene' }, 'unknown_scene');
        client.send({ type: 'scene', name: 'builtin:cornell' });
        await client.inbox.next((m) => m.type === 'state' && m.state?.scene === 'builtin:cornell', 'state after scene back', 15000);
    });

    await t.test('light_add and light_remove change the light list; light edits one light by id', async () => {
        client.send({ type: 'light_add', light: { type: 'point', position: [0.3, 1.2, 0.4], intensity: 1.5, color: [0.4, 0.6, 1] } });
        const added = await client.inbox.next((m) => m.type === 'state' && m.state?.lights?.length === 2, 'state after light_add', 15000);
        const point = added.state.lights[1];
        assert.equal(point.type, 'point');
        assert.equal(added.state.light.id, added.state.lights[0].id, 'protocol 1 light is the first light');
        last = await client.frame('a frame with two lights', (s) => s.lighting?.rendered?.length === 2);
        assert.equal(last.stats.lighting.rendered[1].views, 6, 'a point light has six cube-face views');
        await frameAfter({ type: 'light', id: point.id, light: { enabled: false } }, 'the point light off',
            (s) => s.lighting?.rendered?.length === 1 && s.lighting.skipped.length === 1);
        assert.match(last.stats.lighting.skipped[0], /disabled/);
        await client.expectError({ type: 'light', id: 'light-none', light: { intensity: 1 } }, 'unknown_light');
        await client.expectError({ type: 'light_remove', id: 'light-none' }, 'unknown_light');
        client.send({ type: 'light_remove', id: point.id });
        await client.inbox.next((m) => m.type === 'state' && m.state?.lights?.length === 1, 'state after light_remove', 15000);
    });

    await t.test('quality turns adaptive quality on and off', async () => {
        client.send({ type: 'quality', adaptive: true });
        await frameAfter({ type: 'camera', position: [0.5, 1, 3.5], target: [0, 1, 0] }, 'adaptive frame',
            (s) => s.quality === 'interactive');
        client.send({ type: 'quality', adaptive: false });
        await frameAfter({ type: 'camera', position: [0.4, 1, 3.6], target: [0, 1, 0] }, 'fixed frame',
            (s) => s.quality === 'fixed');
        assert.deepEqual(last.stats.size, SIZE, 'fixed frames are full size');
    });

    await t.test('snapshot sends one lossless full-size frame marked snapshot', async () => {
        const full = (await settle(client, last)).stats.size;
        await frameAfter({ type: 'snapshot' }, 'png snapshot', (s) => s.snapshot === true);
        assert.equal(last.header.codec, 'png', 'codec 2 (PNG) by default');
        assert.ok(isPng(last.payload), 'the payload is a PNG');
        assert.deepEqual(last.stats.size, full, 'full size');
        await frameAfter({ type: 'snapshot', codec: 'webp' }, 'webp snapshot', (s) => s.snapshot === true);
        assert.equal(last.header.codec, 'webp', 'codec 3 (WebP) when asked for');
        assert.ok(isWebp(last.payload), 'the payload is a WebP');
    });

    await t.test('ack frees the window: nothing is rendered while it is full', async () => {
        last = await settle(client, last);
        client.autoAck = false;
        try {
            client.send({ type: 'camera', position: [1, 1, 3.5], target: [0, 1, 0] });
            const first = await client.frame('frame filling the window', (s) => s.frame > last.stats.frame);
            client.send({ type: 'camera', position: [1.1, 1, 3.5], target: [0, 1, 0] });
            await assert.rejects(client.inbox.nextOfType('stats', 'frame beyond max_in_flight 1', 800),
                /nothing within/, 'no frame while the only slot is taken');
            client.send({ type: 'ack', frame: first.stats.frame });
            last = await client.frame('frame after the ack', (s) => s.frame > first.stats.frame);
            client.send({ type: 'ack', frame: last.stats.frame });
        } finally {
            client.autoAck = true;
        }
    });

    await t.test('ping is answered by pong with the same t', async () => {
        client.send({ type: 'ping', t: 7.25 });
        assert.equal((await client.inbox.nextOfType('pong', 'pong')).t, 7.25);
        client.send({ type: 'ping' });
        assert.equal((await client.inbox.nextOfType('pong', 'pong without t')).type, 'pong');
    });

    assert.deepEqual(client.inbox.unclaimed().filter((type) => type === 'error'), [], 'no unexpected errors');
});

check('frames echo the seq of the last steering message their state includes', async () => {
    const client = await open(servers.main);
    let last = await quietFrame(client);
    assert.equal(last.stats.input_seq, undefined, 'none before the controller sends one');
    const after = async (msg, what) => {
        const before = last.stats.frame;
        client.send(msg);
        last = await client.frame(what, (s) => s.frame > before);
        return last.stats.input_seq;
    };
    assert.equal(await after({ type: 'camera', position: [0.2, 1, 3.6], target: [0, 1, 0], seq: 5 }, 'camera seq 5'), 5);
    assert.equal(await after({ type: 'params', values: { exposure: 0.5 }, seq: 6 }, 'params seq 6'), 6);
    // A refused message counts: the frames after it are as it asked, unchanged.
    await client.expectError({ type: 'technique', name: 'no_such_technique', seq: 7 }, 'unknown_technique');
    assert.equal(await after({ type: 'camera', position: [0.3, 1, 3.6], target: [0, 1, 0] }, 'camera without seq'), 7,
        'a message without seq leaves the number');
    await client.expectError({ type: 'camera', position: [0, 1, 3], target: [0, 1, 0], seq: 0 }, 'invalid_message',
        'seq 0');
});

check('bad messages get an error and the connection stays open', async () => {
    const client = await open(servers.main);
    const maxBytes = client.welcome.limits?.max_message_bytes;
    assert.ok(Number.isInteger(maxBytes) && maxBytes > 0, `welcome.limits.max_message_bytes: ${maxBytes}`);
    await client.expectError('{"type": "ping"', 'invalid_json', 'invalid JSON');
    const wrongType = await client.expectError({ type: 'resize', size: [640, '480'] }, 'invalid_message', 'resize with a string');
    assert.equal(wrongType.where, '/size/1');
    assert.equal(wrongType.request, 'resize', 'error.request names the message type');
    const short = await client.expectError({ type: 'camera', position: [0, 1], target: [0, 1, 0] }, 'invalid_message', 'short position');
    assert.equal(short.where, '/position');
    await client.expectError({ type: 'camera', position: 'here', target: [0, 1, 0] }, 'invalid_message', 'position a string');
    const unknown = await client.expectError({ type: 'teleport' }, 'unknown_type', 'unknown type');
    assert.equal(unknown.where, '/type');
    await client.expectError(JSON.stringify({ type: 'ping', t: 1, pad: 'x'.repeat(maxBytes) }), 'message_too_large',
        `a message over ${maxBytes} bytes`);
    client.ws.send(Buffer.from([0x47, 0x49, 0x46, 0x52]), { binary: true });
    await client.inbox.next((m) => m.type === 'error' && m.code === 'binary_not_accepted', 'binary message');
    await client.roundTrip('ping after the bad messages');
    const before = (await quietFrame(client)).stats.frame;
    client.send({ type: 'camera', position: [0.3, 1.1, 3.4], target: [0, 1, 0] });
    await client.frame('a frame after the bad messages', (s) => s.frame > before);
});

// ---------------------------------------------------------------------------------------------
// Sessions: resume, viewers, limits

check('a lost connection resumes with the resume token, state intact; after a close with 1000 it cannot', async () => {
    const first = await open(servers.main);
    const token = first.welcome.resume_token;
    assert.equal(typeof token, 'string');
    const camera = { position: [1.25, 1.5, 3.0], target: [0, 0.9, 0] };
    const before = (await quietFrame(first)).stats.frame;
    first.send({ type: 'camera', ...camera, seq: 9 });
    const moved = await first.frame('frame with the new camera', (s) => s.frame > before);
    assert.equal(moved.stats.input_seq, 9, 'the frame echoes the camera message\'s seq');
    await first.terminate();
    await sleep(300); // let the server see the dropped connection

    const second = await open(servers.main, { resume: token });
    assert.equal(second.welcome.resumed, true, 'welcome.resumed');
    assert.equal(second.welcome.role, 'controller', 'the resumed client steers');
    assert.equal(second.welcome.session, first.welcome.session, 'the same session');
    assertClose(second.welcome.state?.camera?.position, camera.position, 'resumed camera position');
    assertClose(second.welcome.state?.camera?.target, camera.target, 'resumed camera target');
    const frame = await second.frame('a frame after resuming');
    assert.deepEqual(frame.stats.size, SIZE);
    assert.equal(frame.stats.input_seq, undefined, 'a new connection numbers its messages afresh');

    await second.close(); // status 1000: the session ends now
    const latest = second.welcome.resume_token ?? token;
    const third = await connect(servers.main);
    await third.expectError({ type: 'hello', protocol: 1, resume: latest }, 'resume_failed', 'resume after a clean close');
    await third.closedByServer('after resume_failed');
});

check('a viewer receives the frames but cannot steer; it is told when the session ends', async (t) => {
    const controller = await open(servers.main);
    assert.equal(typeof controller.welcome.view_token, 'string');
    await quietFrame(controller);
    const viewer = await open(servers.main, { view: controller.welcome.view_token });
    assert.equal(viewer.welcome.role, 'viewer', 'welcome.role');
    // A viewer joining a still view gets the current frame at once, not a black canvas.
    await viewer.frame('the current frame on joining');
    assert.equal(viewer.welcome.resume_token, undefined, 'viewers get no resume token');
    assert.equal(viewer.welcome.view_token, undefined, 'viewers get no view token');

    // Subtests, so that one refusal the server gets wrong does not hide the others.
    await t.test('the viewer gets the frames, the controller counts it', async () => {
        controller.send({ type: 'camera', position: [-1, 1.2, 3.3], target: [0, 1, 0] });
        const seen = await viewer.frame('the viewer gets a frame');
        assert.ok(seen.payload.length > 0);
        const counted = await controller.frame('controller frame counting the viewer', (s) => s.viewers >= 1);
        assert.ok(counted.stats.viewers >= 1, 'stats.viewers');
    });

    await t.test('steering messages from the viewer are read_only', async () => {
        for (const msg of [{ type: 'camera', position: [0, 1, 3], target: [0, 1, 0] }, { type: 'params', values: { exposure: 1 } },
            { type: 'resize', size: [32, 32] }, { type: 'quality', adaptive: true }]) {
            await viewer.expectError(msg, 'read_only', `viewer sends ${msg.type}`);
        }
        await viewer.roundTrip('viewer ping');
    });

    await t.test('a viewer may take a snapshot; only the viewer receives it', async () => {
        viewer.send({ type: 'snapshot' });
        const snap = await viewer.frame('the viewer snapshot', (s) => s.snapshot === true);
        assert.equal(snap.header.codec, 'png');
        await sleep(300);
        assert.equal(controller.inbox.queue.findIndex((m) => m.type === 'stats' && m.snapshot === true), -1,
            'the controller must not receive the viewer snapshot');
    });

    await t.test('an unknown view token is refused and closed', async () => {
        const stranger = await connect(servers.main);
        await stranger.expectError({ type: 'hello', protocol: 1, view: 'v-not-a-real-token' }, 'unknown_view_token');
        await stranger.closedByServer('after unknown_view_token');
    });

    await t.test('when the controller closes with 1000 the viewer gets session_ended and is closed', async () => {
        await controller.close();
        await viewer.inbox.next((m) => m.type === 'error' && m.code === 'session_ended', 'session_ended for the viewer');
        await viewer.closedByServer('viewer after session_ended');
    });
});

check('beyond --max-sessions 2 a new session is refused with busy and close status 1013', async () => {
    const server = servers.limits;
    await server.waitForSessions(0);
    const a = await open(server);
    const b = await open(server);
    assert.equal(b.welcome.role, 'controller');
    const c = await connect(server);
    await c.expectError({ type: 'hello', protocol: 1 }, 'busy', 'third session');
    assert.equal(await c.closedByServer('after busy'), 1013, 'close status 1013 (try again later)');
    await a.close();
    await server.waitForSessions(1);
    const d = await open(server);
    assert.equal(d.welcome.role, 'controller', 'a slot freed by a clean close is available again');
});

check('over --rate-limit messages are dropped with rate_limited and the connection stays', async () => {
    const server = servers.limits;
    const client = await open(server);
    assert.equal(client.welcome.limits?.messages_per_second, 20, 'welcome.limits.messages_per_second');
    for (let i = 0; i < 200; ++i) client.send({ type: 'ping', t: i });
    await client.inbox.next((m) => m.type === 'error' && m.code === 'rate_limited', 'rate_limited error');
    await sleep(2500); // the bucket refills
    client.inbox.clear();
    await client.roundTrip('ping after the flood');
});

// ---------------------------------------------------------------------------------------------
// Adaptive quality

check('adaptive quality: interactive at half size while steering, then balanced and final without input', async () => {
    // frame_target_ms 0: no frame budget, so interactive frames are exactly --interactive-scale.
    const client = await open(servers.main, { adaptive: true, frame_target_ms: 0 });
    assert.equal(client.welcome.adaptive, true);
    assert.equal(client.welcome.frame_target_ms, 0, 'welcome.frame_target_ms echoes hello');
    assert.equal(client.welcome.limits?.interactive_scale, 0.5, 'welcome.limits.interactive_scale');
    assert.equal(client.welcome.limits?.frame_target_ms, 80, 'welcome.limits.frame_target_ms');
    client.send({ type: 'technique', name: 'rsm_gather' });
    client.send({ type: 'params', values: { vpl_grid: 4 } }); // parameters set by the client win over every preset
    const interactive = await client.frame('interactive frame',
        (s) => s.quality === 'interactive' && s.params?.vpl_grid === 4 && s.technique === 'rsm_gather');
    assert.equal(interactive.stats.scale, 0.5, 'stats.scale');
    assert.deepEqual(interactive.stats.size, SIZE.map((v) => v * 0.5), 'half the requested size');
    assert.equal(interactive.stats.refined, false, 'interactive frames are not refined');
    assert.match(interactive.stats.budget?.reason ?? '', /no frame-time target/);

    // No further input: the session refines on its own, in tiles, each frame the full image so far.
    const steps = [];
    let frame = interactive;
    while (!(frame.stats.quality === 'final' && frame.stats.refine?.complete)) {
        frame = await client.frame('refinement frame', (s) => s.frame > frame.stats.frame);
        steps.push(frame.stats.quality);
        assert.ok(steps.length <= 200, `refinement ends with a complete final: ${steps}`);
        if (frame.stats.refined) {
            assert.deepEqual(frame.stats.size, SIZE, 'refinement frames are full size');
            assert.ok(frame.stats.refine.share > 0 && frame.stats.refine.share <= 1, 'refine.share');
        }
    }
    assert.deepEqual([...new Set(steps.filter((q) => q !== 'interactive'))], ['balanced', 'final'], `balanced, then final: ${steps}`);
    assert.equal(frame.stats.refine.share, 1, 'the final frame covers the image');
    const done = await client.inbox.next((m) => m.type === 'progress' && m.state === 'done', 'progress done', 5000);
    assert.equal(done.step, 'final');
    await assert.rejects(client.inbox.nextOfType('stats', 'a frame after final', 600), /nothing within/,
        'nothing is rendered after final without input');

    client.send({ type: 'camera', position: [0.7, 1.1, 3.6], target: [0, 1, 0] });
    const again = await client.frame('input restarts at interactive', (s) => s.frame > frame.stats.frame);
    assert.equal(again.stats.quality, 'interactive');
});

check('the frame budget sizes interactive frames from what they measured, and says why', async () => {
    const client = await open(servers.main, { adaptive: true, frame_target_ms: 200 });
    client.send({ type: 'technique', name: 'rsm_gather' });
    let frame = await client.frame('first interactive frame', (s) => s.quality === 'interactive' && s.technique === 'rsm_gather');
    for (let i = 0; i < 4; i++) {
        client.send({ type: 'camera', position: [0.2 * i, 1, 3.9], target: [0, 1, 0] });
        frame = await client.frame('interactive frame', (s) => s.quality === 'interactive' && s.frame > frame.stats.frame);
    }
    const budget = frame.stats.budget;
    assert.equal(budget.target_ms, 200);
    assert.ok(budget.scale > 0 && budget.scale <= 0.5, `scale within (0, interactive_scale]: ${budget.scale}`);
    assert.equal(frame.stats.scale, budget.scale);
    assert.ok(typeof budget.reason === 'string' && budget.reason.length > 10, 'a reason');
    assert.ok(budget.predicted_ms > 0, 'predicted from measured frames');
    // A tiny target caps the VPLs of a large set and says so.
    client.send({ type: 'quality', adaptive: true, frame_target_ms: 1 });
    client.send({ type: 'params', values: { vpl_grid: 64 } });
    for (let i = 0; i < 4; i++) {
        client.send({ type: 'camera', position: [0.1 * i, 1, 3.8], target: [0, 1, 0] });
        frame = await client.frame('interactive frame', (s) => s.quality === 'interactive' && s.frame > frame.stats.frame);
    }
    assert.equal(frame.stats.budget.target_ms, 1);
    assert.equal(frame.stats.budget.vpls, 4096);
    assert.ok(frame.stats.budget.vpl_cap > 0 && frame.stats.budget.vpl_cap < 4096, `VPLs capped: ${JSON.stringify(frame.stats.budget)}`);
    assert.ok(frame.stats.counts.vpl_count < 4096, 'the frame rendered fewer VPLs');
    // stats.params are what the frame rendered with; the session keeps what the client set.
    assert.ok(frame.stats.params.vpl_grid ** 2 <= frame.stats.budget.vpl_cap, 'rendered within the cap');
});

check('input during a slow refinement is answered at the next tile or VPL part', async () => {
    // 65,536 VPLs: seconds per refinement step on a CPU, rendered in tiles that input interrupts.
    const client = await open(servers.main, { adaptive: true });
    client.send({ type: 'technique', name: 'rsm_gather', seq: 1 });
    client.send({ type: 'params', values: { vpl_grid: 256 }, seq: 2 });
    // A 64 x 64 tile of them takes seconds: it renders in VPL parts, each sent as they add up.
    const refining = await client.frame('a refinement tile in VPL parts',
        (s) => s.refined && s.refine && !s.refine.complete && s.refine.vpl_parts > 1, 60000);
    assert.equal(refining.stats.input_seq, 2, 'the step renders the state after both messages');
    assert.ok(refining.stats.refine.share < 1);
    assert.ok(refining.stats.refine.vpl_parts_done >= 1 && refining.stats.refine.vpl_parts_done <= refining.stats.refine.vpl_parts);
    assert.equal(refining.stats.counts.vpl_parts, refining.stats.refine.vpl_parts, 'the renderer rendered that part');
    const sent = Date.now();
    client.send({ type: 'camera', position: [0.5, 1.1, 3.7], target: [0, 1, 0], seq: 3 });
    const seqs = [];
    const answer = await client.frame('the answer to input', (s) => {
        seqs.push(`${s.quality}:${s.input_seq}`);
        return s.quality === 'interactive' && s.frame > refining.stats.frame;
    }, 10000);
    const waited = Date.now() - sent;
    assert.equal(answer.stats.input_seq, 3, 'the answer shows the camera message');
    // It says when the input arrived on the server's wall clock, this machine's: after the message
    // left and before the frame came (a millisecond's slack for the rounding).
    const arrived = answer.stats.input?.arrived_unix_ms;
    const statsAt = performance.timeOrigin + client.inbox.arrivedAt.get(answer.stats);
    assert.ok(arrived >= sent - 1 && arrived <= statsAt + 1, `input.arrived_unix_ms ${arrived} within [${sent}, ${statsAt}]`);
    assert.ok(answer.stats.input.rendered_ms >= answer.stats.input.wait_ms, JSON.stringify(answer.stats.input));
    assert.ok(seqs.slice(0, -1).every((q) => q.endsWith(':2')), `the abandoned step's frames do not: ${seqs}`);
    const abandoned = await client.inbox.next((m) => m.type === 'progress' && m.state === 'abandoned', 'progress abandoned', 5000);
    assert.ok(abandoned.share < 1);
    // One tile (about --slice-ms) plus one interactive frame; generous for a loaded CI machine.
    assert.ok(waited < 3000, `input answered after ${waited} ms (frame ${answer.stats.frame_ms} ms)`);
});

// ---------------------------------------------------------------------------------------------
// HTTP API

check('POST /api/render returns the PNG gi-render writes for the same request', async () => {
    const request = { scene: 'builtin:cornell', technique: 'rsm_gather', params: { vpl_grid: 4 }, size: [64, 64], format: 'png' };
    const res = await servers.main.http('/api/render', {
        method: 'POST', body: JSON.stringify(request), headers: { 'Content-Type': 'application/json' }, timeoutMs: 30000,
    });
    assert.equal(res.status, 200, `POST /api/render: ${res.body.toString().slice(0, 300)}`);
    assert.match(res.headers['content-type'] ?? '', /^image\/png/);
    assert.ok(isPng(res.body), 'the body is a PNG');
    const stats = JSON.parse(res.headers['x-gi-stats'] ?? 'null');
    assert.deepEqual(stats?.size, [64, 64], 'X-GI-Stats carries the stats');

    const dir = mkdtempSync(path.join(os.tmpdir(), 'gi-e2e-render-'));
    try {
        const out = path.join(dir, 'file.png');
        const render = spawnSync(path.join(path.dirname(SERVER), 'gi-render'), ['--scene', 'builtin:cornell',
            '--technique', 'rsm_gather', '--param', 'vpl_grid=4', '--size', '64x64', '--out', out, '--quiet'],
        { encoding: 'utf8', timeout: 30000 });
        assert.equal(render.status, 0, `gi-render failed: ${render.error ?? ''}${render.stderr}`);
        assert.ok(readFileSync(out).equals(res.body), 'byte-identical to gi-render --out');
    } finally {
        rmSync(dir, { recursive: true, force: true });
    }
});

check('POST /api/render with a bad field is 400 naming the field', async () => {
    const post = (body) => servers.main.http('/api/render', {
        method: 'POST', body, headers: { 'Content-Type': 'application/json' },
    });
    for (const [request, where] of [
        [{ scene: 'builtin:cornell', size: [8, 64] }, '/size/0'],
        [{ scene: 'builtin:cornell', format: 'gif' }, '/format'],
        [{ scene: 'builtin:cornell', bogus: 1 }, '/bogus'],
        [{ scene: 'builtin:cornell', params: { vpl_grid: 'many' } }, '/params/vpl_grid'],
    ]) {
        const res = await post(JSON.stringify(request));
        assert.equal(res.status, 400, `${JSON.stringify(request)}: status`);
        const body = JSON.parse(res.body.toString());
        assert.equal(typeof body.error, 'string', 'error code');
        assert.equal(body.where, where, `${JSON.stringify(request)}: where`);
    }
    assert.equal((await post('{not json')).status, 400, 'invalid JSON');
});

check('GET /metrics is Prometheus text with the session and frame counters', async () => {
    const client = await open(servers.main);
    await client.frame('a frame to count');
    const res = await servers.main.http('/metrics');
    assert.equal(res.status, 200);
    const text = res.body.toString();
    for (const name of ['gis_sessions', 'gis_frames_total']) {
        assert.match(text, new RegExp(`^${name}(\\{[^}]*\\})? `, 'm'), `a ${name} sample`);
    }
});

check('a zipped .gltf with its .bin and texture folder uploads and renders; bad archives are 400', async () => {
    const client = await open(servers.main);
    const uploadZip = (name, body) => upload(client, name, body, 'application/zip');
    // glTF Transform's .gltf + .bin + PNG of the corpus box, zipped (tests/data/corpus/compress.sh).
    const zip = readFileSync(path.join(REPO, 'tests/data/corpus/textured_box_gltf.zip'));
    const res = await uploadZip('box.zip', zip);
    assert.equal(res.status, 201, `status (${res.body.toString().slice(0, 300)})`);
    const stored = JSON.parse(res.body.toString());
    assert.equal(stored.scene, 'upload:box.zip');
    assert.equal(stored.file, 'textured_box/textured_box.gltf');
    client.send({ type: 'scene', name: 'upload:box.zip' });
    const frame = await client.frame('a frame of the zipped scene', (s) => s.scene === 'upload:box.zip');
    assert.equal(frame.stats.counts?.triangles, 108, 'the box, with its .bin read from the folder');

    const notZip = await uploadZip('bad.zip', Buffer.from('glTF not a zip'));
    assert.equal(notZip.status, 400);
    assert.equal(JSON.parse(notZip.body.toString()).error, 'not_zip');
    const damaged = await uploadZip('bad.zip', zip.subarray(0, zip.length / 2));
    assert.equal(damaged.status, 400);
    const body = JSON.parse(damaged.body.toString());
    assert.equal(body.error, 'bad_archive');
    assert.match(body.message, /damaged/);
});

check('an uploaded Blender file with linked duplicates stays instanced: the state and the frame say so', async () => {
    const client = await open(servers.main);
    const glb = readFileSync(path.join(REPO, 'tests/data/corpus/colonnade.glb'));
    const res = await upload(client, 'colonnade.glb', glb);
    assert.equal(res.status, 201, `status (${res.body.toString().slice(0, 300)})`);
    client.send({ type: 'scene', name: 'upload:colonnade.glb' });
    const state = await client.inbox.next((m) => m.type === 'state' && m.state?.scene === 'upload:colonnade.glb',
        'state after the upload loads', 15000);
    assert.equal(state.state.load.instances, 12, 'twelve placements of the column');
    assert.ok(state.state.load.triangles_stored * 5 < state.state.load.triangles, 'the column is held once');
    const frame = await client.frame('a frame of the colonnade', (s) => s.scene === 'upload:colonnade.glb');
    assert.equal(frame.stats.counts?.instances, 12);
    assert.equal(frame.stats.counts?.triangles, state.state.load.triangles);
});

/**
 * An adaptive session past its first frame of the built-in scene that has asked for `name`, an
 * upload of `images` 4096 x 4096 PNGs (about 250 ms of decoding each), and seen its `loading`.
 * `askedAt`: when the scene was asked for.
 */
async function loadingSlowUpload(name, images) {
    const client = await open(servers.main, { adaptive: true });
    await client.frame('a first frame of the built-in scene', (s) => s.scene === 'builtin:cornell');
    const res = await upload(client, name, slowToLoadGlb(4096, images));
    assert.equal(res.status, 201, `status (${res.body.toString().slice(0, 300)})`);
    const askedAt = performance.now();
    client.send({ type: 'scene', name: `upload:${name}` });
    await client.inbox.next((m) => m.type === 'progress' && m.state === 'loading', 'progress loading', 15000);
    return { client, askedAt };
}

check('input during a scene load is answered by the view in place; the new scene follows', async () => {
    // The load runs on its own thread.
    const { client } = await loadingSlowUpload('slow.glb', 1);
    const sentAt = performance.now();
    client.send({ type: 'camera', position: [0.5, 1.1, 3.7], target: [0, 1, 0] });
    const answer = await client.frame('the view in place answers the camera', (s) => s.scene === 'builtin:cornell' &&
        s.quality === 'interactive' && s.input !== undefined && client.inbox.arrivedAt.get(s) > sentAt, 15000);
    const loaded = await client.inbox.next((m) => m.type === 'progress' && m.state === 'loaded', 'progress loaded', 30000);
    const answeredAt = client.inbox.arrivedAt.get(answer.stats), loadedAt = client.inbox.arrivedAt.get(loaded);
    assert.ok(answeredAt < loadedAt,
        `the answer (input waited ${answer.stats.input.wait_ms} ms) came before the load ended (${loaded.reason})`);
    await client.inbox.next((m) => m.type === 'state' && m.state?.scene === 'upload:slow.glb', 'state of the new scene', 15000);
    await client.frame('a frame of the new scene', (s) => s.scene === 'upload:slow.glb', 15000);
});

check('a scene asked for during a load cancels that load: the newer scene does not wait for it', async () => {
    // Three images: about 750 ms of decoding, checked for a cancel between images.
    const { client, askedAt: loadAskedAt } = await loadingSlowUpload('slower.glb', 3);
    const askedAt = performance.now();
    client.send({ type: 'scene', name: 'builtin:cornell-empty' });
    await client.inbox.next((m) => m.type === 'state' && m.state?.scene === 'builtin:cornell-empty',
        'state of the newer scene', 15000);
    const stateAt = performance.now();
    console.log(`# the newer scene's state ${Math.round(stateAt - askedAt)} ms after it was asked for ` +
        `(${Math.round(askedAt - loadAskedAt)} ms into the cancelled load)`);
    const oldLoad = client.inbox.queue.filter((m) => m.type === 'progress' && m.state === 'loaded' &&
        m.reason.includes('slower.glb'));
    assert.deepEqual(oldLoad, [], 'the cancelled load never finished');
    assert.ok(!client.inbox.queue.some((m) => m.type === 'error'), 'a cancel is no error');
    await client.frame('a frame of the newer scene', (s) => s.scene === 'builtin:cornell-empty', 15000);
});

check('a textured scene reaches GL in slices between frames, not in one hold of the render thread', async () => {
    // Four quads, each with a texture of its own (one 2048 x 2048 PNG, decoded four times): creating
    // and filling a texture with its mipmaps is several pieces, sent about --slice-ms at a time.
    const png = slowToLoadGlb(2048, 1);
    const glb = texturedQuadsGlb(png, 4);
    const client = await open(servers.main, { adaptive: true });
    await client.frame('a first frame of the built-in scene', (s) => s.scene === 'builtin:cornell');
    const res = await upload(client, 'quads.glb', glb);
    assert.equal(res.status, 201, `status (${res.body.toString().slice(0, 300)})`);
    client.send({ type: 'scene', name: 'upload:quads.glb' });
    const state = await client.inbox.next((m) => m.type === 'state' && m.state?.scene === 'upload:quads.glb',
        'state of the textured scene', 30000);
    const load = state.state.load;
    console.log(`# upload: ${Math.round(load.upload_ms)} ms of the render thread in ${load.upload_slices} slices, ` +
        `the longest ${Math.round(load.upload_slice_max_ms)} ms`);
    assert.ok(load.upload_slices >= 2, `several slices (${load.upload_slices})`);
    assert.ok(load.upload_slice_max_ms < load.upload_ms, 'no slice holds the whole upload');
    assert.match(servers.main.log, /upload:quads\.glb uploaded to GL in \d+ ms of the render thread \(\d+ slices/);
    const frame = await client.frame('a frame of the textured scene', (s) => s.scene === 'upload:quads.glb', 15000);
    assert.equal(frame.stats.counts?.triangles, 8);
    await client.close();
});


check('a session that ends during a load cancels it: its teardown does not wait for the file', async () => {
    const { client } = await loadingSlowUpload('abandoned.glb', 3);
    const closedAt = performance.now();
    await client.close();
    const deadline = Date.now() + 15000;
    let health = await servers.main.health();
    while (health.teardowns_pending > 0 || servers.main.log.match(/upload:abandoned\.glb load cancelled/) === null) {
        assert.ok(Date.now() < deadline, `the teardown did not finish: ${JSON.stringify(health)}`);
        await sleep(10);
        health = await servers.main.health();
    }
    console.log(`# the session's teardown finished ${Math.round(performance.now() - closedAt)} ms after the close`);
    assert.doesNotMatch(servers.main.log, /upload:abandoned\.glb loaded/, 'the load never finished');
});

check('the final step waits for the effect planner\'s ray structure without holding input, and keeps it', async () => {
    const client = await open(servers.main, { adaptive: true });
    await client.frame('a first frame', (s) => s.scene === 'builtin:cornell');
    client.send({ type: 'scene', name: 'builtin:atrium' });
    // The final step plans effects (adaptive quality); the atrium's 560k triangles take a while to
    // build into the planner's ray structure, on a thread of the session's own.
    await client.inbox.next((m) => m.type === 'progress' && m.step === 'final' && /effect plan/.test(m.reason),
        'the final step says it waits for the effect plan', 60000);
    const sentAt = performance.now();
    client.send({ type: 'camera', position: [4, 3, 9], target: [0, 2, 0] });
    const answer = await client.frame('the camera is answered meanwhile', (s) => s.scene === 'builtin:atrium' &&
        s.quality === 'interactive' && client.inbox.arrivedAt.get(s) > sentAt, 15000);
    assert.ok(answer.stats.plan === undefined || answer.stats.plan.mode !== 'auto' || answer.stats.plan.pending !== undefined,
        'an interactive frame does not wait for a plan');
    const planned = await client.frame('a final frame with its plan', (s) => s.quality === 'final' &&
        Array.isArray(s.plan?.decisions), 60000);
    assert.ok(planned.stats.plan.decisions.length > 0);
    // A camera move far enough to plan again: the structure is kept, so this plan is rays only.
    client.send({ type: 'camera', position: [-6, 4, 8], target: [0, 2, 0] });
    await client.frame('the move is answered', (s) => s.quality === 'interactive', 15000);
    const replanned = await client.frame('the next final frame with its plan', (s) => s.quality === 'final' &&
        Array.isArray(s.plan?.decisions), 60000);
    // The cornell view's own final step may have started (and built cornell's structure) before the
    // scene message arrived: only the atrium's builds count.
    const builds = servers.main.log.split('\n').filter((l) => l.includes(`session ${client.welcome.session}: building the effect planner`) &&
        l.includes('builtin:atrium'));
    assert.equal(builds.length, 1, `one build for the session's scene: ${builds.join(' | ')}`);
    console.log(`# plans: ${planned.stats.plan.analysis_ms.toFixed(1)} ms, then ${replanned.stats.plan.analysis_ms.toFixed(1)} ms; ` +
        `${servers.main.log.match(/ray structure built in \d+ ms/g)?.at(-1) ?? ''}`);
});

check('a second session on the same scene plans with the first one\'s ray structure', async () => {
    const planned = async (client) => {
        await client.frame('a first frame', () => true);
        client.send({ type: 'scene', name: 'builtin:atrium' });
        return client.frame('a final frame with its plan', (s) => s.scene === 'builtin:atrium' && s.quality === 'final' &&
            Array.isArray(s.plan?.decisions), 60000);
    };
    const first = await open(servers.main, { adaptive: true });
    await planned(first);
    const second = await open(servers.main, { adaptive: true });
    await planned(second);
    const lines = (session) => servers.main.log.split('\n').filter((l) => l.includes(`session ${session}: `));
    assert.ok(!lines(second.welcome.session).some((l) => l.includes('building the effect planner') && l.includes('builtin:atrium')),
        'the second session builds nothing for the atrium');
    assert.ok(lines(second.welcome.session).some((l) => l.includes('is shared with another session') && l.includes('builtin:atrium')),
        'it says it shares the atrium\'s structure');
});

check('interactive frames of a big scene draw its levels of detail once built, shared with the next session; refinement draws every triangle', async () => {
    const client = await open(servers.main, { adaptive: true });
    await client.frame('a first frame', (s) => s.scene === 'builtin:cornell');
    client.send({ type: 'scene', name: 'builtin:atrium' });
    await client.frame('an atrium frame', (s) => s.scene === 'builtin:atrium', 60000);
    // The levels are built on a thread of the session's own after the scene shows: moves are answered
    // meanwhile, at full detail, until they are ready.
    let simplified = null;
    for (let k = 0; k < 60 && !simplified; ++k) {
        client.send({ type: 'camera', position: [6 - 0.1 * k, 2.6, 1.2], target: [-6, 2.2, -0.8] });
        const f = await client.frame('an interactive atrium frame', (s) => s.scene === 'builtin:atrium' && s.quality === 'interactive', 15000);
        assert.equal(f.stats.budget?.lod_pixels, 1, 'stats.budget.lod_pixels: the server default');
        assert.equal(f.stats.params?.lod_pixels, 1, 'the frame rendered with it');
        assert.equal(f.stats.params?.light_lod_texels, 1, 'its light views within a texel');
        assert.equal(f.stats.budget?.light_lod_texels, 1, 'stats.budget.light_lod_texels');
        if (f.stats.counts?.triangles_gbuffer_simplified > 0) simplified = f;
        else await sleep(100);
    }
    assert.ok(simplified, 'an interactive frame drew simplified triangles');
    assert.ok(simplified.stats.counts.triangles_gbuffer < 0.5 * simplified.stats.counts.triangles,
        `far fewer triangles drawn: ${simplified.stats.counts.triangles_gbuffer} of ${simplified.stats.counts.triangles}`);
    assert.ok(await logged(servers.main, `session ${client.welcome.session}: levels of detail for builtin:atrium built in`),
        'the build is logged');
    const refined = await client.frame('a refinement frame', (s) => s.quality === 'balanced' || s.quality === 'final', 60000);
    assert.equal(refined.stats.params?.lod_pixels, 0, 'refinement draws every triangle');
    assert.equal(refined.stats.counts?.triangles_gbuffer_simplified, undefined);
    assert.equal(refined.stats.params?.light_lod_texels, 1, 'and keeps the light views within a texel');

    // A second session on the same scene uses the first one's levels: its first moved frame draws them.
    const second = await open(servers.main, { adaptive: true });
    await second.frame('a first frame', () => true);
    second.send({ type: 'scene', name: 'builtin:atrium' });
    await second.frame('an atrium frame', (s) => s.scene === 'builtin:atrium', 60000);
    second.send({ type: 'camera', position: [5, 2.6, 1.2], target: [-6, 2.2, -0.8] });
    const moved = await second.frame('a moved frame', (s) => s.scene === 'builtin:atrium' && s.quality === 'interactive' &&
        s.counts?.triangles_gbuffer_simplified > 0, 15000);
    assert.ok(moved.stats.counts.triangles_gbuffer_simplified > 0);
    assert.ok(await logged(servers.main,
        `session ${second.welcome.session}: the levels of detail for builtin:atrium are shared with another session`),
    'the second session says it shares the levels');
    const lines = servers.main.log.split('\n').filter((l) => l.includes(`session ${second.welcome.session}: `));
    assert.ok(!lines.some((l) => l.includes('levels of detail for builtin:atrium built in')), 'and builds none');

    // A client that wants every triangle in its own view still gets the light views within a texel,
    // which need the levels as well.
    const third = await open(servers.main, { adaptive: true });
    await third.frame('a first frame', () => true);
    third.send({ type: 'params', values: { lod_pixels: 0 } });
    third.send({ type: 'scene', name: 'builtin:atrium' });
    const lit = await third.frame('an atrium frame with simplified light views', (s) => s.scene === 'builtin:atrium' &&
        s.counts?.triangles_light_views_simplified > 0, 30000);
    assert.equal(lit.stats.params?.lod_pixels, 0, 'the client\'s lod_pixels holds');
    assert.equal(lit.stats.counts?.triangles_gbuffer_simplified, undefined);
    await third.close();
    await second.close();
    await client.close();
});

check('a fixed-quality view with effects=auto is planned when the ray structure is ready, without input', async () => {
    const client = await open(servers.main);
    await client.frame('a first frame', (s) => s.scene === 'builtin:cornell');
    client.send({ type: 'params', values: { effects: 'auto' } });
    client.send({ type: 'scene', name: 'builtin:atrium' });
    const first = await client.frame('the first frame of the new scene', (s) => s.scene === 'builtin:atrium', 60000);
    if (Array.isArray(first.stats.plan?.decisions)) {
        console.log('# the structure was ready before the first frame: nothing to wait for');
        return;
    }
    assert.match(first.stats.plan?.pending ?? '', /measuring the scene/, 'the frame says it is not planned yet');
    const planned = await client.frame('the view again once the plan is ready', (s) => Array.isArray(s.plan?.decisions), 60000);
    assert.equal(planned.stats.scene, 'builtin:atrium');
    console.log(`# unplanned first frame ("${first.stats.plan.pending}"), planned frame ${planned.stats.frame} without input`);
});

check('POST /api/upload of a body that is not a .glb is 400', async () => {
    const client = await open(servers.main);
    const res = await upload(client, 'tiny.glb', Buffer.from('not a glb'));
    assert.equal(res.status, 400, `status (${res.body.toString().slice(0, 200)})`);
    assert.equal(typeof JSON.parse(res.body.toString()).error, 'string', 'a JSON error');
});
