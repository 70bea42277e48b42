// Unit tests of the client's pure modules: camera modes and keys, the light gizmo's math, the
// light list (selection, new lights, what a frame rendered), the parameter controls, stats and latency, the accuracy request, error texts, upload names, and
// that the vendored libraries the import map names are in place. Run: node --test client/test/
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { DRAG_TOOLS, OrbitCamera, gestureFor, keyMotion } from '../camera.js';
import { notShownLines, notShownSummary } from '../scene-notes.js';
import {
    aimAt, aimLight, containRect, dragToWorld, gizmoAnchor, gizmoHandles, gizmoKinds, gizmoLabels, moveLight, projectPoint,
    safeDirection, viewBasis,
} from '../light.js';
import {
    LIGHT_TYPES, applyLightChanges, formatEv, intensityUnit, lightLabel, lightStatuses, lightType, lightingLines, lightsOfState,
    newLightFor, pickSelection, requestLight,
} from '../lights.js';
import { controlSpec, paramHelp, paramLabel, presetChanges, schemaDefaults } from '../params.js';
import { InputWatch } from '../progress.js';
import { ChartSchedule, LatencyTracker, PassHistory, RateCounter, RoundTrip, formatBytes, networkMs, passMs, stackSeries, trianglesText } from '../stats.js';
import {
    DEFAULT_COMPARE, buildCompareRequest, canCompare, compareSettings, compareSize, diffImage, formatCompare, percent,
    referenceLabel, validateCompareRequest, viewKey,
} from '../accuracy.js';
import { describeError, describeHttpError } from '../messages.js';
import { uploadName, uploadType } from '../upload.js';
import { cameraMsg, lightAddMsg, lightMsg, validateClientMessage, validateParamValues } from '../protocol.js';
import { CLIENT_SCHEMAS, RENDER_REQUEST_SCHEMA } from '../schemas.js';
import { dot, length, normalize } from '../vec.js';
import { VENDOR_FILES, checkVendor } from '../tools/vendor.mjs';

const CLIENT_DIR = fileURLToPath(new URL('../', import.meta.url));
const HOME = { position: [0, 1, 3.9], target: [0, 1, 0], up: [0, 1, 0], fov_deg: 40 };

function assertClose(actual, expected, eps, what) {
    assert.equal(actual.length, expected.length, `${what}: length`);
    actual.forEach((v, i) => assert.ok(Math.abs(v - expected[i]) <= eps, `${what}[${i}]: ${v} vs ${expected[i]}`));
}

// ---- camera -------------------------------------------------------------------------------------

test('fly look keeps the eye and turns the view the way the drag goes', () => {
    const cam = new OrbitCamera(HOME);
    const eye = cam.position;
    cam.look(100, 0);
    assertClose(cam.position, eye, 1e-9, 'eye stays');
    assert.ok(cam.forward[0] > 0.1, 'dragging right looks right (+X from the home view)');
    cam.look(0, -100);
    assert.ok(cam.forward[1] > 0.1, 'dragging up looks up');
    assertClose(cam.position, eye, 1e-9, 'eye still stays');
    assert.ok(Math.abs(length(cam.forward) - 1) < 1e-12);
});

test('fly move goes along the view, sideways and up, and zoom-drag changes the distance', () => {
    const cam = new OrbitCamera(HOME);
    cam.move(1, 0, 0);
    assertClose(cam.position, [0, 1, 2.9], 1e-9, 'forward one metre');
    cam.move(0, 2, 0);
    assertClose(cam.position, [2, 1, 2.9], 1e-9, 'right two metres');
    cam.move(0, 0, -0.5);
    assertClose(cam.position, [2, 0.5, 2.9], 1e-9, 'down half a metre');
    assertClose(cam.forward, [0, 0, -1], 1e-9, 'moving does not turn');
    const before = cam.distance;
    cam.zoomDrag(50);
    assert.ok(cam.distance > before, 'dragging down moves away');
    cam.setFov(500);
    assert.equal(cam.fovDeg, 170, 'the field of view stays within the camera schema');
    assert.equal(validateClientMessage(cameraMsg(cam.toCamera()), CLIENT_SCHEMAS), null);
    assert.ok(Math.abs(cam.sceneScale - 3.9) < 1e-9, 'scene scale is the home distance');
});

test('drag gestures: modifiers first, then the tool', () => {
    assert.equal(gestureFor({}, 'orbit'), 'orbit');
    assert.equal(gestureFor({}, 'fly'), 'look');
    assert.equal(gestureFor({}, 'zoom'), 'zoom');
    assert.equal(gestureFor({ shiftKey: true }, 'fly'), 'pan');
    assert.equal(gestureFor({ button: 2 }, 'orbit'), 'pan');
    assert.equal(gestureFor({ ctrlKey: true }, 'orbit'), 'light-aim');
    assert.equal(gestureFor({ metaKey: true, shiftKey: true }, 'orbit'), 'light-move');
    assert.equal(gestureFor({}, 'light-move'), 'light-move');
    assert.equal(gestureFor({}, 'nonsense'), 'orbit');
    assert.deepEqual([...DRAG_TOOLS], ['orbit', 'pan', 'zoom', 'fly', 'light-aim', 'light-move']);
});

test('keys: WASD/EQ move, arrows orbit or look, +/- zoom, Shift is faster', () => {
    const keys = (...codes) => new Set(codes);
    assert.deepEqual(keyMotion(keys('KeyW'), 'orbit', 0.5, 2).move, [1, 0, 0]);
    assert.deepEqual(keyMotion(keys('KeyA', 'KeyQ'), 'fly', 1, 1).move, [0, -1, -1]);
    assert.deepEqual(keyMotion(keys('KeyW'), 'fly', 1, 1, true).move, [3, 0, 0]);
    assert.deepEqual(keyMotion(keys('KeyW', 'KeyS'), 'fly', 1, 1).move, [0, 0, 0], 'opposite keys cancel');
    const orbitLeft = keyMotion(keys('ArrowLeft'), 'orbit', 0.1, 1).turn;
    assert.ok(orbitLeft[0] > 0, 'orbit: ArrowLeft moves the eye left (like dragging right)');
    const lookLeft = keyMotion(keys('ArrowLeft'), 'fly', 0.1, 1).turn;
    assert.ok(lookLeft[0] < 0, 'fly: ArrowLeft looks left');
    assert.ok(keyMotion(keys('ArrowUp'), 'fly', 0.1, 1).turn[1] < 0, 'fly: ArrowUp looks up');
    assert.ok(keyMotion(keys('Equal'), 'orbit', 0.1, 1).zoom < 0, '+ zooms in');
    assert.ok(keyMotion(keys('Minus'), 'orbit', 0.1, 1).zoom > 0, '- zooms out');
    // Through the camera: a held ArrowLeft in orbit mode moves the eye to -X.
    const cam = new OrbitCamera(HOME);
    cam.orbit(...keyMotion(keys('ArrowLeft'), 'orbit', 0.2, 1).turn);
    assert.ok(cam.position[0] < 0);
});

// ---- light --------------------------------------------------------------------------------------

test('projection: the target is in the middle, points left/right/up land where expected', () => {
    const p = projectPoint(HOME, 1, [0, 1, 0]);
    assertClose([p.x, p.y, p.depth], [0, 0, 3.9], 1e-12, 'target');
    const t = Math.tan(20 * Math.PI / 180);
    const edge = projectPoint(HOME, 1, [0, 1 + 3.9 * t, 0]);
    assert.ok(Math.abs(edge.y - 1) < 1e-9, 'a point at the top of the vertical fov is at y = 1');
    assert.ok(projectPoint(HOME, 2, [1, 1, 0]).x > 0, '+X is right of the centre');
    assert.equal(projectPoint(HOME, 1, [0, 1, 5]), null, 'behind the eye');
    const { forward, right, up } = viewBasis(HOME);
    assertClose([dot(forward, right), dot(forward, up), dot(right, up)], [0, 0, 0], 1e-12, 'orthogonal basis');
});

test('a dragged light stays under the cursor', () => {
    const light = { position: [0.3, 1.5, 0.5], direction: [0, -1, 0] };
    const before = projectPoint(HOME, 1, light.position);
    const moved = moveLight(light.position, HOME, 40, -20, 400);
    const after = projectPoint(HOME, 1, moved);
    // NDC spans 2 over 400 pixels: 40 px right is +0.2, 20 px up is +0.1.
    assert.ok(Math.abs(after.x - before.x - 0.2) < 1e-4, `x moved ${after.x - before.x}`);
    assert.ok(Math.abs(after.y - before.y - 0.1) < 1e-4, `y moved ${after.y - before.y}`);
    assert.ok(Math.abs(after.depth - before.depth) < 1e-4, 'the depth is kept');
    const delta = dragToWorld(HOME, 3.9, 0, 100, 400);
    assert.ok(delta[1] < 0 && Math.abs(delta[0]) < 1e-12, 'dragging down moves down');
});

test('aiming turns the beam with the drag and keeps it a valid light direction', () => {
    const light = { position: [0, 1.95, 0], direction: [0, -1, 0] };
    const right = aimLight(light, HOME, 50, 0, 400);
    assert.ok(right[0] > 0.1, 'dragging right turns a beam pointing down towards the camera\'s right');
    const tilted = aimLight({ position: [0, 1, 0], direction: [0, 0, -1] }, HOME, 0, 50, 400);
    assert.ok(tilted[1] < -0.1, 'dragging down tilts a beam pointing away from the camera down');
    const toward = aimLight({ position: [0, 1, 0], direction: [0, 0, 1] }, HOME, -50, 0, 400);
    assert.ok(toward[0] < -0.1, 'a beam pointing at the camera turns too');
    for (const d of [right, tilted, toward, aimLight(light, HOME, 3000, -7000, 400)]) {
        assert.ok(Math.abs(length(d) - 1) < 1e-4, `unit length ${d}`);
        assert.equal(validateClientMessage(lightMsg({ direction: d }), CLIENT_SCHEMAS), null, `valid ${d}`);
    }
    assert.deepEqual(safeDirection([0, 0, 0]), [0, -1, 0], 'a zero vector falls back to straight down');
    assertClose(aimAt([0, 2, 0], [1, 1, 0]), normalize([1, -1, 0]).map((v) => Math.round(v * 1e5) / 1e5), 1e-12, 'aim at');
});

test('gizmo handles and the contained frame rectangle', () => {
    const handles = gizmoHandles(HOME, 1, { position: [0, 1.95, 0], direction: [0, -1, 0] });
    assert.ok(handles.origin.y > handles.tip.y, 'a light pointing down has its aim handle below it');
    assert.ok(Math.abs(handles.origin.x) < 1e-12 && Math.abs(handles.tip.x) < 1e-12);
    assert.deepEqual(containRect(800, 400, 100, 100), { left: 200, top: 0, width: 400, height: 400 });
    assert.deepEqual(containRect(400, 800, 200, 100), { left: 0, top: 300, width: 400, height: 200 });
    assert.deepEqual(containRect(300, 200, 0, 0), { left: 0, top: 0, width: 300, height: 200 });
});

test('the gizmo has the handles the light type has, labelled by type', () => {
    assert.deepEqual(gizmoKinds({ type: 'spot' }), { move: true, aim: true });
    assert.deepEqual(gizmoKinds({}), { move: true, aim: true }, 'protocol 1\'s light is a spot');
    assert.deepEqual(gizmoKinds({ type: 'point' }), { move: true, aim: false });
    assert.deepEqual(gizmoKinds({ type: 'directional' }), { move: false, aim: true });
    assert.equal(gizmoLabels({ type: 'point' }).move, 'point light: drag to move it');
    assert.match(gizmoLabels({ type: 'directional' }).aim, /^directional light: drag/);
    assert.match(gizmoLabels({ type: 'spot' }).aim, /^spotlight aim/);
    const point = gizmoHandles(HOME, 1, { type: 'point', position: [0, 1.5, 0], direction: [0, -1, 0] });
    assert.ok(point.origin && point.tip === null, 'a point light has no aim handle');
    const sun = { type: 'directional', direction: [0, -1, 0] };
    assert.deepEqual(gizmoAnchor(sun, HOME), HOME.target, 'without a position the orbit target anchors it');
    const sunHandles = gizmoHandles(HOME, 1, sun);
    assert.ok(sunHandles.origin === null && sunHandles.tip, 'a directional light only has the aim handle');
    assert.ok(sunHandles.anchorPoint.y > sunHandles.tip.y, 'shining down: the handle is below the anchor');
    assert.deepEqual(gizmoAnchor({ ...sun, position: [1, 2, 3] }, HOME), [1, 2, 3], 'the server\'s position anchors it');
    const turned = aimLight(sun, HOME, 50, 0, 400);
    assert.ok(turned[0] > 0.1, `aiming a directional light without a position works (${turned})`);
});

// ---- lights -------------------------------------------------------------------------------------

const KEY = { id: 'light0', name: 'key', type: 'spot', position: [0, 1.95, 0], direction: [0, -1, 0], intensity: 6,
    color: [1, 1, 1], range: 0, cone_deg: 60, inner_cone_deg: 48, enabled: true };

test('a state\'s lights: protocol 2\'s list or protocol 1\'s one light', () => {
    assert.deepEqual(lightsOfState({ lights: [KEY], light: KEY }), [KEY]);
    assert.notEqual(lightsOfState({ lights: [KEY] })[0], KEY, 'a copy');
    const v1 = { position: [0, 1, 0], direction: [0, -1, 0], intensity: 6, color: [1, 1, 1], cone_deg: 60, enabled: true };
    assert.deepEqual(lightsOfState({ light: v1 }), [v1]);
    assert.deepEqual(lightsOfState({ lights: [], light: null }), []);
    assert.equal(lightsOfState({ camera: HOME }), null, 'a state without lights leaves them alone');
    assert.equal(lightType(v1), 'spot');
    assert.equal(lightType({ type: 'point' }), 'point');
    assert.equal(lightLabel(KEY), 'key');
    assert.equal(lightLabel({ id: 'light3', name: '' }), 'light3');
    assert.equal(intensityUnit({ type: 'directional' }), 'lux');
    assert.equal(intensityUnit(KEY), 'cd');
    assert.deepEqual([...LIGHT_TYPES], ['spot', 'point', 'directional']);
});

test('the selection follows an added light, keeps a light still there, else takes the first', () => {
    const a = { id: 'light0' };
    const b = { id: 'light1' };
    const c = { id: 'light2' };
    assert.equal(pickSelection(['light0', 'light1'], [a, b, c], 'light0', { expectAdded: true }), 'light2');
    assert.equal(pickSelection(['light0', 'light1'], [a, b, c], 'light0'), 'light0', 'a list from elsewhere keeps it');
    assert.equal(pickSelection(['light0', 'light1'], [a], 'light1'), 'light0', 'the removed light\'s first neighbour');
    assert.equal(pickSelection(['light0'], [], 'light0'), null);
    assert.equal(pickSelection([], [{}], null), null, 'protocol 1\'s unnamed light');
    assert.equal(pickSelection(['light0'], [a], 'light0', { expectAdded: true }), 'light0', 'nothing new: kept');
});

test('local light edits follow the server\'s cone rule', () => {
    const narrower = applyLightChanges(KEY, { cone_deg: 30 });
    assert.equal(narrower.cone_deg, 30);
    assert.ok(Math.abs(narrower.inner_cone_deg - 24) < 1e-9, 'the inner cone keeps its proportion');
    assert.equal(applyLightChanges(KEY, { cone_deg: 30, inner_cone_deg: 10 }).inner_cone_deg, 10);
    assert.deepEqual(applyLightChanges(KEY, { position: [1, 1, 1] }).position, [1, 1, 1]);
    assert.deepEqual(KEY.position, [0, 1.95, 0], 'the light given is left as it was');
});

test('new lights are placed from the view and light the target about as the selected light does', () => {
    const at = (light) => light.intensity / Math.hypot(...light.position.map((v, i) => v - HOME.target[i])) ** 2;
    const key = 6 / 0.95 ** 2;
    const point = newLightFor('point', HOME, KEY);
    assert.equal(point.type, 'point');
    assert.ok(point.position[1] > HOME.target[1] && point.position[1] < HOME.target[1] + 1, `above the target (${point.position})`);
    assert.ok(Math.abs(at(point) - key) / key < 0.01, 'the same illuminance at the target');
    const sun = newLightFor('directional', HOME, KEY);
    assert.ok(sun.direction[2] < -0.8 && sun.direction[1] < -0.2 && Math.abs(sun.direction[0]) < 1e-9,
        `shines along the view, somewhat down (${sun.direction})`);
    const sunHandles = gizmoHandles(HOME, 1, sun);
    assert.ok(Math.hypot(sunHandles.tip.x - sunHandles.anchorPoint.x, sunHandles.tip.y - sunHandles.anchorPoint.y) > 0.05,
        'its aim handle is apart from its anchor');
    assert.ok(Math.abs(sun.intensity - key) / key < 0.01, 'lux at the target');
    const spot = newLightFor('spot', HOME, KEY);
    const aim = normalize(spot.position.map((v, i) => HOME.target[i] - v));
    assertClose(spot.direction, aim, 1e-4, 'the spot aims at the target');
    assert.ok(spot.position[2] > HOME.target[2] && spot.position[2] < HOME.position[2], 'between target and eye');
    assert.ok(newLightFor('point', HOME, null).intensity > 0, 'without a light to match there is still light');
    for (const type of LIGHT_TYPES) {
        for (const reference of [KEY, null, { type: 'directional', direction: [0, -1, 0], intensity: 3 }]) {
            const msg = lightAddMsg(newLightFor(type, HOME, reference));
            assert.equal(validateClientMessage(msg, CLIENT_SCHEMAS), null, JSON.stringify(msg));
        }
    }
});

test('what a frame says about each light: rendered, or skipped and why', () => {
    const lights = [KEY, { id: 'light1', name: 'fill', type: 'point' }, { id: 'light2', name: 'sun', type: 'directional' }];
    const lighting = {
        source: 'scene', note: 'the scene\'s 3 lights',
        rendered: [{ id: 'light0', name: 'key', type: 'spot', views: 1 }],
        skipped: ["light 'fill' (light1): disabled", "light 'sun' (light2): over max_lights (1): raise it to render this light"],
        views: 1, shadow_side: 1024, rsm_side: 256,
    };
    assert.deepEqual(lightStatuses(lights, lighting), [
        { id: 'light0', rendered: true, reason: null, views: 1 },
        { id: 'light1', rendered: false, reason: 'disabled', views: 0 },
        { id: 'light2', rendered: false, reason: 'over max_lights (1): raise it to render this light', views: 0 },
    ]);
    assert.deepEqual(lightStatuses(lights, null).map((s) => s.rendered), [null, null, null], 'no stats: unknown');
    assert.deepEqual(lightStatuses([...lights, { id: 'light3', type: 'point' }], lighting)[3],
        { id: 'light3', rendered: null, reason: null, views: null }, 'a frame from before the light was added');
    const lines = lightingLines({ ...lighting, warning: 'none of the lights is rendered' });
    assert.deepEqual(lines.map((l) => l.kind), ['note', 'warning', 'skipped', 'skipped']);
    assert.equal(lines[0].text, 'Lights from the scene: the scene\'s 3 lights');
    assert.match(lines[2].text, /^not rendered: light 'fill' \(light1\): disabled$/);
    assert.match(lightingLines({ source: 'default', note: 'the scene has no lights' })[0].text, /^Default lighting: /);
    assert.deepEqual(lightingLines(null), []);
    // The exposure's base: a Blender file's lamps metered, then the exposure parameter on top.
    const metered = { source: 'scene', note: 'the scene\'s 3 lights',
        exposure: { base_ev: -10.88, ev: -10.88, source: 'metered', note: 'metered for the scene\'s lights: -10.9 EV' } };
    assert.deepEqual(lightingLines(metered).map((l) => l.text),
        ['Lights from the scene: the scene\'s 3 lights', 'Exposure: metered for the scene\'s lights: -10.9 EV']);
    assert.equal(lightingLines({ ...metered, exposure: { ...metered.exposure, ev: -9.38 } })[1].text,
        'Exposure: metered for the scene\'s lights: -10.9 EV; with exposure +1.5 EV: -9.4 EV');
    assert.equal(formatEv(0), '+0.0 EV');
    assert.equal(formatEv(-0.04), '+0.0 EV');
    assert.equal(formatEv(-2.25), '-2.2 EV');
});

// ---- parameters ---------------------------------------------------------------------------------

const VPL_GRID = { type: 'integer', minimum: 1, maximum: 256, default: 16, description: 'VPLs on a grid',
    'x-unit': 'VPLs per side', 'x-source': '000 §3.1', 'x-log-scale': true };

test('controls follow the schema: kind, range, step, label with unit and help', () => {
    const grid = controlSpec('vpl_grid', VPL_GRID, 8);
    assert.deepEqual({ ...grid, help: undefined }, { name: 'vpl_grid', kind: 'integer', label: 'vpl_grid (VPLs per side)',
        help: undefined, min: 1, max: 256, step: 1, initial: 8 });
    assert.match(grid.help, /VPLs on a grid · range 1 to 256 VPLs per side · default 16 · source: 000 §3.1/);
    const exposure = controlSpec('exposure', { type: 'number', minimum: -10, maximum: 10, default: 0, 'x-unit': 'EV' });
    assert.equal(exposure.step, 0.1);
    assert.equal(exposure.initial, 0, 'the default when the session has no value');
    const tonemap = controlSpec('tonemap', { type: 'string', enum: ['filmic', 'linear'], default: 'filmic' }, 'bogus');
    assert.deepEqual([tonemap.kind, tonemap.options, tonemap.initial], ['enum', ['filmic', 'linear'], 'filmic']);
    assert.equal(controlSpec('vpl_shadows', { type: 'boolean', default: false }, true).initial, true);
    const open = controlSpec('scale', { type: 'number', minimum: 0 });
    assert.equal(open.step, undefined, 'no slider step without a maximum');
    assert.equal(paramLabel('kernel', { enum: ['point'] }), 'kernel');
    assert.match(paramHelp({ type: 'number', minimum: 0 }), /at least 0/);
    // Every value a control can produce is one the server accepts.
    const schema = { type: 'object', properties: { vpl_grid: VPL_GRID } };
    for (const v of [grid.min, grid.max, grid.initial]) assert.equal(validateParamValues({ vpl_grid: v }, schema), null);
});

test('defaults and the preset changes of a frame', () => {
    const schema = { properties: { a: { default: 1 }, b: { default: 'x' }, c: {} } };
    assert.deepEqual(schemaDefaults(schema), { a: 1, b: 'x' });
    assert.deepEqual(schemaDefaults(undefined), {});
    assert.deepEqual(presetChanges({ vpl_grid: 256, exposure: 0, extra: 1 }, { vpl_grid: 16, exposure: 0 }),
        [['vpl_grid', 256, 16]]);
    assert.deepEqual(presetChanges(null, {}), []);
});

// ---- stats --------------------------------------------------------------------------------------

test('frame rate counts the frames of the last second', () => {
    const r = new RateCounter(1000);
    for (const t of [0, 100, 200, 900]) r.tick(t);
    assert.equal(r.rate(950), 4);
    assert.equal(r.rate(1150), 2);
    assert.equal(r.rate(5000), 0);
});

test('input-to-frame latency counts from the oldest input a frame can contain', () => {
    const l = new LatencyTracker();
    l.input(1000);
    l.input(1010);
    // Arrived at 1100 after 40 ms of render and encode with a 20 ms round trip: render started by
    // 1040, so both inputs are in it.
    assert.equal(l.frameDrawn(1100, 1105, { frame_ms: 30, encode_ms: 10 }, 20), 105);
    l.input(1200);
    // This frame started rendering (1250 - 40 - 20 = 1190) before the input: it cannot show it.
    assert.equal(l.frameDrawn(1250, 1252, { frame_ms: 30, encode_ms: 10 }, 20), null);
    assert.equal(l.frameDrawn(1400, 1402, { frame_ms: 30, encode_ms: 10 }, 20), 202);
    assert.equal(l.typical, (105 + 202) / 2);
    assert.equal(l.frameDrawn(1500, 1501, {}, 0), null, 'no input, no sample');
    l.reset();
    assert.equal(l.typical, null);
});

test('input-to-frame latency follows the input number a frame echoes', () => {
    const l = new LatencyTracker();
    l.input(1000, 1);
    l.input(1010, 2);
    // Estimated to begin rendering at 1250 - 40 - 20 = 1190, after both inputs, but it echoes 1:
    // the second input is not in it.
    assert.equal(l.frameDrawn(1250, 1252, { frame_ms: 30, encode_ms: 10, input_seq: 1 }, 20), 252);
    // Estimated to begin before the input (a long round trip), yet it shows it.
    assert.equal(l.frameDrawn(1300, 1302, { frame_ms: 30, encode_ms: 10, input_seq: 2 }, 500), 292);
    assert.equal(l.frameDrawn(1400, 1402, { frame_ms: 30, encode_ms: 10, input_seq: 2 }, 20), null, 'nothing new');
});

test('network time, pass times and byte formatting', () => {
    assert.equal(networkMs(20, 100, 103), 13);
    assert.equal(networkMs(null, 100, 101), 1);
    assert.equal(networkMs(10, undefined, 5), 5);
    assert.equal(passMs({ gpu_ms: 2, cpu_ms: 3 }), 2);
    assert.equal(passMs({ cpu_ms: 3 }), 3);
    assert.equal(passMs({}), 0);
    assert.equal(formatBytes(512), '512 B');
    assert.equal(formatBytes(41234), '40.3 KB');
    assert.equal(formatBytes(3 * 1024 * 1024), '3.00 MB');
});

test('pass history keeps the window, orders passes and stacks them', () => {
    const h = new PassHistory(10);
    h.push(0, [{ name: 'shadow_map', gpu_ms: 2 }, { name: 'gather', gpu_ms: 10 }]);
    h.push(5, [{ name: 'shadow_map', gpu_ms: 3 }, { name: 'blur', cpu_ms: 1 }, { name: 'gather', gpu_ms: 12 }]);
    h.push(12, [{ name: 'shadow_map', gpu_ms: 4 }, { name: 'blur', gpu_ms: 2 }, { name: 'gather', gpu_ms: 8 }]);
    const s = h.series();
    assert.deepEqual(s.times, [5, 12], 'the frame older than 10 s is gone');
    assert.deepEqual(s.names, ['shadow_map', 'blur', 'gather'], 'pipeline order of the newest frame');
    assert.deepEqual(s.values, [[3, 4], [1, 2], [12, 8]]);
    assert.deepEqual(s.stacked, [[3, 4], [4, 6], [16, 14]]);
    assert.deepEqual(stackSeries([[1, NaN], [2, 2]]), [[1, 0], [3, 2]]);
    h.clear();
    assert.deepEqual(h.series().names, []);
});

test('the pass history\'s version changes with its samples only, so a still chart need not redraw', () => {
    const h = new PassHistory(10);
    const v0 = h.version;
    h.push(1, [{ name: 'gather', gpu_ms: 5 }]);
    const v1 = h.version;
    assert.notEqual(v1, v0, 'a frame');
    h.prune(5);
    assert.equal(h.version, v1, 'a prune that removes nothing');
    assert.equal(h.windowEnd(30), 1, 'the window stops at the newest frame 10 s after it');
    h.prune(30);
    assert.equal(h.version, v1, 'nor does a window that stopped');
    h.push(40, [{ name: 'gather', gpu_ms: 5 }]);
    assert.notEqual(h.version, v1, 'a frame that pushes the old one out');
    assert.deepEqual(h.series().times, [40]);
    const v2 = h.version;
    h.clear();
    assert.notEqual(h.version, v2, 'a clear');
});

test('the chart redraws each tick while nothing waits, and after the awaited frame while input does', () => {
    const s = new ChartSchedule({ periodMs: 250, maxDeferMs: 1000 });
    assert.equal(s.onTick(0, false), true, 'the first tick');
    s.drawn(0);
    assert.equal(s.onTick(240, false), true, 'the next tick, a little early on its timer');
    s.drawn(240);
    assert.equal(s.onTick(300, false), false, 'not twice within a period');
    assert.equal(s.onTick(500, true), false, 'an input awaits its frame: the tick leaves the chart');
    assert.equal(s.onTick(750, true), false);
    assert.equal(s.onFrameDrawn(760), true, 'the awaited frame is drawn: the chart after it');
    s.drawn(770);
    assert.equal(s.onFrameDrawn(800), false, 'the next frame, within a period: not again');
    assert.equal(s.onTick(1000, true), false);
    assert.equal(s.onTick(1770, true), true, 'input waiting for a second holds it back no longer');
});

// ---- accuracy -----------------------------------------------------------------------------------

test('the accuracy request is the view on screen, small, and valid for POST /api/render', () => {
    assert.deepEqual(compareSize([480, 400], 128), [128, 107]);
    assert.deepEqual(compareSize([100, 60], 256), [100, 60], 'never larger than the frame');
    assert.deepEqual(compareSize([2000, 20], 128), [128, 16], 'each side at least 16');
    const fill = { id: 'light1', name: 'added light1', type: 'point', position: [0.5, 1.5, 0.2], direction: [0, -1, 0],
        intensity: 3, color: [1, 0.8, 0.6], range: 4, cone_deg: 45, inner_cone_deg: 36, enabled: false };
    const request = buildCompareRequest({
        scene: 'builtin:cornell', technique: 'rsm_gather', params: { vpl_grid: 4, exposure: 0 }, camera: HOME,
        lights: [KEY, fill], frameSize: [480, 400], maxSide: 128, mode: 'one-bounce-unoccluded', noiseTarget: 0.05, maxSpp: 1024,
    });
    assert.deepEqual(request.lights, [KEY, fill], 'every light, with its type and id');
    assert.equal('light' in request, false, 'lights replace the scene\'s; light would only edit one of them');
    assert.notEqual(request.lights[0], KEY, 'a copy');
    assert.equal(request.response, 'json');
    assert.deepEqual(request.compare, { mode: 'one-bounce-unoccluded', noise_target: 0.05, spp: 1024 },
        'a noise target with the spp only the cap');
    assert.deepEqual(request.size, [128, 107]);
    assert.equal(validateCompareRequest(request, RENDER_REQUEST_SCHEMA), null);
    assert.equal(validateCompareRequest({ ...request, compare: { mode: 'nope' } }, RENDER_REQUEST_SCHEMA).where, '/compare/mode');
    assert.equal(validateCompareRequest({ ...request, compare: { ...request.compare, noise_target: 0.6 } },
        RENDER_REQUEST_SCHEMA).where, '/compare/noise_target', 'the schema caps the noise target at 0.5');
    assert.equal(validateCompareRequest({ ...request, compare: { ...request.compare, noise_target: 0 } },
        RENDER_REQUEST_SCHEMA).where, '/compare/noise_target');
    // Above the server's limit is the server's to refuse (400 at /compare/spp): the schema has no maximum.
    assert.equal(validateCompareRequest({ ...request, compare: { ...request.compare, spp: 4096 } }, RENDER_REQUEST_SCHEMA), null);
    assert.equal(referenceLabel(request), 'one-bounce-unoccluded, to 5 % noise, at most 1024 spp, 128×107');
    assert.equal(validateCompareRequest({ ...request, response: 'xml' }, RENDER_REQUEST_SCHEMA).where, '/response');
    assert.equal(viewKey({ ...request, size: [64, 64], compare: { mode: 'path', spp: 1 } }), viewKey(request),
        'the view key ignores size and reference settings');
    assert.notEqual(viewKey({ ...request, params: { vpl_grid: 5 } }), viewKey(request));
    assert.notEqual(viewKey({ ...request, lights: [KEY] }), viewKey(request), 'a removed light is another view');
    // A protocol-1 light has no type; a local copy may hold fields the request has no room for.
    const v1 = { position: [0, 1.95, 0], direction: [0, -1, 0], intensity: 6, color: [1, 1, 1], cone_deg: 60, enabled: true };
    assert.deepEqual(requestLight({ ...v1, extra: 1 }), { ...v1, type: 'spot' });
    assert.equal('inner_cone_deg' in requestLight({ ...KEY, inner_cone_deg: 70 }), false,
        'an inner cone wider than the outer one is left to the server');
    const noLights = buildCompareRequest({ scene: 'builtin:cornell', technique: 'none', camera: HOME, lights: [], frameSize: [64, 64],
        maxSide: 64, mode: 'direct', noiseTarget: 0.05, maxSpp: 1024 });
    assert.deepEqual(noLights.lights, [], 'no lights is a view too');
    assert.deepEqual(noLights.compare, { mode: 'direct', spp: 1024 }, 'a direct reference is exact: no noise target');
    assert.equal(referenceLabel(noLights), 'direct, 64×64');
    assert.equal(validateCompareRequest(noLights, RENDER_REQUEST_SCHEMA), null);
    const single = buildCompareRequest({ scene: 'builtin:cornell', technique: 'none', camera: HOME, light: v1, frameSize: [64, 64],
        maxSide: 64, mode: 'path', noiseTarget: 0.2, maxSpp: 16 });
    assert.deepEqual(single.compare, { mode: 'path', noise_target: 0.2, spp: 16 });
    assert.equal(referenceLabel(single), 'path, to 20 % noise, at most 16 spp, 64×64');
    assert.equal(referenceLabel({ size: [64, 64], compare: { mode: 'path', spp: 8 } }), 'path, 8 spp, 64×64',
        'a fixed sample count');
    assert.deepEqual(single.light, v1, 'a server without a light list gets its one light');
    assert.equal(validateCompareRequest(single, RENDER_REQUEST_SCHEMA), null);
    assert.ok(canCompare('builtin:cornell'));
    assert.ok(!canCompare('upload:x.glb'), 'uploads are not reachable through the HTTP API');
});

test('saved accuracy settings: a noise target and an spp cap; an older page\'s fixed spp is dropped', () => {
    const defaults = { noiseTarget: DEFAULT_COMPARE.noiseTarget, maxSpp: DEFAULT_COMPARE.maxSpp };
    assert.deepEqual(defaults, { noiseTarget: 0.1, maxSpp: 1024 }, '10 % of the indirect light, the server\'s limit');
    assert.deepEqual(compareSettings({}), defaults);
    assert.deepEqual(compareSettings(undefined), defaults);
    assert.deepEqual(compareSettings({ compareSpp: 8, compareMode: 'path' }), defaults,
        'the old reference spp is not taken as the cap (8 spp would never reach the target)');
    assert.deepEqual(compareSettings({ compareNoiseTarget: 0.1, compareMaxSpp: 256 }), { noiseTarget: 0.1, maxSpp: 256 });
    assert.deepEqual(compareSettings({ compareNoiseTarget: 0.001, compareMaxSpp: 1e9 }), { noiseTarget: 0.01, maxSpp: 4096 },
        'clamped to the controls\' ranges');
    assert.deepEqual(compareSettings({ compareNoiseTarget: 'x', compareMaxSpp: -3 }), defaults);
    assert.deepEqual(compareSettings({ compareNoiseTarget: null, compareMaxSpp: null }), defaults);
});

// A POST /api/render answer's stats.compare (PROTOCOL.md): noise, corrected errors, indirect and direct.
const COMPARE = {
    relative_rmse: 0.129, relative_rmse_corrected: 0.124, reference_noise: 0.035, rmse: 0.02, psnr_db: 27.46,
    max_abs_error: 0.9, ssim: 0.91234, flip: 0.08123, pixels: 13696,
    indirect: { relative_rmse: 0.240, relative_rmse_corrected: 0.222, rmse: 0.01, reference_noise: 0.095, mean_ratio: 0.9962,
        pixels: 13696 },
    direct: { relative_rmse: 0.121, rmse: 0.02, psnr_db: 28, ssim: 0.93, flip: 0.07, pixels: 13696, reference_noise: 0,
        reference: { mode: 'direct', spp: 1, key: 'k2' } },
    reference: { mode: 'one-bounce-unoccluded', spp: 575, seconds: 0.171, key: 'k1', cache_hit: false,
        noise_target: { value: 0.1, of: 'indirect' } },
};

test('comparison metrics: corrected errors beside the reference\'s noise, indirect light and direct pass', () => {
    const f = formatCompare(COMPARE);
    assert.equal(f.indirect, '22.2 % (reference noise 9.5 %)', 'the corrected indirect error, not the raw 24.0 %');
    assert.equal(f.image, '12.4 % (noise 3.5 %)');
    assert.equal(f.direct, '12.1 %');
    assert.equal(f.indirectEnergy, '0.996 × the reference\'s');
    assert.equal(f.psnr, '27.5 dB');
    assert.equal(f.ssim, '0.9123');
    assert.equal(f.reference, 'one-bounce-unoccluded, 575 spp (stopped at 10 % noise), 0.17 s');
    assert.equal(f.overlay, 'indirect error 22.2 % ±9.5 % noise');
    assert.equal(f.relRmse, '22.2 %', 'the headline is the indirect light\'s');
    assert.ok(f.corrected);
    assert.match(f.hint, /corrected for the reference's own noise; indirect = each side less its own direct light/);
    assert.deepEqual(f.rows.map(([k]) => k), ['indirect light error', 'indirect energy', 'whole image', 'direct pass',
        'PSNR', 'SSIM', 'FLIP', 'reference']);
    assert.deepEqual(f.rows[0], ['indirect light error', '22.2 % (reference noise 9.5 %)']);

    // The cap (or the server's time limit) came first: the noise reached says so.
    const capped = formatCompare({ ...COMPARE, indirect: { ...COMPARE.indirect, reference_noise: 0.072 },
        reference: { ...COMPARE.reference, spp: 1024, noise_target: { value: 0.05, of: 'indirect' }, cache_hit: true } });
    assert.equal(capped.reference, 'one-bounce-unoccluded, 1024 spp (5 % noise not reached: 7.2 %), 0.17 s, cached');
    const ofImage = formatCompare({ ...COMPARE, reference: { ...COMPARE.reference, noise_target: { value: 0.05, of: 'image' } } });
    assert.match(ofImage.reference, /575 spp \(stopped at 5 % noise\)/, 'a target of the image is checked against the image\'s noise');
    assert.equal(formatCompare({ ...COMPARE, reference: { ...COMPARE.reference, noise_target: undefined } }).reference,
        'one-bounce-unoccluded, 575 spp, 0.17 s', 'a fixed sample count');

    // Noise unknown (a reference without variance): the figures as measured, and said so.
    const unknown = formatCompare({ ...COMPARE, reference_noise: null, relative_rmse_corrected: 0.129,
        indirect: { ...COMPARE.indirect, reference_noise: null, relative_rmse_corrected: 0.240 } });
    assert.equal(unknown.indirect, '24.0 % (reference noise –)');
    assert.equal(unknown.image, '12.9 % (noise –)');
    assert.equal(unknown.overlay, 'indirect error 24.0 %');
    assert.ok(!unknown.corrected);
    assert.match(unknown.hint, /as measured/);
    assert.match(unknown.reference, /575 spp \(to 10 % noise\)/);

    // A direct reference: nothing to split, exact.
    const direct = formatCompare({ relative_rmse: 0.05, relative_rmse_corrected: 0.05, reference_noise: 0, ssim: 0.99,
        reference: { mode: 'direct', spp: 1, seconds: 0.01 } });
    assert.deepEqual(direct.rows.map(([k]) => k), ['whole image', 'PSNR', 'SSIM', 'FLIP', 'reference']);
    assert.equal(direct.image, '5.0 % (noise 0 %)');
    assert.equal(direct.overlay, 'image error 5.0 % ±0 % noise');
    assert.doesNotMatch(direct.hint, /indirect/);
});

test('comparison metrics of an older server: what it sends, "–" for the rest', () => {
    const f = formatCompare({ relative_rmse: 0.0431, psnr_db: 31.25, ssim: 0.95, flip: 0.0812,
        reference: { mode: 'one-bounce-unoccluded', spp: 8, seconds: 1.234, cache_hit: false } });
    assert.equal(f.relRmse, '4.3 %');
    assert.equal(f.image, '4.3 % (noise –)');
    assert.equal(f.indirect, '–');
    assert.equal(f.indirectEnergy, '–');
    assert.equal(f.direct, '–');
    assert.equal(f.psnr, '31.3 dB');
    assert.equal(f.reference, 'one-bounce-unoccluded, 8 spp, 1.23 s');
    assert.equal(f.overlay, 'image error 4.3 %');
    assert.ok(!f.corrected);
    assert.deepEqual(f.rows.slice(0, 4), [['indirect light error', '–'], ['indirect energy', '–'],
        ['whole image', '4.3 % (noise –)'], ['direct pass', '–']]);
    assert.equal(formatCompare({ relative_rmse: Number.MAX_VALUE }).relRmse, '–', 'undefined relative RMSE');
    assert.equal(formatCompare({ relative_rmse: 0.1, relative_rmse_corrected: Number.MAX_VALUE, reference_noise: 0.5 }).image,
        '– (noise 50.0 %)', 'undefined corrected error: the noise swamps the signal');
    assert.equal(formatCompare({ reference: {} }).image, '– (noise –)');
    assert.equal(formatCompare(null), null);
    assert.equal(percent(0.0043), '0.43 %', 'two decimals below 1 %');
    assert.equal(percent(0), '0 %');
    assert.equal(percent(undefined), '–');
});

test('the difference image', () => {
    const a = new Uint8ClampedArray([10, 20, 30, 255, 0, 0, 0, 255]);
    const b = new Uint8ClampedArray([12, 20, 10, 0, 0, 0, 100, 255]);
    const d = diffImage(a, b, 4);
    assert.deepEqual([...d.data], [8, 0, 80, 255, 0, 0, 255, 255]);
    assert.ok(Math.abs(d.meanAbs - (2 + 20 + 100) / 6) < 1e-12);
    assert.throws(() => diffImage(a, new Uint8ClampedArray(4)), /differ in size/);
});

// ---- messages and uploads -----------------------------------------------------------------------

test('server errors read as sentences with the server\'s details', () => {
    assert.equal(describeError({ code: 'invalid_param', message: 'must be <= 256, got 1000', where: '/values/vpl_grid' }),
        'The server refused a parameter value. (at /values/vpl_grid: must be <= 256, got 1000)');
    assert.match(describeError({ code: 'unauthorized', message: 'x' }), /#token=/);
    assert.match(describeError({ code: 'busy' }), /session limit/);
    assert.match(describeError({ code: 'something_new', message: 'm' }), /something_new.*\(m\)/);
    assert.match(describeHttpError(400, { error: 'invalid_request', message: 'too big', where: '/size/0' }),
        /at \/size\/0: too big/);
    assert.match(describeHttpError(503, {}), /busy/);
});

test('upload names follow the server\'s rules', () => {
    assert.equal(uploadName('My Scene (2).glb'), 'My_Scene_2_.glb');
    assert.equal(uploadName('C:\\models\\room.GLB'), 'room.glb');
    assert.equal(uploadName('.hidden.glb'), 'hidden.glb');
    assert.equal(uploadName('.glb'), 'scene.glb');
    assert.equal(uploadName(`${'x'.repeat(300)}.glb`).length, 100);
    assert.equal(uploadName('scene.gltf'), null, 'a .gltf needs its files: zip them');
    assert.equal(uploadName('Sponza (glTF).ZIP'), 'Sponza_glTF_.zip');
    assert.equal(uploadType(uploadName('a.zip')), 'application/zip');
    assert.equal(uploadType(uploadName('a.glb')), 'model/gltf-binary');
    assert.equal(uploadName(undefined), null);
    for (const name of ['My Scene (2).glb', 'ü.glb', `${'y'.repeat(150)}.glb`]) {
        assert.match(uploadName(name), /^[A-Za-z0-9_-][A-Za-z0-9._-]{0,95}\.glb$/, name);
    }
});

// ---- vendored libraries -------------------------------------------------------------------------

test('the import map points at vendored files that npm ci put in place', () => {
    const html = readFileSync(path.join(CLIENT_DIR, 'index.html'), 'utf8');
    const map = JSON.parse(html.match(/<script type="importmap">([\s\S]*?)<\/script>/)[1]);
    const vendored = new Set(VENDOR_FILES.map(([, , name]) => `./vendor/${name}`));
    for (const [specifier, url] of Object.entries(map.imports)) {
        assert.ok(vendored.has(url), `${specifier} -> ${url} is one of the files client/tools/vendor.mjs copies`);
    }
    assert.ok(html.includes('href="vendor/uPlot.min.css"'), 'uPlot\'s stylesheet is linked');
    const problems = checkVendor();
    assert.deepEqual(problems, [], `client/vendor/ is not ready: ${problems.join('; ')}`);
    for (const [, , name] of VENDOR_FILES) assert.ok(existsSync(path.join(CLIENT_DIR, 'vendor', name)));
});

test('not shown: the file\'s unshown features as lines, malformed entries left out', () => {
    assert.deepEqual(notShownLines(undefined), []);
    assert.deepEqual(notShownLines({ feature: 'x' }), []);
    const lines = notShownLines([
        { feature: 'KHR_materials_clearcoat', detail: "1 material ('Paint'): clear coat is not rendered" },
        { feature: 'normalTexture' },
        null,
        { feature: 'alphaMode MASK', detail: 'cutouts render opaque' },
    ]);
    assert.deepEqual(lines.map((l) => l.feature), ['KHR_materials_clearcoat', 'alphaMode MASK']);
    assert.equal(lines[0].text, "KHR_materials_clearcoat: 1 material ('Paint'): clear coat is not rendered");
    assert.equal(notShownSummary([]), '');
    assert.match(notShownSummary(lines), /2 features this renderer does not show/);
    assert.match(notShownSummary(lines.slice(0, 1)), /1 feature this renderer/);
});

test('the triangle count says what instancing holds back', () => {
    assert.equal(trianglesText(undefined), '–');
    assert.equal(trianglesText({ triangles: 1164 }), '1164');
    assert.equal(trianglesText({ triangles: 1106, triangles_stored: 94, instances: 12 }),
        '1106 (94 held, 12 instances)');
});

test('the round trip is the least of the last pings\', so a stalled pong does not unanswer input', () => {
    const rtt = new RoundTrip(4);
    assert.equal(rtt.ms, null, 'nothing before a pong');
    assert.equal(rtt.add(15), 15);
    assert.equal(rtt.add(12), 12);
    // A pong that waited 2.6 s behind a stall (a proxy holding messages, a frozen network).
    assert.equal(rtt.add(2600), 12);
    rtt.add(Number.NaN);
    rtt.add(-3);
    assert.equal(rtt.ms, 12, 'not finite or negative: ignored');
    for (const ms of [30, 31, 32, 33]) rtt.add(ms);
    assert.equal(rtt.ms, 30, 'only the last four count');
    rtt.reset();
    assert.equal(rtt.ms, null);

    // Input at 1000 ms; frames and the pong held back until 3500 ms; the frame (50 ms to render)
    // arrives at 3510. With the stalled pong as the round trip its render "began" before the input.
    const renderStart = (roundTripMs) => 3510 - roundTripMs - 50;
    const answered = (roundTripMs) => {
        const watch = new InputWatch();
        watch.input(1000);
        watch.frameDrawn(renderStart(roundTripMs), 3515);
        return !watch.pending;
    };
    assert.equal(answered(2600), false, 'the last pong\'s round trip leaves the input waiting for ever');
    const estimate = new RoundTrip();
    [15, 12, 2600].forEach((ms) => estimate.add(ms));
    assert.equal(answered(estimate.ms), true);
});
