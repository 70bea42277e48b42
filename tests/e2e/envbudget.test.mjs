// End-to-end test of the environment probes' budget in the live view (docs/nondiffuse.md, "Probe
// budget"): on a scene with probes, interactive frames carry env_budget_ms, a quarter of the frame
// target, in their parameters and stats.budget, and the probes' plan in stats.nondiffuse.env; the
// final step gets the whole target; a value the client sets wins.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';

import { Client, ServerProcess } from './helpers.mjs';

let server = null;
let client = null;

before(async () => {
    server = await ServerProcess.start(['--scene', 'builtin:gallery', '--technique', 'none',
        '--frame-target-ms', '80', '--settle-ms', '100']);
});

after(async () => {
    await client?.close();
    await server?.stop();
});

test('the live view budgets the environment probes from its frame target', async () => {
    client = await Client.open(server, { codecs: ['jpeg'] });
    client.send({ type: 'resize', size: [160, 128] });
    // A light change renders the probes again.
    client.send({ type: 'light', id: 'light0', light: { intensity: 9 } });
    const interactive = await client.frame('an interactive frame after the light change',
        (s) => s.quality === 'interactive' && s.params?.env_budget_ms === 20);
    assert.equal(interactive.stats.budget?.env_budget_ms, 20, 'stats.budget.env_budget_ms');
    assert.equal(interactive.stats.counts?.env_budget_ms, 20, 'the probes saw the budget');
    assert.match(interactive.stats.nondiffuse?.env ?? '', /^on: .*; env_size \d+, \d probes?/,
                 'stats.nondiffuse.env ends with the probes\' plan');

    const final = await client.frame('a final-step frame', (s) => s.quality === 'final', 60000);
    assert.equal(final.stats.params?.env_budget_ms, 80, 'the final step may spend the whole target');

    client.send({ type: 'params', values: { env_budget_ms: 0 } });
    const own = await client.frame('a frame with the client\'s env_budget_ms',
        (s) => s.quality === 'interactive' && s.params?.env_budget_ms === 0);
    assert.match(own.stats.nondiffuse?.env ?? '', /no budget/, 'as asked: no budget');
    assert.equal(own.stats.counts?.env_size, own.stats.counts?.env_size_requested, 'env_size as asked');
});

test('probes asked at their costliest are measured small first, so input is not held for seconds', async () => {
    await client?.close();
    client = await Client.open(server, { codecs: ['jpeg'] });
    client.send({ type: 'resize', size: [160, 128] });
    await client.frame('a first frame', () => true);
    // Every probe at 512 texels with 256 samples: seconds per probe on a CPU, one stage each, in the
    // frame that answers this message. Nothing is measured at 256 samples yet.
    client.send({ type: 'params', values: { env_size: 512, env_samples: 256 } });
    const answer = await client.frame('the frame that answers the parameters',
        (s) => s.quality === 'interactive' && s.params?.env_samples === 256, 30000);
    assert.equal(answer.stats.counts?.env_size_requested, 512);
    assert.equal(answer.stats.counts?.env_size, 32, 'the smallest first');
    assert.equal(answer.stats.counts?.env_probes, 1, 'the room probe alone');
    assert.match(answer.stats.nondiffuse?.env ?? '', /not measured yet, so the smallest first/);
    assert.ok(answer.stats.frame_ms < 2000, `answered in ${answer.stats.frame_ms} ms`);

    // The next render of the probes plans from what that one measured.
    client.send({ type: 'light', id: 'light0', light: { intensity: 8 } });
    const planned = await client.frame('an interactive frame after a light change',
        (s) => s.quality === 'interactive' && s.frame > answer.stats.frame && s.counts?.env_predicted_ms > 0, 30000);
    assert.doesNotMatch(planned.stats.nondiffuse?.env ?? '', /not measured/);
    assert.ok(planned.stats.counts.env_predicted_ms <= 20 || /over budget at the smallest/.test(planned.stats.nondiffuse?.env),
        `within the 20 ms budget: ${planned.stats.nondiffuse?.env}`);
    assert.ok(planned.stats.frame_ms < 2000, `answered in ${planned.stats.frame_ms} ms`);
});
