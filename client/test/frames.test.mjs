import { test } from 'node:test';
import assert from 'node:assert/strict';

import { enqueueFrame, figuresDue, isPatch, patchPlacement } from '../frames.js';

const whole = (id) => ({ id, entry: { stats: { size: [64, 32] } } });
const patch = (id, x = 0, y = 0) => ({ id, entry: { stats: { size: [64, 32], patch: { x, y, width: 16, height: 16 } } } });

test('a whole frame replaces the frames that wait; patches wait their turn', () => {
    let q = [];
    ({ queue: q } = enqueueFrame(q, whole(1)));
    let r = enqueueFrame(q, patch(2));
    assert.deepEqual(r.queue.map((f) => f.id), [1, 2]);
    assert.deepEqual(r.dropped, []);
    r = enqueueFrame(r.queue, patch(3));
    assert.deepEqual(r.queue.map((f) => f.id), [1, 2, 3]);
    r = enqueueFrame(r.queue, whole(4));
    assert.deepEqual(r.queue.map((f) => f.id), [4]);
    assert.deepEqual(r.dropped.map((f) => f.id), [1, 2, 3], 'the superseded ones are acknowledged unseen');
    assert.equal(isPatch(patch(5)), true);
    assert.equal(isPatch(whole(5)), false);
    assert.equal(isPatch({}), false);
});

test('a patch is placed inside the whole image, or not at all', () => {
    assert.deepEqual(patchPlacement(patch(1, 48, 16).entry.stats, { width: 16, height: 16 }),
        { width: 64, height: 32, x: 48, y: 16 });
    assert.equal(patchPlacement(whole(1).entry.stats, { width: 64, height: 32 }), null);
    assert.equal(patchPlacement(patch(1, 56, 0).entry.stats, { width: 16, height: 16 }), null, 'past the right edge');
    assert.equal(patchPlacement({ patch: { x: -1, y: 0 }, size: [64, 32] }, { width: 1, height: 1 }), null);
    assert.equal(patchPlacement({ patch: { x: 0, y: 0 } }, { width: 1, height: 1 }), null, 'no size');
});

test('a patch shows its figures at most once a period; whole frames and the last patch always', () => {
    const patch = { patch: { x: 0, y: 0, width: 8, height: 8 }, refine: { complete: false } };
    assert.equal(figuresDue(patch, 1000, -Infinity, 250), true, 'the first patch');
    assert.equal(figuresDue(patch, 1100, 1000, 250), false, 'one 100 ms after');
    assert.equal(figuresDue(patch, 1250, 1000, 250), true, 'one a period after');
    assert.equal(figuresDue({ ...patch, refine: { complete: true } }, 1010, 1000, 250), true, 'the one that completes the image');
    assert.equal(figuresDue({ quality: 'interactive' }, 1010, 1000, 250), true, 'a whole frame');
    assert.equal(figuresDue(null, 1010, 1000, 250), true, 'a frame without stats');
});
