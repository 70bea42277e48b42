// Parameter extremes through the service's entry points (issue #10, "bad input"; tests/robustness/README.md):
// the WebSocket protocol and the HTTP API of one gi-server. Every case is derived from the parameter
// tables the server publishes (GET /api/techniques: each technique's params_schema and the
// frame_params_schema), never hand-listed:
//   - rejected: below minimum, above maximum, non-integer for integers, NaN (JSON null), wrong type,
//     unknown enum option, unknown name, for every parameter of every technique, over HTTP and over
//     the WebSocket; each error must name the parameter, the value and the allowed range;
//   - rendered: every parameter's in-range extremes (minimum and maximum, every enum option, both
//     booleans) over HTTP, and every parameter's far extreme over the WebSocket; each parameter is
//     rendered with one technique that has it, chosen round-robin among its owners (sampling keeps
//     the run near 1 min; see the README);
//   - camera and light extremes (fov, zero direction, NaN position, huge intensity, unparsable
//     numbers): a clear error or a sane frame, and the server answers /healthz after every one.
// Run: GI_SERVER=build/dev/bin/gi-server node --test tests/e2e/robustness.test.mjs
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';

import { Client, decodePng, REPO, ServerProcess, testGroup } from './helpers.mjs';

const SIZE = [16, 16]; // the smallest size every entry point accepts
let server = null;
let api = null; // GET /api/techniques
const group = testGroup(test); // closes each test's clients; remembers failures for the log
const { clients, check } = group;

before(async () => {
    server = await ServerProcess.start(['--scene', 'builtin:cornell', '--technique', 'none', '--size',
        `${SIZE[0]}x${SIZE[1]}`, '--max-size', '64x64', '--rate-limit', '100000', '--client-dir',
        path.join(REPO, 'client')]);
    const res = await server.http('/api/techniques');
    assert.equal(res.status, 200);
    api = JSON.parse(res.body.toString());
});

after(async () => {
    if (group.failed() && server) console.error(`--- gi-server log ---\n${server.log.slice(-4000)}`);
    await Promise.all([...clients].map((c) => c.close()));
    if (server) await server.stop();
});


// ---- cases derived from the published tables ---------------------------------------------------------

/** [{technique, name, schema}] for every parameter of every technique, frame parameters included. */
function allParams() {
    const out = [];
    for (const t of api.techniques) {
        const own = t.params_schema?.properties ?? {};
        for (const [name, schema] of Object.entries({ ...api.frame_params_schema.properties, ...own }))
            out.push({ technique: t.name, name, schema });
    }
    return out;
}

/**
 * Each parameter name once, with one technique that has it: the owners take turns (round-robin by
 * the order names first appear), so every technique renders some of the shared parameters.
 */
function sampledParams() {
    const owners = new Map();
    for (const p of allParams()) {
        if (!owners.has(p.name)) owners.set(p.name, []);
        owners.get(p.name).push(p);
    }
    // A VPL count's maximum (65536 VPLs) costs ~40 s a frame in the splatting technique on llvmpipe:
    // such parameters render on their first owner, the plain gather.
    return [...owners.values()].map((list, i) => list[/VPL/.test(list[0].schema['x-unit'] ?? '') ? 0 : i % list.length]);
}

/** Out-of-range and wrongly typed values of one parameter, each with what the error must show. */
function badValues(schema) {
    const out = [];
    const numeric = schema.type === 'number' || schema.type === 'integer';
    if (numeric) {
        out.push({ kind: 'below minimum', value: schema.minimum - 1, shows: String(schema.minimum - 1) });
        out.push({ kind: 'above maximum', value: schema.maximum + 1, shows: String(schema.maximum + 1) });
        if (schema.type === 'integer')
            out.push({ kind: 'not an integer', value: schema.minimum + 0.5, shows: String(schema.minimum + 0.5) });
        out.push({ kind: 'string', value: String(schema.default), shows: JSON.stringify(String(schema.default)) });
    }
    if (schema.type === 'string') {
        out.push({ kind: 'unknown option', value: 'no_such_option', shows: "'no_such_option'" });
        out.push({ kind: 'number', value: 1, shows: '1' });
    }
    if (schema.type === 'boolean') out.push({ kind: 'string', value: 'yes', shows: '"yes"' });
    // JSON has no NaN: JSON.stringify sends null, which the tables reject like any wrong type.
    out.push({ kind: 'NaN (null)', value: NaN, shows: 'null' });
    out.push({ kind: 'array', value: [1], shows: '[1]' });
    return out;
}

/** In-range extremes: minimum and maximum, every enum option, both booleans. */
function extremes(schema) {
    if (schema.type === 'boolean') return [false, true];
    if (schema.enum) return schema.enum;
    return [schema.minimum, schema.maximum];
}

/** The far extreme only (the WebSocket's sample): maximum, last option, the non-default boolean. */
function farExtreme(schema) {
    if (schema.type === 'boolean') return !schema.default;
    if (schema.enum) return schema.enum.at(-1);
    return schema.maximum;
}

/** The error text must say what (the parameter and the value) and how to fix it (the allowed range). */
function assertParamMessage(message, { name, schema }, bad, what) {
    assert.ok(message.includes(`'${name}'`), `${what}: names the parameter: ${message}`);
    assert.ok(message.includes(`got ${bad.shows}`), `${what}: shows the value (got ${bad.shows}): ${message}`);
    if (schema.type === 'number' || schema.type === 'integer') {
        const range = /\[([-0-9.e+]+), ([-0-9.e+]+)\]/.exec(message);
        assert.ok(range, `${what}: gives the range [min, max]: ${message}`);
        assert.equal(Number(range[1]), schema.minimum, `${what}: the range's minimum: ${message}`);
        assert.equal(Number(range[2]), schema.maximum, `${what}: the range's maximum: ${message}`);
        assert.ok(message.includes(schema.type === 'integer' ? 'an integer' : 'a number'), `${what}: the type: ${message}`);
        if (schema['x-unit']) assert.ok(message.includes(schema['x-unit']), `${what}: the unit: ${message}`);
    } else if (schema.enum) {
        for (const o of schema.enum) assert.ok(message.includes(`'${o}'`), `${what}: lists option '${o}': ${message}`);
    } else {
        assert.ok(message.includes('true or false'), `${what}: says true or false: ${message}`);
    }
}

function assertFiniteStats(stats, what) {
    assert.ok(Number.isFinite(stats.frame_ms) && stats.frame_ms >= 0, `${what}: frame_ms ${stats.frame_ms}`);
    for (const p of stats.passes ?? []) {
        for (const key of ['gpu_ms', 'cpu_ms']) {
            if (key in p) assert.ok(Number.isFinite(p[key]), `${what}: pass ${p.name} ${key} ${p[key]}`);
        }
    }
}

async function render(body) {
    const res = await server.http('/api/render', { method: 'POST', body: JSON.stringify({ response: 'json', ...body }) });
    return { status: res.status, json: JSON.parse(res.body.toString()) };
}

/** Runs fn over items with `width` in flight (the server has one render slot per core). */
async function pooled(items, width, fn) {
    let next = 0;
    await Promise.all(Array.from({ length: width }, async () => {
        while (next < items.length) await fn(items[next++]);
    }));
}

async function assertHealthy(what) {
    const health = await server.health();
    assert.equal(health.status, 'ok', `${what}: /healthz ok`);
}

// ---- HTTP ----------------------------------------------------------------------------------------------

check('HTTP: every out-of-range or mistyped value of every parameter is a 400 naming it', async () => {
    const cases = allParams().flatMap((p) => badValues(p.schema).map((bad) => ({ p, bad })));
    for (const t of api.techniques) {
        cases.push({ p: { technique: t.name, name: 'no_such_param' }, unknown: true });
    }
    assert.ok(cases.length > 300, `derived ${cases.length} cases`);
    await pooled(cases, 4, async ({ p, bad, unknown }) => {
        const what = `HTTP ${p.technique}.${p.name} ${bad?.kind ?? 'unknown name'}`;
        const { status, json } = await render({ scene: 'builtin:cornell', technique: p.technique, size: SIZE,
            params: { [p.name]: unknown ? 1 : bad.value } });
        assert.equal(status, 400, `${what}: status (${JSON.stringify(json)})`);
        assert.equal(json.error, 'invalid_request', `${what}: code`);
        assert.equal(json.where, `/params/${p.name}`, `${what}: where`);
        if (unknown) {
            assert.match(json.message, /unknown parameter 'no_such_param'.*known: /, `${what}: ${json.message}`);
        } else {
            assertParamMessage(json.message, p, bad, what);
        }
    });
    // Numbers JSON cannot carry: a clear parse error, not a crash.
    for (const text of ['{"scene": "builtin:cornell", "params": {"exposure": 1e400}}',
        '{"scene": "builtin:cornell", "params": {"exposure": NaN}}',
        '{"scene": "builtin:cornell", "params": {"exposure": Infinity}}']) {
        const res = await server.http('/api/render', { method: 'POST', body: text });
        const json = JSON.parse(res.body.toString());
        assert.equal(res.status, 400, text);
        assert.equal(json.error, 'invalid_json', text);
        assert.match(json.message, /not valid JSON: .+/, `${text}: says why: ${json.message}`);
    }
    await assertHealthy('after HTTP bad values');
});

check('HTTP: every parameter\'s in-range extremes render (sampled: one technique per parameter)', async () => {
    const cases = sampledParams().flatMap((p) => extremes(p.schema).map((value) => ({ p, value })));
    const seconds = [];
    await pooled(cases, 2, async ({ p, value }) => {
        const what = `HTTP ${p.technique}.${p.name}=${JSON.stringify(value)}`;
        const started = Date.now();
        const { status, json } = await render({ scene: 'builtin:cornell', technique: p.technique, size: SIZE,
            params: { [p.name]: value } });
        seconds.push([(Date.now() - started) / 1000, what]);
        if (status === 400 && json.error === 'invalid_request' && /limit|VPLs/.test(json.message)) return; // a server cap, stated
        assert.equal(status, 200, `${what}: ${JSON.stringify(json).slice(0, 300)}`);
        assert.equal(json.stats.params[p.name], value, `${what}: rendered with the value`);
        assertFiniteStats(json.stats, what);
        const png = decodePng(Buffer.from(json.image_base64, 'base64'));
        assert.deepEqual([png.width, png.height], SIZE, `${what}: image size`);
    });
    seconds.sort((a, b) => b[0] - a[0]);
    console.log(`# ${cases.length} extreme renders; slowest: ${seconds.slice(0, 3).map(([s, w]) => `${w} ${s.toFixed(1)} s`).join(', ')}`);
    await assertHealthy('after HTTP extremes');
});

check('HTTP: camera and light extremes are a clear 400 or a sane frame', async () => {
    const cam = { position: [0, 1, 3.9], target: [0, 1, 0] };
    const bad = [
        [{ camera: { ...cam, fov_deg: 0 } }, '/camera/fov_deg', /1\.\.170|>= 1/],
        [{ camera: { ...cam, fov_deg: 171 } }, '/camera/fov_deg', /170/],
        [{ camera: { ...cam, target: cam.position } }, '/camera/target', /must differ/],
        [{ camera: { ...cam, up: [0, 0, 0] } }, '/camera/up', /zero/],
        [{ camera: { ...cam, position: [NaN, 1, 3.9] } }, '/camera/position/0', /number/],
        [{ camera: { ...cam, position: [2e6, 1, 3.9] } }, '/camera/position/0', /1000000|1e\+?6/],
        [{ light: { direction: [0, 0, 0] } }, '/light/direction', /zero/],
        [{ light: { intensity: 1e7 } }, '/light/intensity', /1000000|1e\+?6/],
        [{ light: { intensity: -1 } }, '/light/intensity', />= 0/],
        [{ light: { cone_deg: 0 } }, '/light/cone_deg', /1\.\.85|>= 1/],
        [{ light: { color: [2, 0, 0] } }, '/light/color/0', /<= 1/],
        [{ light: { position: [null, 0, 0] } }, '/light/position/0', /number/],
    ];
    for (const [extra, where, text] of bad) {
        const what = `HTTP ${JSON.stringify(extra)}`;
        const { status, json } = await render({ scene: 'builtin:cornell', technique: 'rsm_gather', size: SIZE, ...extra });
        assert.equal(status, 400, `${what}: ${JSON.stringify(json)}`);
        assert.equal(json.where, where, `${what}: where (${json.message})`);
        assert.match(json.message, text, `${what}: message`);
    }
    const good = [
        { camera: { ...cam, fov_deg: 1 } }, { camera: { ...cam, fov_deg: 170 } },
        { camera: { ...cam, up: [0, 0, -1] } }, // up parallel to the view direction
        { camera: { position: [1e6, 1e6, 1e6], target: [0, 1, 0] } },
        { light: { intensity: 1e6 } }, { light: { intensity: 0 } }, { light: { cone_deg: 1 } },
        { light: { cone_deg: 85 } }, { light: { direction: [1e-3, 0, 0] } }, { light: { color: [0, 0, 0] } },
        { light: { position: [-1e6, 1e6, -1e6], direction: [1, -1, 1] } }, { light: { enabled: false } },
    ];
    for (const extra of good) {
        const what = `HTTP ${JSON.stringify(extra)}`;
        const { status, json } = await render({ scene: 'builtin:cornell', technique: 'rsm_gather', size: SIZE,
            params: { vpl_grid: 4 }, ...extra });
        assert.equal(status, 200, `${what}: ${JSON.stringify(json).slice(0, 300)}`);
        assertFiniteStats(json.stats, what);
        const png = decodePng(Buffer.from(json.image_base64, 'base64'));
        assert.deepEqual([png.width, png.height], SIZE, `${what}: image size`);
    }
    await assertHealthy('after HTTP camera and light');
});

// ---- WebSocket -----------------------------------------------------------------------------------------

async function open() {
    const client = await Client.open(server, { size: SIZE, adaptive: false, codecs: ['png'] });
    clients.add(client);
    await client.frame('first frame');
    return client;
}

/** The next error, or the next frame's stats (its binary consumed too) for which match(stats) holds. */
async function frameOrError(client, match, what, timeoutMs = 60000) {
    const deadline = Date.now() + timeoutMs;
    for (;;) {
        const m = await client.inbox.next((x) => x.type === 'error' || x.type === 'stats', `${what}: frame or error`,
            Math.max(1, deadline - Date.now()));
        if (m.type === 'error') return m;
        await client.inbox.next((x) => x.binary !== undefined, `${what}: binary frame`);
        if (match(m)) return m;
    }
}

check('WebSocket: every bad value of every parameter is an invalid_param naming it; the connection stays', async () => {
    const client = await open();
    const byTechnique = new Map();
    for (const p of allParams()) {
        if (!byTechnique.has(p.technique)) byTechnique.set(p.technique, []);
        byTechnique.get(p.technique).push(p);
    }
    let count = 0;
    for (const [technique, params] of byTechnique) {
        client.send({ type: 'technique', name: technique });
        for (const p of params) {
            for (const bad of badValues(p.schema)) {
                const what = `WS ${technique}.${p.name} ${bad.kind}`;
                const error = await client.expectError({ type: 'params', values: { [p.name]: bad.value } }, 'invalid_param', what);
                assert.equal(error.where, `/values/${p.name}`, `${what}: where`);
                assert.equal(error.request, 'params', `${what}: request`);
                assertParamMessage(error.message, p, bad, what);
                ++count;
            }
        }
        const error = await client.expectError({ type: 'params', values: { no_such_param: 1 } }, 'invalid_param');
        assert.match(error.message, new RegExp(`unknown parameter 'no_such_param' for technique '${technique}'`));
    }
    assert.ok(count > 300, `derived ${count} cases`);
    for (const text of ['{"type": "params", "values": {"exposure": 1e400}}', '{"type": "params", "values": {"exposure": NaN}}']) {
        const error = await client.expectError(text, 'invalid_json', text);
        assert.match(error.message, /not valid JSON: .+/, `${text}: says why`);
    }
    await client.roundTrip('after every bad value');
    await assertHealthy('after WebSocket bad values');
});

check('WebSocket: every parameter\'s far extreme renders a frame (sampled: one technique per parameter)', async () => {
    const client = await open();
    const byTechnique = new Map();
    for (const p of sampledParams()) {
        if (!byTechnique.has(p.technique)) byTechnique.set(p.technique, []);
        byTechnique.get(p.technique).push(p);
    }
    for (const [technique, params] of byTechnique) {
        client.send({ type: 'technique', name: technique });
        await client.frame(`WS technique ${technique}`, (s) => s.technique === technique);
        let previous = null;
        for (const p of params) {
            const value = farExtreme(p.schema);
            const values = { [p.name]: value };
            if (previous) values[previous.name] = previous.schema.default; // one extreme at a time
            const what = `WS ${technique}.${p.name}=${JSON.stringify(value)}`;
            client.send({ type: 'params', values });
            const reply = await frameOrError(client, (s) => s.params?.[p.name] === value, what);
            if (reply.type === 'error') {
                // Only a server cap may refuse an in-range value, and it must say so.
                assert.equal(reply.code, 'limit_exceeded', `${what}: ${reply.message}`);
                previous = null;
                continue;
            }
            assertFiniteStats(reply, what);
            previous = p;
        }
    }
    client.inbox.clear();
    client.send({ type: 'snapshot', codec: 'png' });
    const snap = await client.frame('snapshot', (s) => s.snapshot === true, 60000);
    assert.ok(snap.header.codec === 'png' || snap.header.codec === 2, `snapshot is PNG (${snap.header.codec})`);
    const png = decodePng(snap.payload);
    assert.deepEqual([png.width, png.height], snap.stats.size, 'snapshot decodes at its size');
    await assertHealthy('after WebSocket extremes');
});

check('WebSocket: camera, light and resize extremes get a clear error or a frame; the server survives', async () => {
    const client = await open();
    const cam = { type: 'camera', position: [0, 1, 3.9], target: [0, 1, 0] };
    const bad = [
        [{ ...cam, fov_deg: 0 }, '/fov_deg'], [{ ...cam, fov_deg: 171 }, '/fov_deg'],
        [{ ...cam, target: cam.position }, '/target'], [{ ...cam, up: [0, 0, 0] }, '/up'],
        [{ ...cam, position: [NaN, 1, 3.9] }, '/position/0'], [{ ...cam, position: [Infinity, 1, 3.9] }, '/position/0'],
        [{ type: 'light', direction: [0, 0, 0] }, '/direction'], [{ type: 'light', intensity: 1e7 }, '/intensity'],
        [{ type: 'light', intensity: -1 }, '/intensity'], [{ type: 'light', cone_deg: 90 }, '/cone_deg'],
        [{ type: 'light', color: [NaN, 0, 0] }, '/color/0'], [{ type: 'resize', size: [1, 1] }, '/size/0'],
        [{ type: 'resize', size: [16, 16], dpr: 0 }, '/dpr'], [{ type: 'resize', size: [1e9, 16] }, '/size/0'],
    ];
    for (const [msg, where] of bad) {
        const what = `WS ${JSON.stringify(msg)}`;
        const error = await client.expectError(msg, 'invalid_message', what);
        assert.equal(error.where, where, `${what}: where (${error.message})`);
        assert.ok(error.message.length > 10, `${what}: says what to fix: ${error.message}`);
    }
    for (const text of ['{"type": "camera", "position": [1e400, 1, 3.9], "target": [0, 1, 0]}', '{"type": "light", "intensity": 1e999}',
        '{"type": "light",', '\u0000']) {
        const error = await client.expectError(text, 'invalid_json', text);
        assert.match(error.message, /not valid JSON/, text);
    }
    await client.roundTrip('after bad camera and light');
    const good = [
        { ...cam, fov_deg: 1 }, { ...cam, fov_deg: 170 }, { ...cam, up: [0, 0, -1] },
        { type: 'camera', position: [1e6, 1e6, 1e6], target: [0, 1, 0] },
        { type: 'light', intensity: 1e6 }, { type: 'light', intensity: 0 }, { type: 'light', cone_deg: 1 },
        { type: 'light', cone_deg: 85, direction: [1e-4, -1e-4, 0] }, { type: 'light', color: [0, 0, 0], intensity: 3 },
        { type: 'resize', size: [16, 8192], dpr: 4 }, { type: 'resize', size: [17, 16], dpr: 0.25 },
    ];
    for (const msg of good) {
        const what = `WS ${JSON.stringify(msg)}`;
        client.send(msg);
        const reply = await frameOrError(client, () => true, what);
        assert.equal(reply.type, 'stats', `${what}: ${JSON.stringify(reply)}`);
        assertFiniteStats(reply, what);
        assert.ok(reply.size[0] >= 16 && reply.size[1] >= 16 && reply.size[0] <= 64 && reply.size[1] <= 64,
            `${what}: size within [16, max-size]: ${reply.size}`);
    }
    await client.roundTrip('after camera and light extremes');
    await assertHealthy('after WebSocket camera and light');
});
