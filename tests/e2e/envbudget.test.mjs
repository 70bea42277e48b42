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
