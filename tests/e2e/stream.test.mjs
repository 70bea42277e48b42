// End-to-end test of gi-server: starts the binary, talks protocol v1 over a real WebSocket and
// checks the HTTP side. Run: GI_SERVER=build/dev/bin/gi-server node --test tests/e2e/
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';

import { Client, isJpeg, REPO, ServerProcess } from './helpers.mjs';

let server = null;
let client = null;
let lastFrame = null; // {header, payload, stats}

/** The next frame, checked to be a JPEG whose stats agree with it. */
async function receiveFrame(what, match) {
    const frame = await client.frame(what, match);
    assert.equal(frame.header.codec, 'jpeg', `${what}: codec 1 (JPEG), as asked for in hello`);
    assert.ok(isJpeg(frame.payload), `${what}: payload is a JPEG (SOI ... EOI)`);
    // PROTOCOL.md does not say whether `bytes` counts the 16-byte header; accept either.
    assert.ok([frame.payload.length, frame.payload.length + 16].includes(frame.stats.bytes),
        `${what}: stats.bytes (${frame.stats.bytes}) is the size of the JPEG (${frame.payload.length}) or of the message`);
    return frame;
}

before(async () => {
    // A VPL-grid technique rather than the presets' default: step d sets `vpl_grid` and counts the VPLs.
    server = await ServerProcess.start(['--scene', 'builtin:cornell', '--technique', 'multires_gather', '--client-dir',
        path.join(REPO, 'client')]);
});

after(async () => {
    await client?.close();
    await server?.stop();
});

test('gi-server streams frames over the gi-stream WebSocket', async (t) => {
    let anyFailed = false;
    t.after(() => {
        if (anyFailed) console.error(`--- gi-server log ---\n${server.log}`);
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
    await step('a. hello first, then welcome', async () => {
        // adaptive false: every frame is exactly the requested state (no scaled interactive frames).
        client = await Client.open(server, { codecs: ['jpeg'], adaptive: false });
        welcome = client.welcome;
        assert.equal(welcome.protocol, 2, 'welcome.protocol is 2');
        assert.equal(welcome.role, 'controller', 'a new session makes this client its controller');
        assert.equal(welcome.resumed, false, 'a new session is not resumed');
        assert.equal(welcome.codec, 'jpeg', 'the codec asked for in hello');
        for (const token of ['resume_token', 'view_token']) {
            assert.equal(typeof welcome[token], 'string', `welcome.${token} is a string`);
            assert.ok(welcome[token].length >= 16, `welcome.${token} is long enough to be a secret`);
        }
        assert.ok(Array.isArray(welcome.techniques), 'welcome.techniques is a list');
        const names = welcome.techniques.map((x) => x.name);
        for (const name of ['rsm_gather', 'none']) assert.ok(names.includes(name), `techniques include ${name}: ${names}`);
        for (const technique of welcome.techniques) {
            assert.equal(technique.params_schema?.type, 'object', `${technique.name} has a params_schema object`);
        }
        assert.equal(welcome.frame_params_schema?.type, 'object', 'welcome has frame_params_schema');
        assert.ok(welcome.scenes?.includes('builtin:cornell'), 'scenes include builtin:cornell');
        assert.equal(welcome.state?.scene, 'builtin:cornell', 'the session starts on --scene');
        assert.equal(typeof welcome.limits?.max_message_bytes, 'number', 'welcome.limits.max_message_bytes');
    });

    await step('b. resize to 256x256 gives stats and a JPEG frame', async () => {
        client.send({ type: 'resize', size: [256, 256] });
        // The first frame may have been rendered at the default size before the resize arrived;
        // take frames until one is 256x256.
        const frame = await receiveFrame('frame after resize', (stats) => stats.size[0] === 256);
        assert.deepEqual([frame.header.width, frame.header.height], [256, 256], 'frame is 256x256 after resize');
        assert.equal(frame.stats.type, 'stats');
        assert.equal(frame.stats.codec, 'jpeg', 'stats.codec is jpeg');
        assert.ok(Array.isArray(frame.stats.passes) && frame.stats.passes.length > 0, 'stats lists passes');
        assert.ok(typeof frame.stats.frame_ms === 'number', 'stats.frame_ms is a number');
        assert.equal(frame.stats.quality, 'fixed', 'stats.quality is fixed with adaptive false');
        lastFrame = frame;
    });

    await step('c. a camera change renders a different frame', async () => {
        client.send({ type: 'camera', position: [1.2, 1.4, 3.2], target: [0, 1, 0] });
        const frame = await receiveFrame('frame after camera change', (stats) => stats.frame > lastFrame.header.frame);
        assert.ok(!frame.payload.equals(lastFrame.payload), 'the new camera gives different image bytes');
        lastFrame = frame;
    });

    await step('d. bad messages get errors and the session survives', async () => {
        await client.expectError('{not json', 'invalid_json', 'malformed JSON');
        const small = await client.expectError({ type: 'resize', size: [8, 8] }, 'invalid_message', 'resize 8x8');
        assert.equal(small.where, '/size/0', 'resize 8x8: where points at the first bad value');
        await client.expectError({ type: 'teleport' }, 'unknown_type', 'unknown message type');
        await client.expectError({ type: 'params', values: { vpl_grid: 100000 } }, 'invalid_param', 'out-of-range parameter');
        client.ws.send(Buffer.from([1, 2, 3]), { binary: true });
        await client.inbox.next((m) => m.type === 'error' && m.code === 'binary_not_accepted', 'binary from the client');
        client.send({ type: 'params', values: { vpl_grid: 8 } });
        const frame = await receiveFrame('frame after params change', (stats) => stats.params?.vpl_grid === 8);
        assert.equal(frame.stats.counts?.vpl_count, 64, 'stats.counts.vpl_count is 8^2');
        // The effect plan: asked for through a frame parameter, reported in the stats.
        client.send({ type: 'params', values: { effects: 'auto' } });
        // The first frame may come before the scene's ray structure for the planner is built: it says
        // so, and the view is rendered again, planned, when the structure is ready.
        const first = await receiveFrame('frame after effects=auto', (stats) => stats.params?.effects === 'auto');
        assert.equal(first.stats.plan?.mode, 'auto', 'stats.plan.mode is auto');
        if (!Array.isArray(first.stats.plan?.decisions))
            assert.match(first.stats.plan?.pending ?? '', /measuring the scene/, 'an unplanned frame says why');
        const planned = Array.isArray(first.stats.plan?.decisions) ? first
            : await receiveFrame('the planned frame', (stats) => Array.isArray(stats.plan?.decisions));
        assert.ok(Array.isArray(planned.stats.plan?.decisions) && planned.stats.plan.decisions.length >= 4,
                  'stats.plan lists the decisions');
        client.send({ type: 'ping', t: 42.5 });
        const pong = await client.inbox.nextOfType('pong', 'pong');
        assert.equal(pong.t, 42.5, 'pong echoes t');
    });

    await step('e. HTTP: client files, API, 404 and no path traversal', async () => {
        const index = await server.http('/');
        assert.equal(index.status, 200, 'GET / is 200');
        assert.match(index.headers['content-type'] ?? '', /^text\/html/, 'GET / is text/html');
        assert.match(index.body.toString(), /<script type="module" src="main\.js">/, 'GET / is client/index.html');

        const js = await server.http('/protocol.js');
        assert.equal(js.status, 200, 'GET /protocol.js is 200');
        assert.match(js.headers['content-type'] ?? '', /javascript/, 'ES modules are served as JavaScript');

        const api = await server.http('/api/techniques');
        assert.equal(api.status, 200, 'GET /api/techniques is 200');
        assert.match(api.headers['content-type'] ?? '', /json/, '/api/techniques is JSON');
        const body = JSON.parse(api.body.toString());
        const list = Array.isArray(body) ? body : body.techniques;
        assert.ok(Array.isArray(list), '/api/techniques lists techniques');
        const names = list.map((x) => (typeof x === 'string' ? x : x.name));
        assert.ok(names.includes('rsm_gather') && names.includes('none'), `/api/techniques names: ${names}`);

        assert.equal((await server.http('/nonexistent')).status, 404, 'GET /nonexistent is 404');
        for (const attempt of ['/../etc/passwd', '/../../../../etc/passwd', '/%2e%2e/%2e%2e/etc/passwd',
            '/..%2f..%2f..%2fetc%2fpasswd', '/test/../../protocol/PROTOCOL.md']) {
            const res = await server.http(attempt);
            assert.ok([400, 403, 404].includes(res.status), `GET ${attempt} is refused (got ${res.status})`);
            assert.ok(!res.body.toString().includes('root:'), `GET ${attempt} does not leak /etc/passwd`);
        }
    }, { independent: true });

    assert.deepEqual(client?.inbox.unclaimed().filter((type) => type === 'error') ?? [], [], 'no unexpected error messages');
});
