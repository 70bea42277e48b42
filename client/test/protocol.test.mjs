// Client protocol tests: the shared vectors in protocol/vectors, the builders, the frame header,
// the page URL options and the orbit camera math. Run: node --test client/test/
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';

import {
    ackMsg, buildFrameHeader, cameraMsg, CLIENT_MESSAGE_TYPES, CODEC_MIME, CODECS, helloMsg, lightAddMsg, lightMsg,
    lightRemoveMsg, paramsMsg, parseFrameHeader, parseServerMessage, pingMsg, PROTOCOL_VERSION, qualityMsg, resizeMsg,
    sceneMsg, snapshotMsg, techniqueMsg, validateClientMessage, validateJson, validateParamValues, validateServerMessage,
    viewportFor,
} from '../protocol.js';
import { OrbitCamera, cameraBasis, orbitFromPosition, positionFromOrbit } from '../camera.js';
import { backoffDelay, pageOptions, shareLink, streamUrl } from '../connection.js';
import { niceStep, widgetKind } from '../params.js';
import { CLIENT_SCHEMAS, CODEC_TABLE, MESSAGES, RENDER_REQUEST_SCHEMA, SERVER_SCHEMAS } from '../schemas.js';
import {
    loadCodecTable, loadMessageTable, loadProtocolSchemas, loadRenderRequestSchema, loadServerSchemas, loadVectors,
    PROTOCOL_DIR,
} from '../tools/protocol-files.mjs';

const schemas = loadProtocolSchemas();

function assertClose(actual, expected, eps, what) {
    assert.equal(actual.length, expected.length, `${what}: length`);
    actual.forEach((v, i) => assert.ok(Math.abs(v - expected[i]) <= eps, `${what}[${i}]: ${v} vs ${expected[i]}`));
}

test('every client message type has a schema and the client carries the current copy', () => {
    assert.deepEqual(Object.keys(schemas).sort(), [...CLIENT_MESSAGE_TYPES].sort());
    assert.deepEqual(CLIENT_SCHEMAS, schemas,
        'client/schemas.js differs from protocol/schema; run node client/tools/update-schemas.mjs');
    assert.deepEqual(RENDER_REQUEST_SCHEMA, loadRenderRequestSchema(),
        'client/schemas.js differs from protocol/http/render_request.json; run node client/tools/update-schemas.mjs');
});

test('the message table names every schema, and the client carries the current table and server schemas', () => {
    const table = loadMessageTable();
    delete table.$comment;
    assert.deepEqual(MESSAGES, table, 'client/schemas.js differs from protocol/messages.json; run node client/tools/update-schemas.mjs');
    assert.deepEqual(Object.keys(table.client).sort(), Object.keys(schemas).sort(), 'a client schema per client row');
    const serverSchemas = loadServerSchemas();
    assert.deepEqual(Object.keys(table.server).sort(), Object.keys(serverSchemas).sort(), 'a server schema per server row');
    assert.deepEqual(SERVER_SCHEMAS, serverSchemas,
        'client/schemas.js differs from protocol/schema/server; run node client/tools/update-schemas.mjs');
    for (const [type, row] of Object.entries(table.client)) {
        assert.ok(['connection', 'session'].includes(row.handler), `${type}: handler`);
        assert.equal(typeof row.viewers, 'boolean', `${type}: viewers`);
    }
    const viewerTypes = Object.keys(table.client).filter((t) => table.client[t].viewers).sort();
    assert.deepEqual(viewerTypes, ['ack', 'hello', 'ping', 'snapshot'], 'viewers only watch, acknowledge and snapshot');
});

test('the codecs come from protocol/codecs.json: the schemas\' lists and the frame header\'s table', () => {
    const codecs = loadCodecTable();
    assert.deepEqual(CODEC_TABLE, codecs, 'client/schemas.js differs from protocol/codecs.json; run node client/tools/update-schemas.mjs');
    const names = codecs.map((c) => c.name);
    assert.deepEqual(schemas.hello.properties.codecs.items.enum, names);
    assert.equal(schemas.hello.properties.codecs.maxItems, names.length);
    assert.deepEqual(schemas.snapshot.properties.codec.enum, codecs.filter((c) => c.lossless).map((c) => c.name));
    assert.deepEqual(loadRenderRequestSchema().properties.format.enum, names);
    for (const c of codecs) {
        assert.equal(CODECS[c.id], c.name);
        assert.equal(CODEC_MIME[c.name], c.mime);
    }
});

test('server messages are checked against their schemas', () => {
    assert.equal(validateServerMessage({ type: 'pong', t: 12.5 }), null);
    assert.equal(validateServerMessage({ type: 'error', code: 'busy', message: 'full', request: 'hello' }), null);
    assert.deepEqual(validateServerMessage({ type: 'pong', t: 'soon' })?.where, '/t');
    assert.ok(validateServerMessage({ type: 'progress', state: 'rendering', step: 'final', share: 0, eta_ms: 0, reason: '' }));
    assert.ok(validateServerMessage({ type: 'error', code: 'busy' }), 'an error says what is wrong');
    assert.equal(validateServerMessage({ type: 'from_the_future' }), null, 'unknown types are left to the caller');
});

// The vectors protocol v1 added; listed so that losing one fails a test instead of shrinking it.
const V1_VALID = ['hello_resume.json', 'hello_viewer.json', 'quality.json', 'resize_dpr.json', 'snapshot.json'];
const V1_INVALID = ['hello_in_flight_range.json', 'hello_unknown_codec.json', 'quality_not_bool.json',
    'resize_dpr_range.json', 'snapshot_lossy.json'];

test('valid vectors are accepted', () => {
    const vectors = loadVectors('valid');
    assert.ok(vectors.length >= Object.keys(schemas).length, 'expected a valid vector per message type');
    for (const name of V1_VALID) assert.ok(vectors.some((v) => v.name === name), `vectors/valid/${name} exists`);
    for (const { name, message } of vectors) {
        assert.equal(validateClientMessage(message, schemas), null, `vectors/valid/${name} rejected`);
    }
});

test('invalid vectors are rejected', () => {
    const vectors = loadVectors('invalid');
    assert.ok(vectors.length > 0);
    for (const name of V1_INVALID) assert.ok(vectors.some((v) => v.name === name), `vectors/invalid/${name} exists`);
    for (const { name, message } of vectors) {
        const problem = validateClientMessage(message, schemas);
        assert.ok(problem, `vectors/invalid/${name} accepted`);
        assert.ok(['invalid_message', 'unknown_type'].includes(problem.code), `${name}: code ${problem.code}`);
        assert.equal(typeof problem.where, 'string', `${name}: where`);
        assert.ok(problem.message.length > 0, `${name}: message`);
    }
});

test('rejections carry the server error code and a JSON pointer', () => {
    const check = (msg) => validateClientMessage(msg, schemas);
    assert.deepEqual(check({ type: 'teleport' }).code, 'unknown_type');
    assert.equal(check([1, 2, 3]).code, 'invalid_message');
    assert.equal(check(null).code, 'invalid_message');
    assert.equal(check('hello').code, 'invalid_message');
    assert.match(check({ position: [0, 0, 0] }).message, /missing required field 'type'/);
    assert.equal(check({ type: 7 }).where, '/type');
    assert.deepEqual(check({ type: 'resize', size: [8, 8] }),
        { code: 'invalid_message', where: '/size/0', message: 'must be >= 16, got 8' });
    assert.equal(check({ type: 'resize', size: [640, '480'] }).where, '/size/1');
    assert.equal(check({ type: 'resize', size: [640.5, 480] }).where, '/size/0');
    assert.equal(check({ type: 'resize', size: [640, 480, 1] }).where, '/size');
    assert.equal(check({ type: 'camera', position: [0, 1, 2], target: [0, 1, 0], fov_deg: 200 }).where, '/fov_deg');
    assert.equal(check({ type: 'camera', position: [0, NaN, 2], target: [0, 1, 0] }).where, '/position/1');
    assert.equal(check({ type: 'technique', name: 'rsm_gather', extra: 1 }).where, '/extra');
    assert.equal(check({ type: 'technique', name: '' }).where, '/name');
    assert.equal(check({ type: 'params', values: [1, 2] }).where, '/values');
    assert.equal(check({ type: 'params', values: { a: null } }).where, '/values/a');
    assert.equal(check({ type: 'params', values: { 'a/b': [] } }).where, '/values/a~1b');
    assert.equal(check({ type: 'ack', frame: -1 }).where, '/frame');
    assert.equal(check({ type: 'hello', protocol: 0, client: 'x'.repeat(201) }).where, '/client');
});

test('validateJson covers the rest of the subset', () => {
    assert.equal(validateJson('b', { enum: ['a', 'b'] }), null);
    assert.equal(validateJson('c', { enum: ['a', 'b'] }).message, 'must be one of ["a","b"], got "c"');
    assert.equal(validateJson(3, { type: ['string', 'integer'] }), null);
    assert.equal(validateJson(1, { exclusiveMinimum: 1 }).message, 'must be > 1, got 1');
    assert.equal(validateJson(2, { exclusiveMaximum: 2 }).message, 'must be < 2, got 2');
    assert.equal(validateJson({ a: 1 }, { additionalProperties: { type: 'string' } }).where, '/a');
    assert.equal(validateJson({ a: 1 }, { properties: { a: false } }).message, 'is not allowed here');
    assert.equal(validateJson({ k: [1, { x: 2 }] }, { const: { k: [1, { x: 2 }] } }), null);
});

test('parameter values are checked against the welcome schemas', () => {
    const technique = { type: 'object', properties: { vpl_grid: { type: 'integer', minimum: 1, maximum: 256 } } };
    const frame = { type: 'object', properties: { tonemap: { type: 'string', enum: ['filmic', 'linear'] } } };
    assert.equal(validateParamValues({ vpl_grid: 8, tonemap: 'linear' }, technique, frame), null);
    assert.deepEqual(validateParamValues({ vpl_grid: 100000 }, technique, frame),
        { code: 'invalid_param', where: '/values/vpl_grid', message: 'must be <= 256, got 100000' });
    assert.equal(validateParamValues({ nope: 1 }, technique, frame).message, "unknown parameter 'nope'");
    assert.equal(validateParamValues({ tonemap: 'aces' }, technique, frame).code, 'invalid_param');
});

// One example call per builder, keyed by message type; the table test below checks it covers
// every type of PROTOCOL.md.
const BUILT = {
    hello: [
        helloMsg(),
        helloMsg({ client: 'gi-web/test', codecs: ['webp', 'jpeg'], max_in_flight: 2, size: [800, 600], dpr: 2 }),
        helloMsg({ token: 's3cret', resume: 'r-1234', quality: 80, adaptive: false }),
        helloMsg({ view: 'v-abcd' }),
        helloMsg({ size: [390, 844], dpr: 1.742, frame_target_ms: 50 }),
    ],
    camera: [cameraMsg({ position: [0, 1, 3.9], target: [0, 1, 0], up: [0, 1, 0], fov_deg: 40 }),
        cameraMsg({ position: [1, 2, 3], target: [0, 0, 0] })],
    light: [lightMsg({ intensity: 8, enabled: false }), lightMsg({ direction: [0, -1, 0], cone_deg: 30 }),
        lightMsg({ type: 'point', position: [0.5, 1.5, 0.2], intensity: 3, color: [1, 0.8, 0.6], range: 4 }, 'light1'),
        lightMsg({ id: 'light0', name: 'key', type: 'spot', cone_deg: 40, inner_cone_deg: 30, enabled: true })],
    light_add: [lightAddMsg(), lightAddMsg({ type: 'directional', direction: [0.3, -0.9, 0.2], intensity: 2 }),
        lightAddMsg({ type: 'point', position: [0, 1.5, 0], intensity: 3, color: [1, 1, 1], range: 0 })],
    light_remove: [lightRemoveMsg('light1')],
    technique: [techniqueMsg('none')],
    params: [paramsMsg({ vpl_grid: 8, effects: 'auto', exposure: 0.5 })],
    resize: [resizeMsg(256, 256), resizeMsg(640, 480, 1.5)],
    scene: [sceneMsg('builtin:crease')],
    quality: [qualityMsg(true), qualityMsg(false), qualityMsg(true, 80), qualityMsg(false, 150)],
    snapshot: [snapshotMsg(), snapshotMsg('png'), snapshotMsg('webp')],
    ack: [ackMsg(0), ackMsg(123456)],
    ping: [pingMsg(), pingMsg(12.5)],
};

test('every builder produces messages that validate against their schema', () => {
    for (const [type, messages] of Object.entries(BUILT)) {
        for (const msg of messages) {
            assert.equal(msg.type, type, JSON.stringify(msg));
            assert.equal(validateJson(msg, schemas[type]), null, `${JSON.stringify(msg)} against schema/${type}.json`);
            assert.equal(validateClientMessage(msg, schemas), null, JSON.stringify(msg));
        }
    }
});

test('builders send only the fields given', () => {
    assert.equal(PROTOCOL_VERSION, 2);
    assert.deepEqual(helloMsg(), { type: 'hello', protocol: 2 });
    assert.deepEqual(helloMsg({ view: 'v-1', token: undefined, resume: undefined }), { type: 'hello', protocol: 2, view: 'v-1' });
    const fields = { client: 'c', token: 't', resume: 'r', view: 'v', codecs: ['webp'], quality: 90,
        max_in_flight: 3, adaptive: false, size: [320, 200], dpr: 1.25 };
    assert.deepEqual(helloMsg(fields), { type: 'hello', protocol: 2, ...fields });
    assert.deepEqual(helloMsg({ adaptive: false }).adaptive, false, 'false is a value, not a missing field');
    assert.equal('unknown' in helloMsg({ unknown: 1 }), false, 'fields outside the schema are not copied');
    assert.deepEqual(resizeMsg(640, 480), { type: 'resize', size: [640, 480] });
    assert.deepEqual(resizeMsg(640, 480, 2), { type: 'resize', size: [640, 480], dpr: 2 });
    assert.deepEqual(qualityMsg(false), { type: 'quality', adaptive: false });
    assert.deepEqual(snapshotMsg(), { type: 'snapshot' });
    assert.deepEqual(snapshotMsg('webp'), { type: 'snapshot', codec: 'webp' });
    assert.equal('up' in cameraMsg({ position: [1, 2, 3], target: [0, 0, 0] }), false);
});

test('light messages: nested with an id (protocol 2), flat without (protocol 1)', () => {
    assert.deepEqual(lightMsg({ intensity: 3 }), { type: 'light', intensity: 3 });
    assert.deepEqual(lightMsg({ intensity: 3, type: 'point' }), { type: 'light', intensity: 3 },
        'the flat form has no room for a light type');
    assert.deepEqual(lightMsg({ type: 'point', intensity: 3 }, 'light2'),
        { type: 'light', id: 'light2', light: { type: 'point', intensity: 3 } });
    assert.deepEqual(lightMsg({ id: 'light4', enabled: false }), { type: 'light', id: 'light4', light: { enabled: false } },
        'the light\'s own id names it');
    assert.deepEqual(lightMsg({ id: 'light4', enabled: false }, 'light5').id, 'light5', 'the id argument wins');
    const changes = { position: [1, 2, 3] };
    lightMsg(changes, 'light1').light.position[0] = 9;
    assert.deepEqual(changes.position, [1, 2, 3], 'the message holds a copy');
    assert.deepEqual(lightAddMsg(), { type: 'light_add' });
    assert.deepEqual(lightAddMsg({ type: 'point' }), { type: 'light_add', light: { type: 'point' } });
    assert.deepEqual(lightRemoveMsg('light3'), { type: 'light_remove', id: 'light3' });
    const check = (msg) => validateClientMessage(msg, schemas);
    assert.equal(check(lightMsg({ type: 'area' }, 'light1')).where, '/light/type');
    assert.equal(check(lightAddMsg({ type: 'spot', range: -1 })).where, '/light/range');
    assert.equal(check(lightRemoveMsg('')).where, '/id');
});

test('invalid builder input is caught by the schema before sending', () => {
    const check = (msg) => validateClientMessage(msg, schemas);
    assert.equal(check(helloMsg({ codecs: ['gif'] })).where, '/codecs/0');
    assert.equal(check(helloMsg({ max_in_flight: 5 })).where, '/max_in_flight');
    assert.equal(check(helloMsg({ dpr: 8 })).where, '/dpr');
    assert.equal(check(resizeMsg(640, 480, 0.1)).where, '/dpr');
    assert.equal(check(qualityMsg('yes')).where, '/adaptive');
    assert.equal(check(snapshotMsg('jpeg')).where, '/codec');
});

/** The message types of PROTOCOL.md's "Client -> server" table (first column). */
function documentedClientTypes() {
    const doc = readFileSync(path.join(PROTOCOL_DIR, 'PROTOCOL.md'), 'utf8');
    const section = doc.split(/^## /m).find((s) => s.startsWith('Client -> server'));
    assert.ok(section, 'PROTOCOL.md has a "Client -> server" section');
    return [...section.matchAll(/^\| `([a-z_]+)` \|/gm)].map((m) => m[1]);
}

test('every client message type in PROTOCOL.md has a builder, a schema and a valid vector', () => {
    const documented = documentedClientTypes();
    assert.ok(documented.length >= 11, `found ${documented.length} types in the table`);
    assert.deepEqual([...documented].sort(), [...CLIENT_MESSAGE_TYPES].sort(), 'CLIENT_MESSAGE_TYPES matches the table');
    const validVectorTypes = new Set(loadVectors('valid').map((v) => v.message.type));
    for (const type of documented) {
        assert.ok(BUILT[type]?.length > 0, `a builder for ${type}`);
        assert.ok(schemas[type], `protocol/schema/${type}.json`);
        assert.ok(CLIENT_SCHEMAS[type], `client/schemas.js has ${type}`);
        assert.ok(validVectorTypes.has(type), `a valid vector of type ${type}`);
    }
});

test('viewport announcements stay within the hello and resize schemas', () => {
    assert.deepEqual(viewportFor(800, 600, 1), { size: [800, 600], dpr: 1 });
    assert.deepEqual(viewportFor(800.4, 599.6, 2), { size: [800, 600], dpr: 2 });
    assert.deepEqual(viewportFor(0, 0, 1), { size: [16, 16], dpr: 1 });
    assert.deepEqual(viewportFor(20000, 100, 1), { size: [8192, 100], dpr: 1 });
    assert.deepEqual(viewportFor(300, 200, NaN), { size: [300, 200], dpr: 1 });
    assert.deepEqual(viewportFor(300, 200, 10), { size: [300, 200], dpr: 4 });
    assert.deepEqual(viewportFor(300, 200, 0.1), { size: [300, 200], dpr: 0.25 });
    for (const [w, h, dpr] of [[1, 1, 1], [1920, 1080, 3], [375, 667, 2.625], [17, 40000, 1], [NaN, 5, -1]]) {
        const { size, dpr: d } = viewportFor(w, h, dpr);
        assert.equal(validateClientMessage(resizeMsg(size[0], size[1], d), schemas), null, `${w}x${h}@${dpr}`);
        assert.equal(validateClientMessage(helloMsg({ size, dpr: d }), schemas), null, `hello ${w}x${h}@${dpr}`);
    }
});

function frameWith(header, payload = [0xff, 0xd8, 0xff, 0xd9]) {
    const bytes = new Uint8Array(16 + payload.length);
    bytes.set(new Uint8Array(header));
    bytes.set(payload, 16);
    return bytes.buffer;
}

test('parseFrameHeader reads a good header', () => {
    const bytes = new Uint8Array(frameWith(new ArrayBuffer(16)));
    bytes.set([0x47, 0x49, 0x46, 0x52, 0x2a, 0x01, 0x00, 0x00, 0x00, 0x02, 0x80, 0x01, 0x01, 0, 0, 0]);
    assert.deepEqual(parseFrameHeader(bytes.buffer),
        { frame: 298, width: 512, height: 384, codec: 'jpeg', payloadOffset: 16 });
    const png = frameWith(buildFrameHeader({ frame: 0xfffffffe, width: 65535, height: 16, codec: 'png' }));
    assert.deepEqual(parseFrameHeader(png), { frame: 0xfffffffe, width: 65535, height: 16, codec: 'png', payloadOffset: 16 });
    const webp = new Uint8Array(frameWith(buildFrameHeader({ frame: 7, width: 320, height: 200, codec: 'webp' })));
    assert.equal(webp[12], 3, 'WebP is codec 3 on the wire');
    assert.deepEqual(parseFrameHeader(webp.buffer), { frame: 7, width: 320, height: 200, codec: 'webp', payloadOffset: 16 });
    // A typed-array view into a larger buffer (node's ws hands out Buffers like that).
    const padded = new Uint8Array(40);
    padded.set(new Uint8Array(png), 8);
    assert.equal(parseFrameHeader(padded.subarray(8)).frame, 0xfffffffe);
});

test('parseFrameHeader rejects bad frames', () => {
    const good = buildFrameHeader({ frame: 1, width: 64, height: 64 });
    const badMagic = new Uint8Array(frameWith(good));
    badMagic[0] = 0x4a;
    assert.throws(() => parseFrameHeader(badMagic.buffer), /magic/);
    assert.throws(() => parseFrameHeader(new ArrayBuffer(15)), /too short/);
    assert.throws(() => parseFrameHeader(new ArrayBuffer(0)), /too short/);
    const badCodec = new Uint8Array(frameWith(good));
    for (const id of [0, 4, 255]) {
        badCodec[12] = id;
        assert.throws(() => parseFrameHeader(badCodec.buffer), /codec/, `codec ${id}`);
    }
    assert.throws(() => buildFrameHeader({ frame: 1, width: 1, height: 1, codec: 'gif' }), /codec/);
    const zeroSize = new Uint8Array(frameWith(good));
    zeroSize[8] = zeroSize[9] = 0;
    assert.throws(() => parseFrameHeader(zeroSize.buffer), /size/);
    assert.throws(() => parseFrameHeader('GIFR'), TypeError);
});

test('frame codecs map 1/2/3 to JPEG/PNG/WebP with their MIME types', () => {
    assert.deepEqual({ ...CODECS }, { 1: 'jpeg', 2: 'png', 3: 'webp' });
    assert.deepEqual({ ...CODEC_MIME }, { jpeg: 'image/jpeg', png: 'image/png', webp: 'image/webp' });
    for (const codec of Object.values(CODECS)) {
        const header = buildFrameHeader({ frame: 1, width: 16, height: 16, codec });
        assert.equal(parseFrameHeader(frameWith(header)).codec, codec, `${codec} round trip`);
    }
});

test('parseServerMessage keeps JSON objects with a type only', () => {
    assert.deepEqual(parseServerMessage('{"type":"pong","t":1}'), { type: 'pong', t: 1 });
    for (const text of ['{not json', '[1]', '{"t":1}', 'null', '{"type":3}']) {
        assert.equal(parseServerMessage(text), null, text);
    }
});

test('orbit math round-trips position -> yaw/pitch/distance -> position', () => {
    const target = [0.3, 1, -0.2];
    for (const position of [[0, 1, 3.9], [2, 3, -1], [-1.5, -0.5, 0.25], [0.01, 5, 0.02], [7, 1, 0]]) {
        const orbit = orbitFromPosition(position, target);
        assertClose(positionFromOrbit(orbit, target), position, 1e-9, `round trip of ${position}`);
    }
    const welcome = orbitFromPosition([0, 1, 3.9], [0, 1, 0]);
    assertClose([welcome.yaw, welcome.pitch, welcome.distance], [0, 0, 3.9], 1e-12, 'welcome camera');
    for (const [yaw, pitch, distance] of [[0.5, 0.2, 2], [-2.5, -1.2, 10], [3, 1.5, 0.5]]) {
        const o = orbitFromPosition(positionFromOrbit({ yaw, pitch, distance }, target), target);
        assertClose([o.yaw, o.pitch, o.distance], [yaw, pitch, distance], 1e-9, `orbit ${yaw},${pitch},${distance}`);
    }
});

test('camera basis is orthonormal and perpendicular to the view direction', () => {
    for (const [yaw, pitch] of [[0, 0], [1, 0.4], [-2, -1.3]]) {
        const { right, up } = cameraBasis(yaw, pitch);
        const forward = positionFromOrbit({ yaw, pitch, distance: -1 }, [0, 0, 0]);
        const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        assertClose([dot(right, right), dot(up, up), dot(right, up), dot(right, forward), dot(up, forward)],
            [1, 1, 0, 0, 0], 1e-12, `basis at ${yaw},${pitch}`);
    }
});

test('OrbitCamera orbits, zooms, pans and resets', () => {
    const home = { position: [0, 1, 3.9], target: [0, 1, 0], up: [0, 1, 0], fov_deg: 40 };
    const cam = new OrbitCamera(home);
    assert.deepEqual(cam.toCamera(), home);
    cam.orbit(100, 0);
    assert.ok(cam.position[0] < 0, 'dragging right moves the eye to its left');
    cam.orbit(0, 100000);
    assert.ok(cam.pitch < Math.PI / 2, 'pitch stays off the pole');
    const before = cam.distance;
    cam.zoom(100);
    assert.ok(cam.distance > before, 'positive wheel moves away');
    cam.reset();
    assertClose(cam.position, home.position, 1e-12, 'reset');
    cam.pan(100, 0, 500);
    assert.ok(cam.target[0] < 0 && Math.abs(cam.target[1] - 1) < 1e-12, 'panning right moves the target left');
    assertClose(cam.position, [cam.target[0], 1, 3.9], 1e-12, 'pan keeps the view direction');
    assert.equal(validateClientMessage(cameraMsg(cam.toCamera()), schemas), null);
});

test('reconnect backoff doubles from 0.5 s up to 8 s', () => {
    assert.deepEqual([0, 1, 2, 3, 4, 5, 9].map(backoffDelay), [500, 1000, 2000, 4000, 8000, 8000, 8000]);
    assert.equal(streamUrl({ protocol: 'https:', host: 'example.org:8443' }), 'wss://example.org:8443/ws');
    assert.equal(streamUrl({ protocol: 'http:', host: '127.0.0.1:8080' }), 'ws://127.0.0.1:8080/ws');
});

test('page URL options: view and token from the hash or the query', () => {
    const at = (url) => pageOptions(new URL(url));
    assert.deepEqual(at('http://h:8080/'), { view: undefined, token: undefined });
    assert.deepEqual(at('http://h:8080/#view=v-123'), { view: 'v-123', token: undefined });
    assert.deepEqual(at('http://h:8080/#token=s3cret'), { view: undefined, token: 's3cret' });
    assert.deepEqual(at('http://h:8080/?token=q'), { view: undefined, token: 'q' });
    assert.deepEqual(at('http://h:8080/?token=q#view=v-1&token=h'), { view: 'v-1', token: 'h' }, 'the hash wins');
    assert.deepEqual(at('http://h:8080/#view='), { view: undefined, token: undefined }, 'empty means absent');
});

test('share links carry the view token and keep the query, not the hash', () => {
    assert.equal(shareLink(new URL('http://h:8080/'), 'v-abc'), 'http://h:8080/#view=v-abc');
    assert.equal(shareLink(new URL('https://h/app/index.html?token=t#token=x'), 'v-1'),
        'https://h/app/index.html?token=t#view=v-1');
    assert.equal(pageOptions(new URL(shareLink(new URL('http://h/'), 'v-a+b/c'))).view, 'v-a+b/c', 'round trip');
});

test('parameter widgets follow the schema', () => {
    assert.equal(widgetKind({ type: 'integer', minimum: 1, maximum: 256 }), 'integer');
    assert.equal(widgetKind({ type: 'string', enum: ['filmic', 'linear'] }), 'enum');
    assert.equal(widgetKind({ type: 'boolean' }), 'boolean');
    assert.equal(niceStep(-10, 10), 0.1);
    assert.equal(niceStep(0, 1), 0.005);
    assert.equal(niceStep(0, 10000), 50);
    assert.equal(niceStep(1, 1), 0.01, 'an empty range still gets a step');
});
