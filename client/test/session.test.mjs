// Unit tests of the session-level logic: a new session restoring the lost one (restore.js),
// toasts that count repeats and the notices that stay (messages.js), "Reset parameters", typed
// numbers and the parameter order (params.js), framing the model and the orbit target
// (camera.js), and the server message types. Run: node --test client/test/
import { test } from 'node:test';
import assert from 'node:assert/strict';

import { lightRestoreMessages, restoreMessages, restorePlan, sessionSnapshot } from '../restore.js';
import { MessageStack, noticeFor } from '../messages.js';
import { checkTypedNumber, orderedProperties, rangeText, resetPlan } from '../params.js';
import { OrbitCamera, boundsSphere, fitDistance, withOrbitTarget } from '../camera.js';
import { SERVER_MESSAGE_TYPES, isKnownServerMessage, parseServerMessage, validateClientMessage } from '../protocol.js';
import { CLIENT_SCHEMAS } from '../schemas.js';
import { dot, length, normalize, sub } from '../vec.js';

const VPL_GRID = { type: 'integer', minimum: 1, maximum: 256, default: 16, 'x-unit': 'VPLs per side' };
const EXPOSURE = { type: 'number', minimum: -10, maximum: 10, default: 0, 'x-unit': 'EV' };
const WELCOME = {
    adaptive: true,
    scenes: ['builtin:cornell', 'builtin:sponza'],
    techniques: [{ name: 'none', params_schema: { properties: {} } },
        { name: 'rsm_gather', params_schema: { properties: { vpl_grid: VPL_GRID } } }],
    frame_params_schema: { properties: { exposure: EXPOSURE } },
    state: { scene: 'builtin:cornell', technique: 'none' },
};
const CAMERA = { position: [1, 2, 3], target: [0, 1, 0], up: [0, 1, 0], fov_deg: 50 };

function assertClose(actual, expected, eps, what) {
    assert.equal(actual.length, expected.length, `${what}: length`);
    actual.forEach((v, i) => assert.ok(Math.abs(v - expected[i]) <= eps, `${what}[${i}]: ${v} vs ${expected[i]}`));
}

// ---- restoring a lost session ---------------------------------------------------------------------

test('a new session gets the scene, technique, explicit parameters and camera of the lost one', () => {
    const saved = sessionSnapshot({
        scene: 'builtin:sponza', technique: 'rsm_gather', params: { vpl_grid: 6, exposure: 0.5, other: 1 },
        explicit: new Set(['vpl_grid', 'exposure']), camera: CAMERA, adaptive: false,
    });
    assert.deepEqual(saved.params, { vpl_grid: 6, exposure: 0.5 }, 'only the explicit values');
    const plan = restorePlan(saved, WELCOME);
    assert.deepEqual(plan, { scene: 'builtin:sponza', technique: 'rsm_gather', params: { vpl_grid: 6, exposure: 0.5 },
        lights: [], camera: CAMERA, adaptive: false, notes: [] });
    const messages = restoreMessages(plan);
    assert.deepEqual(messages.map((m) => m.type), ['technique', 'params', 'camera'], 'after the scene, in this order');
    for (const msg of messages) assert.equal(validateClientMessage(msg, CLIENT_SCHEMAS), null, JSON.stringify(msg));
    assert.equal(restorePlan(null, WELCOME), null);
});

test('what the new session already has, or cannot have, is not sent', () => {
    const same = restorePlan(sessionSnapshot({ scene: 'builtin:cornell', technique: 'none', camera: CAMERA,
        adaptive: true }), WELCOME);
    assert.deepEqual([same.scene, same.technique, same.params, same.adaptive], [null, null, {}, null]);
    assert.deepEqual(restoreMessages(same).map((m) => m.type), ['camera']);
    const upload = restorePlan(sessionSnapshot({ scene: 'upload:box.glb', technique: 'gone', camera: CAMERA,
        params: { vpl_grid: 999, exposure: 1 }, explicit: new Set(['vpl_grid', 'exposure']) }), WELCOME);
    assert.equal(upload.scene, null);
    assert.equal(upload.camera, null, 'the old camera belongs to the old scene');
    assert.deepEqual(upload.params, { exposure: 1 });
    assert.equal(upload.notes.length, 3);
    assert.match(upload.notes[0], /box\.glb was deleted with the old session/);
    assert.match(upload.notes[1], /technique gone/);
    assert.match(upload.notes[2], /vpl_grid = 999/);
    assert.match(restorePlan({ scene: 'file:old.glb' }, WELCOME).notes[0], /no longer offers file:old\.glb/);
});

const SPOT = { id: 'light0', name: 'key', type: 'spot', position: [0, 2, 0], direction: [0, -1, 0], intensity: 8,
    color: [1, 1, 1], range: 0, cone_deg: 40, inner_cone_deg: 30, enabled: true };
const FILL = { id: 'light1', name: 'fill', type: 'point', position: [1, 1, 1], intensity: 2, color: [1, 1, 1], range: 0,
    enabled: true };

test('the lights of the lost session are restored: edits, lights removed and lights added', () => {
    const added = { id: 'light2', name: 'sun', type: 'directional', direction: [0, -1, 0.2], intensity: 3,
        color: [1, 0.9, 0.8], enabled: true };
    const saved = [{ ...SPOT, intensity: 20, color: [1, 0, 0] }, added]; // the fill was removed, a sun added
    const messages = lightRestoreMessages(saved, [SPOT, FILL]);
    assert.deepEqual(messages.map((m) => m.type), ['light_remove', 'light', 'light_add']);
    assert.deepEqual(messages[0], { type: 'light_remove', id: 'light1' });
    assert.deepEqual(messages[1], { type: 'light', id: 'light0', light: { intensity: 20, color: [1, 0, 0] } },
        'only the fields that differ');
    assert.equal(messages[2].light.type, 'directional');
    assert.equal(messages[2].light.id, undefined, 'the server gives an added light its id');
    for (const msg of messages) assert.equal(validateClientMessage(msg, CLIENT_SCHEMAS), null, JSON.stringify(msg));
    assert.deepEqual(lightRestoreMessages([SPOT, FILL], [SPOT, FILL]), [], 'nothing changed, nothing sent');

    // Through the plan: on the same scene the light messages come before the camera.
    const welcome = { ...WELCOME, state: { ...WELCOME.state, lights: [SPOT, FILL] } };
    const plan = restorePlan(sessionSnapshot({ scene: 'builtin:cornell', technique: 'none', camera: CAMERA,
        lights: saved }), welcome);
    assert.deepEqual(restoreMessages(plan).map((m) => m.type), ['light_remove', 'light', 'light_add', 'camera']);
    // A server that lists no lights (protocol 1) cannot take them: said, not sent.
    const old = restorePlan(sessionSnapshot({ scene: 'builtin:cornell', technique: 'none', lights: saved }), WELCOME);
    assert.deepEqual(old.lights, []);
    assert.match(old.notes[0], /lights/);
    // A scene loaded first: its lights are diffed when its state arrives (main.js), not in the plan.
    const other = restorePlan(sessionSnapshot({ scene: 'builtin:sponza', technique: 'none', lights: saved }), welcome);
    assert.deepEqual(other.lights, []);
});

// ---- toasts and notices -----------------------------------------------------------------------------

test('identical messages are counted on one toast, which then lasts longer', () => {
    const m = new MessageStack({ max: 3, ttlMs: 1000 });
    const first = m.add('busy', 'error', 0);
    assert.equal(first.added, true);
    m.add('other', 'info', 10);
    const again = m.add('busy', 'error', 500);
    assert.equal(again.added, false);
    assert.equal(again.entry, first.entry);
    assert.equal(again.entry.count, 2);
    assert.deepEqual(m.entries.map((e) => e.text), ['other', 'busy'], 'the repeated one is the newest');
    assert.equal(m.add('busy', 'info', 600).added, true, 'another kind is another message');
    const fourth = m.add('fourth', 'error', 700);
    assert.deepEqual(fourth.dropped.map((e) => e.text), ['other'], 'beyond max the oldest goes');
    assert.deepEqual(m.expire(1200).map((e) => e.text), [], 'the repeat restarted its time');
    assert.deepEqual(m.expire(1600).map((e) => [e.text, e.kind]), [['busy', 'error'], ['busy', 'info']]);
    assert.deepEqual(m.entries.map((e) => e.text), ['fourth']);
    m.clear();
    assert.equal(m.entries.length, 0);
});

test('errors the page cannot recover from get a notice that says what to do', () => {
    const dead = noticeFor('unknown_view_token', { viewer: true });
    assert.match(dead.title, /view link has expired/);
    assert.match(dead.text, /Ask whoever shared it for a new link/);
    assert.equal(dead.action, 'own-session', 'not a retry of the dead token');
    assert.equal(noticeFor('session_ended', { viewer: true }).action, 'own-session');
    assert.equal(noticeFor('session_ended').action, 'connect');
    assert.equal(noticeFor('idle_timeout').action, 'connect');
    assert.equal(noticeFor('protocol_mismatch').action, 'reload');
    assert.equal(noticeFor('unauthorized').action, null);
    assert.match(noticeFor('unauthorized').text, /#token=/);
    assert.equal(noticeFor('busy'), null, 'the page retries by itself');
    assert.equal(noticeFor('invalid_param'), null);
});

// ---- parameters ---------------------------------------------------------------------------------------

test('a typed number outside the schema is refused with its range, not clamped', () => {
    assert.deepEqual(checkTypedNumber('vpl_grid', VPL_GRID, ' 32 '), { value: 32 });
    assert.deepEqual(checkTypedNumber('vpl_grid', VPL_GRID, '9999'),
        { error: 'vpl_grid: 9999 is out of range (range 1 to 256 VPLs per side); not sent.' });
    assert.match(checkTypedNumber('vpl_grid', VPL_GRID, '0').error, /out of range/);
    assert.match(checkTypedNumber('vpl_grid', VPL_GRID, '2.5').error, /2\.5 is not a whole number \(range 1 to 256/);
    assert.match(checkTypedNumber('vpl_grid', VPL_GRID, '12abc').error, /"12abc" is not a number/);
    assert.match(checkTypedNumber('vpl_grid', VPL_GRID, '').error, /is not a number/);
    assert.deepEqual(checkTypedNumber('exposure', EXPOSURE, '-2.5'), { value: -2.5 });
    assert.deepEqual(checkTypedNumber('exposure', EXPOSURE, '1e1'), { value: 10 });
    assert.match(checkTypedNumber('exposure', EXPOSURE, '10.01').error, /range -10 to 10 EV/);
    assert.deepEqual(checkTypedNumber('scale', { type: 'number' }, '1e9'), { value: 1e9 });
    assert.equal(rangeText({ type: 'number', minimum: 0, 'x-unit': 'm' }), 'at least 0 m');
    assert.equal(rangeText({}), '');
});

test('parameters keep the server\'s order, or x-order where the schema has it', () => {
    const schema = { properties: { vpl_grid: {}, kernel: {}, clamp_b: {} } };
    assert.deepEqual(orderedProperties(schema).map(([k]) => k), ['vpl_grid', 'kernel', 'clamp_b'], 'not alphabetical');
    const ranked = {
        properties: { a_late: { 'x-order': 3 }, b_first: { 'x-order': 1 }, c_none: {}, d_second: { 'x-order': 2 } },
    };
    assert.deepEqual(orderedProperties(ranked).map(([k]) => k), ['b_first', 'd_second', 'a_late', 'c_none']);
    assert.deepEqual(orderedProperties(undefined), []);
});

test('"Reset parameters" forgets explicit technique values and sends only frame values off their default', () => {
    const techniqueSchema = { properties: { vpl_grid: VPL_GRID } };
    const frameSchema = { properties: { exposure: EXPOSURE, tonemap: { type: 'string', default: 'filmic' } } };
    const plan = resetPlan({ techniqueSchema, frameSchema, params: { vpl_grid: 6, exposure: 1, tonemap: 'filmic' },
        explicit: new Set(['vpl_grid', 'exposure', 'tonemap']) });
    assert.deepEqual(plan, { technique: true, frame: { exposure: 0 }, techniqueDefaults: { vpl_grid: 16 } });
    const explicitAtDefault = resetPlan({ techniqueSchema, frameSchema, params: { vpl_grid: 16, exposure: 0 },
        explicit: new Set(['vpl_grid']) });
    assert.equal(explicitAtDefault.technique, true, 'an explicit value at its default still keeps the preset away');
    assert.deepEqual(explicitAtDefault.frame, {});
    const clean = resetPlan({ techniqueSchema, frameSchema, params: { vpl_grid: 16, exposure: 0, tonemap: 'filmic' } });
    assert.deepEqual([clean.technique, clean.frame], [false, {}], 'nothing to send');
});

// ---- camera framing --------------------------------------------------------------------------------------

test('framing the model fits its bounding sphere in both fields of view, from the current direction', () => {
    const bounds = { min: [-250, 0, -250], max: [250, 500, 250] };
    const sphere = boundsSphere(bounds);
    assertClose(sphere.centre, [0, 250, 0], 1e-9, 'centre');
    assert.ok(Math.abs(sphere.radius - Math.sqrt(3) * 250) < 1e-9);
    assert.equal(boundsSphere({ min: [1, 1, 1], max: [0, 0, 0] }), null);
    assert.equal(boundsSphere({ min: [0, 0], max: [1, 1, 1] }), null);
    assert.equal(boundsSphere(undefined), null);
    const cam = new OrbitCamera({ position: [0, 1, 3.9], target: [0, 1, 0], fov_deg: 40 });
    cam.orbit(80, 30);
    const direction = cam.forward;
    assert.ok(cam.frame(bounds, 16 / 9));
    assertClose(cam.target, [0, 250, 0], 1e-9, 'target at the centre');
    assertClose(cam.forward, direction, 1e-9, 'the view direction is kept');
    const tall = fitDistance(sphere.radius, 40, 0.5);
    assert.ok(tall > fitDistance(sphere.radius, 40, 2), 'a portrait view has to step back further');
    assert.ok(Math.abs(cam.distance - sphere.radius / Math.sin((20 * Math.PI) / 180)) < 1e-6, 'wide: the vertical field decides');
    assert.equal(cam.frame(null), false);
});

test('the orbit target goes to the model\'s depth along the view, which stays as it was', () => {
    // A glTF camera: look-at one unit ahead, 800 units in front of a 500-unit model.
    const bounds = { min: [-250, 0, -250], max: [250, 500, 250] };
    const gltf = { position: [0, 250, 800], target: [0, 250, 799], up: [0, 1, 0], fov_deg: 40 };
    const placed = withOrbitTarget(gltf, bounds);
    assertClose(placed.target, [0, 250, 0], 1e-6, 'target at the centre\'s depth');
    assert.deepEqual(placed.position, gltf.position);
    const before = normalize(sub(gltf.target, gltf.position));
    assert.ok(dot(normalize(sub(placed.target, placed.position)), before) > 1 - 1e-12, 'same direction');
    const oblique = withOrbitTarget({ position: [100, 250, 800], target: [100, 250, 799] }, bounds);
    assert.ok(Math.abs(length(sub(oblique.target, oblique.position)) - 800) < 1e-6, 'the depth, not the distance');
    const behind = { position: [0, 250, 800], target: [0, 250, 801] };
    assert.equal(withOrbitTarget(behind, bounds), behind, 'a model behind the eye: unchanged');
    assert.equal(withOrbitTarget(gltf, null), gltf);
});

// ---- server messages -----------------------------------------------------------------------------------

test('progress is a server message the client knows', () => {
    assert.ok(SERVER_MESSAGE_TYPES.includes('progress'));
    assert.ok(isKnownServerMessage('progress'));
    assert.ok(!isKnownServerMessage('teleport'));
    const msg = parseServerMessage('{"type":"progress","state":"skipped","step":"final","share":0,"eta_ms":0,'
        + '"reason":"over the refinement budget"}');
    assert.equal(msg.state, 'skipped');
});
