// The benchmarks' shared helpers: the quantiles every report is made of.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { percentile } from '../lib.mjs';

test('percentile interpolates between the nearest ranks', () => {
    const ten = [10, 1, 9, 2, 8, 3, 7, 4, 6, 5]; // 1..10, unsorted
    assert.equal(percentile(ten, 0), 1);
    assert.equal(percentile(ten, 1), 10);
    assert.equal(percentile(ten, 0.5), 5.5, 'the median of an even count is the mean of the middle two');
    // Position 0.95 * 9 = 8.55: between the 9th and 10th values, not the slowest alone.
    assert.ok(Math.abs(percentile(ten, 0.95) - 9.55) < 1e-9);
    assert.equal(percentile([3, 1, 2], 0.5), 2);
    assert.equal(percentile([7], 0.95), 7);
});

test('percentile leaves its input alone and has no answer for no values', () => {
    const values = [3, 1, 2];
    percentile(values, 0.5);
    assert.deepEqual(values, [3, 1, 2]);
    assert.equal(percentile([], 0.5), null);
    assert.equal(percentile([1, 2], 2), 2, 'p is clamped to 0..1');
});
