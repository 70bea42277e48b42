// Unit tests of what the page says while the server works and of the resolution choices:
// refinement progress, late frames and stale figures (progress.js), the pixel budget and frame-time
// targets (budget.js), the chart's window and axis (stats.js) and the reconnect countdown.
// Run: node --test client/test/
import { test } from 'node:test';
import assert from 'node:assert/strict';

import {
    DEFAULT_FRAME_TARGET_MS, FLASH_MS, InputWatch, RefineTracker, STALE_AFTER_MS, busyText, formatSeconds,
} from '../progress.js';
import {
    DEFAULT_PIXEL_BUDGET, PIXEL_BUDGETS, budgetDpr, budgetLine, budgetViewport, frameTargetOptions, frameTargetSupported,
    normalizeFrameTarget, normalizePixelBudget,
} from '../budget.js';
import { PassHistory, axisSize, msTickLabels } from '../stats.js';
import { formatCountdown } from '../connection.js';
import { helloMsg, qualityMsg, validateClientMessage } from '../protocol.js';
import { CLIENT_SCHEMAS } from '../schemas.js';

// ---- refinement progress -------------------------------------------------------------------------

test('refinement tiles and progress messages show the step, the share done and the time left', () => {
    const r = new RefineTracker();
    assert.equal(r.view(0), null, 'nothing before refinement');
    r.message({ type: 'progress', state: 'refining', step: 'balanced', share: 0, eta_ms: 2000 }, 1000);
    assert.deepEqual(r.view(1000), { kind: 'refining', text: 'refining balanced · 0 % · 2.0 s left', share: 0 });
    r.stats({ quality: 'balanced', refine: { step: 'balanced', tiles_done: 7, share: 0.41, elapsed_ms: 900, eta_ms: 1300,
        complete: false } }, 2000);
    assert.equal(r.view(2000).text, 'refining balanced · 41 % · 1.3 s left');
    assert.equal(r.view(2500).text, 'refining balanced · 41 % · 0.8 s left', 'the time left counts down between tiles');
    assert.equal(r.view(9000).text, 'refining balanced · 41 % · 0.0 s left', 'never below zero');
    assert.equal(r.view(2000).share, 0.41);
    assert.ok(r.refining);
    // A step with nothing measured before it: the server does not know the time left yet.
    r.stats({ quality: 'balanced', refine: { step: 'balanced', share: 0.02, eta_ms: null, complete: false } }, 2100);
    assert.equal(r.view(2200).text, 'refining balanced · 2 %', 'no time left when none is known');
    r.stats({ quality: 'balanced', refine: { step: 'balanced', share: 0.41, eta_ms: 1300, complete: false } }, 2000);
    r.stats({ quality: 'balanced', refine: { step: 'balanced', share: 1, eta_ms: 0, complete: true } }, 2600);
    assert.equal(r.view(2600), null, 'between steps nothing runs');
    r.message({ state: 'skipped', step: 'final', reason: 'over budget' }, 2700);
    assert.equal(r.view(2700).text, 'skipped final: over budget', 'and a skipped final step is said');
    r.reset();
    r.stats({ quality: 'final', refine: { step: 'final', share: 1, eta_ms: 0, complete: true } }, 3000);
    assert.deepEqual(r.view(3000), { kind: 'done', text: 'refined: final quality', share: null },
        'a complete final tile finishes refinement even before the done message');
    assert.equal(r.view(3000 + FLASH_MS.done), null, '"done" fades');
    r.message({ state: 'refining', step: 'final', share: 0.5, eta_ms: 100 }, 4000);
    r.message({ state: 'done', step: 'final', share: 1 }, 4100);
    assert.equal(r.view(4100).kind, 'done');
});

test('abandoned and skipped refinement are said, skipped longest and alongside the next step', () => {
    const r = new RefineTracker();
    r.message({ state: 'refining', step: 'balanced', share: 0.2, eta_ms: 1000 }, 0);
    r.message({ state: 'abandoned', step: 'balanced', reason: 'the camera moved' }, 100);
    assert.deepEqual(r.view(100), { kind: 'abandoned', text: 'refinement abandoned: the camera moved', share: null });
    assert.ok(!r.refining);
    r.message({ state: 'abandoned' }, 200);
    assert.equal(r.view(200).text, 'refinement abandoned (input)');
    r.message({ state: 'skipped', step: 'final', reason: 'predicted 9000 ms, over the refinement budget of 5000 ms' }, 1000);
    assert.deepEqual(r.view(1000), { kind: 'skipped',
        text: 'skipped final: predicted 9000 ms, over the refinement budget of 5000 ms', share: null });
    r.message({ state: 'done' }, 1100);
    assert.equal(r.view(1100).kind, 'skipped', '"done" does not hide that the final step was skipped');
    assert.equal(r.view(1000 + FLASH_MS.skipped), null);
    r.message({ state: 'skipped', step: 'balanced', reason: 'over budget' }, 2000);
    r.message({ state: 'refining', step: 'final', share: 0.1, eta_ms: 500 }, 2100);
    assert.equal(r.view(2100).text, 'refining final · 10 % · 0.5 s left · skipped balanced: over budget');
    r.stats({ quality: 'interactive' }, 2200);
    assert.ok(!r.refining, 'an interactive frame ends the step on screen');
    r.message({ state: 'bogus' }, 2300);
    r.reset();
    assert.equal(r.view(2300), null);
});

test('stats without refine (older servers) leave the progress alone', () => {
    const r = new RefineTracker();
    r.stats({ quality: 'balanced', refined: true }, 0);
    r.stats({ quality: 'final', refined: true }, 10);
    assert.equal(r.view(10), null);
});

// ---- late frames and stale figures ----------------------------------------------------------------

test('a frame is late when input waits more than twice the frame target without any frame', () => {
    const w = new InputWatch();
    assert.equal(w.lateMs(1000), null);
    w.frameDrawn(0, 100);
    w.input(1000);
    assert.ok(w.pending);
    assert.equal(w.lateMs(1000 + 2 * DEFAULT_FRAME_TARGET_MS), null, 'not yet at twice the target');
    assert.equal(w.lateMs(1200, 80), 200);
    assert.equal(w.lateMs(1200, 150), null, 'a slower target waits longer');
    w.input(1100); // more input: the oldest waiting one counts
    assert.equal(w.lateMs(1400, 80), 400);
    // A frame whose render began after the newest input contains all of it.
    w.frameDrawn(1150, 1450);
    assert.ok(!w.pending);
    assert.equal(w.lateMs(3000, 80), null);
});

test('frames that keep coming during a drag are not late, and part of the input can be shown', () => {
    const w = new InputWatch();
    for (let t = 0; t < 3000; t += 16) {
        w.input(t);
        // A frame every 64 ms whose render began 100 ms before it was drawn.
        if (t % 64 === 0 && t >= 100) w.frameDrawn(t - 100, t);
        assert.equal(w.lateMs(t, 80), null, `at ${t} ms`);
        assert.equal(w.stale(t, 80), false, `at ${t} ms`);
    }
    assert.ok(w.pending, 'the newest input is not in any frame yet');
    assert.ok(w.pendingSince > 2000, 'what waits began after the last frame started rendering');
});

test('figures go stale once input has waited too long for a frame that shows it', () => {
    const w = new InputWatch();
    w.input(0);
    assert.equal(w.stale(500), false, 'no frame on screen yet: nothing to mark');
    w.frameDrawn(-50, 10); // began before the input
    assert.equal(w.stale(100, 80), false);
    assert.equal(w.stale(200, 80), true, 'late: no frame for over twice the target');
    w.frameDrawn(-20, 150); // frames still coming, none with the input
    assert.equal(w.stale(300, 1000), false);
    assert.equal(w.stale(STALE_AFTER_MS + 1, 1000), true, 'input waiting over 2 s');
    w.frameDrawn(10, STALE_AFTER_MS + 50);
    assert.equal(w.stale(STALE_AFTER_MS + 60), false);
    w.reset();
    assert.equal(w.pending, false);
});

test('the busy badge: late first, then refinement, else nothing', () => {
    assert.equal(busyText({ lateMs: 1234 }), 'rendering… 1.2 s');
    const refining = { kind: 'refining', text: 'refining final · 3 %' };
    assert.equal(busyText({ lateMs: null, refine: refining }), 'refining final · 3 %');
    assert.equal(busyText({ lateMs: 50, refine: { kind: 'refining', text: 'x' } }), 'rendering… 0.1 s');
    assert.equal(busyText({ refine: { kind: 'done', text: 'refined' } }), null);
    assert.equal(busyText({}), null);
    assert.equal(formatSeconds(65_000), '1 min 5 s');
    assert.equal(formatSeconds(-5), '0.0 s');
});

// ---- pixel budget and frame targets ---------------------------------------------------------------

test('the pixel budget caps the announced dpr: a dpr 3 phone does not ask for 3x3 its pixels', () => {
    const phone = budgetViewport(390, 844, 3, DEFAULT_PIXEL_BUDGET);
    assert.deepEqual(phone.size, [390, 844]);
    assert.ok(phone.dpr < 3 && phone.dpr > 1.7, `dpr ${phone.dpr}`);
    assert.ok(390 * 844 * phone.dpr ** 2 <= DEFAULT_PIXEL_BUDGET, 'within the budget');
    const small = budgetViewport(315.4, 682.7, 3, DEFAULT_PIXEL_BUDGET);
    assert.ok(small.size[0] * small.dpr * small.size[1] * small.dpr <= 1e6, 'not 946x2048');
    assert.equal(budgetDpr(400, 300, 2, 1e6), 2, 'under the budget the device ratio stays');
    assert.equal(budgetDpr(400, 300, 2, 0), 2, '0: no cap');
    assert.equal(budgetDpr(1920, 1080, 1, 1e6), 0.694, 'a large window is capped below 1 too');
    assert.equal(budgetDpr(8192, 8192, 1, 250_000), 0.25, 'never below the protocol minimum');
    assert.equal(budgetDpr(100, 100, 9, 0), 4, 'never above the protocol maximum');
    assert.equal(budgetDpr(100, 100, NaN, 1e6), 1);
    for (const [w, h, dpr] of [[390, 844, 3], [1280, 800, 1], [3840, 2160, 2], [10, 10, 0.1], [20000, 20000, 4]]) {
        for (const { px } of PIXEL_BUDGETS) {
            const vp = budgetViewport(w, h, dpr, px);
            const msg = helloMsg({ size: vp.size, dpr: vp.dpr });
            assert.equal(validateClientMessage(msg, CLIENT_SCHEMAS), null, `${w}x${h}@${dpr}, ${px}`);
        }
    }
});

test('stored quality settings are kept only when they are valid choices', () => {
    assert.equal(normalizePixelBudget(2_000_000), 2_000_000);
    assert.equal(normalizePixelBudget(0), 0);
    assert.equal(normalizePixelBudget(123), DEFAULT_PIXEL_BUDGET);
    assert.equal(normalizePixelBudget('1e6'), DEFAULT_PIXEL_BUDGET);
    assert.equal(normalizeFrameTarget(80), 80);
    assert.equal(normalizeFrameTarget(null), null);
    assert.equal(normalizeFrameTarget(10), null, 'below the protocol range');
    assert.equal(normalizeFrameTarget(1001), null);
    assert.equal(normalizeFrameTarget(80.5), null);
});

test('frame targets are offered only where the server announces them and the schema has the field', () => {
    const schemas = { quality: { properties: { frame_target_ms: { type: 'integer' } } }, hello: { properties: {} } };
    assert.equal(frameTargetSupported({ frame_target_ms: 80 }, schemas), true);
    assert.equal(frameTargetSupported({}, schemas), false, 'an older server: the control is hidden');
    assert.equal(frameTargetSupported({ frame_target_ms: 80 }, { quality: { properties: {} } }), false);
    assert.equal(frameTargetSupported(null, schemas, 'hello'), false);
    assert.deepEqual(Object.entries(frameTargetOptions(80)), [['server default (80 ms)', 'default'],
        ['smooth (50 ms)', 50], ['balanced (80 ms)', 80], ['sharp (150 ms)', 150]]);
    assert.equal(Object.keys(frameTargetOptions(undefined))[0], 'server default');
    assert.deepEqual(qualityMsg(true, 50), { type: 'quality', adaptive: true, frame_target_ms: 50 });
    assert.deepEqual(qualityMsg(false), { type: 'quality', adaptive: false });
    assert.equal(helloMsg({ frame_target_ms: 150 }).frame_target_ms, 150);
    if (frameTargetSupported({ frame_target_ms: 80 }, CLIENT_SCHEMAS)) {
        for (const ms of [50, 80, 150]) assert.equal(validateClientMessage(qualityMsg(true, ms), CLIENT_SCHEMAS), null);
    }
});

test('a frame\'s budget reads as one line with its reason', () => {
    const line = budgetLine({ target_ms: 80, scale: 0.31, vpls: 1024, vpl_cap: 256, predicted_ms: 70.2,
        reason: 'the full VPL set is predicted at 210 ms' });
    assert.deepEqual(line, { text: 'budget 80 ms: predicted 70 ms · VPLs 256 of 1024 · scale 0.31',
        reason: 'the full VPL set is predicted at 210 ms', capped: true });
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, vpl_cap: null, predicted_ms: 12 }).text,
        'budget 80 ms: predicted 12 ms · VPLs 64');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, vpl_cap: null }).capped, false);
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, lod_pixels: 1 }).text,
        'budget 80 ms: predicted 12 ms · VPLs 64 · detail within 1 px', 'the level of detail the server set');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, lod_pixels: 0 }).text,
        'budget 80 ms: predicted 12 ms · VPLs 64');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, lod_pixels: 1, light_lod_texels: 1 }).text,
        'budget 80 ms: predicted 12 ms · VPLs 64 · detail within 1 px, light views 1 texel', 'and in the light views');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, light_lod_texels: 0.5 }).text,
        'budget 80 ms: predicted 12 ms · VPLs 64 · light views within 0.5 texels');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, light_view_cap: { shadow_side: 2048,
        rsm_side: 512, shadow_side_asked: 4096, rsm_side_asked: 1024, predicted_ms: 19 } }).text,
    'budget 80 ms: predicted 12 ms · VPLs 64 · maps 2048/512 of 4096/1024', 'light views drawn smaller');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, light_view_cap: { shadow_side: 1024,
        rsm_side: null, shadow_side_asked: 4096, rsm_side_asked: 256 } }).text,
    'budget 80 ms: predicted 12 ms · VPLs 64 · maps 1024 of 4096', 'shadow maps alone (no RSM read)');
    assert.equal(budgetLine({ target_ms: 80, vpls: 64, predicted_ms: 12, light_view_cap: null }).text,
        'budget 80 ms: predicted 12 ms · VPLs 64');
    const receivers = budgetLine({ target_ms: 80, vpls: 4096, vpl_cap: null, receiver_share_cap: 0.04,
        receiver_capped_vpls: 361, predicted_ms: 70, reason: 'fits; this view\'s receivers exceed the cap' });
    assert.equal(receivers.text, 'budget 80 ms: predicted 70 ms · VPLs 361 of 4096 (receiver cap)',
        'a frame the receiver cap cut says so');
    assert.equal(receivers.capped, true);
    assert.equal(budgetLine(undefined), null);
    assert.equal(budgetLine('x'), null);
});

// ---- chart and countdown --------------------------------------------------------------------------

test('the chart keeps its last frames when no new ones come, and its axis has room and a unit', () => {
    const h = new PassHistory(10);
    h.push(1, [{ name: 'gather', gpu_ms: 5 }]);
    h.push(2, [{ name: 'gather', gpu_ms: 6 }]);
    assert.equal(h.windowEnd(5), 5, 'frames within the window: it scrolls');
    assert.equal(h.windowEnd(30), 2, 'none for longer than the window: it stops at the newest');
    h.prune(30);
    assert.equal(h.samples.length, 2, 'and keeps them');
    assert.equal(h.ageS(30), 28);
    h.push(31, []);
    h.prune(31);
    assert.deepEqual(h.samples.map((x) => x.t), [31], 'a new frame starts a new window');
    assert.equal(new PassHistory().ageS(1), null);
    assert.deepEqual(msTickLabels([0, 50, 1200, 1.25]), ['0 ms', '50 ms', '1200 ms', '1.25 ms']);
    assert.ok(axisSize(['1200 ms']) >= 7 * 6 + 10, 'wide enough for "1200 ms"');
    assert.ok(axisSize(['0 ms']) < axisSize(['1200 ms']));
    assert.equal(axisSize(null), axisSize([]));
});

test('the reconnect countdown counts whole seconds, tenths below one', () => {
    assert.equal(formatCountdown(8000), '8 s');
    assert.equal(formatCountdown(7001), '8 s');
    assert.equal(formatCountdown(1000), '1 s');
    assert.equal(formatCountdown(500), '0.5 s');
    assert.equal(formatCountdown(-20), '0.0 s');
});

test('a scene load shows while it runs, then what it cost; a failed one leaves the error to say why', () => {
    const r = new RefineTracker();
    r.message({ type: 'progress', state: 'loading', step: 'scene', reason: 'loading upload:city.glb (48.0 MiB)' }, 0);
    assert.deepEqual(r.view(10), { kind: 'loading', text: 'loading upload:city.glb (48.0 MiB)', share: null });
    assert.equal(busyText({ refine: r.view(10) }), 'loading upload:city.glb (48.0 MiB)');
    assert.equal(r.view(60000).kind, 'loading', 'a long load stays up');
    r.message({ type: 'progress', state: 'loaded', step: 'scene', reason: 'loaded upload:city.glb: 2000 triangles in 900 ms' }, 61000);
    assert.equal(r.view(61010).kind, 'loaded');
    assert.match(r.view(61010).text, /2000 triangles in 900 ms/);
    assert.equal(r.view(61000 + FLASH_MS.loaded + 1), null);
    r.message({ type: 'progress', state: 'loading', step: 'scene', reason: 'loading upload:bad.glb' }, 70000);
    r.message({ type: 'progress', state: 'load_failed', step: 'scene', reason: 'could not load upload:bad.glb' }, 70100);
    assert.equal(r.view(70200), null);
});

test('a long load shows how far it got and the time left, counting down between messages', () => {
    const r = new RefineTracker();
    r.message({ type: 'progress', state: 'loading', step: 'scene', share: 0, eta_ms: 0, reason: 'loading upload:city.glb (48.0 MiB)' }, 0);
    assert.equal(r.view(10).share, null, 'the first message knows nothing yet');
    r.message({ type: 'progress', state: 'loading', step: 'scene', share: 0.4, eta_ms: 3000,
        reason: 'loading upload:city.glb (48.0 MiB): decoding images: 3 of 12' }, 2000);
    const v = r.view(2500);
    assert.equal(v.kind, 'loading');
    assert.equal(v.share, 0.4);
    assert.equal(v.text, 'loading upload:city.glb (48.0 MiB): decoding images: 3 of 12 · 40 % · 2.5 s left');
    assert.match(busyText({ refine: v }), /3 of 12 · 40 %/);
    assert.match(r.view(9000).text, /0\.0 s left$/, 'the countdown stops at zero');
    r.message({ type: 'progress', state: 'loaded', step: 'scene', share: 1, reason: 'loaded upload:city.glb' }, 9100);
    assert.deepEqual(r.view(9200), { kind: 'loaded', text: 'loaded upload:city.glb', share: null });
});

test('the echoed input number decides which inputs a frame shows, whatever the clocks say', () => {
    const w = new InputWatch();
    w.input(1000, 1);
    w.input(1010, 2);
    // A frame estimated to have begun before both inputs (a round trip measured too long) that
    // echoes number 2 shows both: nothing waits, in a still view where no later frame would come.
    w.frameDrawn(900, 1200, 2);
    assert.equal(w.pending, false);
    w.input(1300, 3);
    // A refinement tile of the step input abandoned: its estimated start follows the input, but
    // it echoes 2, so input 3 still waits for a frame.
    w.frameDrawn(1350, 1400, 2);
    assert.equal(w.pending, true);
    assert.equal(w.pendingSince, 1300);
    w.input(1450, 4);
    w.frameDrawn(1460, 1500, 3); // shows 3, not 4
    assert.equal(w.pendingSince, 1450);
    // Once the server has echoed a number, a frame without one predates every numbered input of
    // the connection (the server numbers afresh on each): it shows none.
    w.frameDrawn(2000, 2100, undefined);
    assert.equal(w.pendingSince, 1450);
    w.frameDrawn(0, 2200, 4);
    assert.equal(w.pending, false);
    w.reset();
    w.input(3000, 5);
    w.frameDrawn(3100, 3200, undefined);
    assert.equal(w.pending, true, 'a new connection: frames before its first number show nothing');
    w.frameDrawn(2900, 3300, 5);
    assert.equal(w.pending, false);
});
