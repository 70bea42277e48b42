// End-to-end test of the light views in interactive frames (docs/interactive.md, "Light views in
// interactive frames"): with shadow_map_size and rsm_size above their defaults, an interactive frame
// that draws its light views again draws them no larger than stats.budget.light_view_cap says, and
// says so in stats.lighting (the sides drawn, and the asked ones when smaller); where nothing is
// measured yet the defaults' sides come first; a refinement step draws the asked sides.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';

import { Client, ServerProcess } from './helpers.mjs';

let server = null;
let client = null;

before(async () => {
    server = await ServerProcess.start(['--scene', 'builtin:cornell', '--technique', 'hier_isr',
        '--frame-target-ms', '80', '--settle-ms', '100']);
});

after(async () => {
    await client?.close();
    await server?.stop();
});

const sides = (s) => `${s.lighting?.shadow_side}/${s.lighting?.rsm_side}`;

test('interactive frames draw large light views within the budget, refinement draws them whole', async () => {
    client = await Client.open(server, { codecs: ['jpeg'] });
    client.send({ type: 'resize', size: [160, 128] });
    await client.frame('a first frame', (s) => s.quality === 'interactive');
    client.send({ type: 'params', values: { shadow_map_size: 4096, rsm_size: 1024 } });
    await client.frame('a frame with the large maps asked', (s) => s.params?.rsm_size === 1024);

    // A technique this scene has not rendered yet: nothing of its light views is measured, so its
    // first frame draws them at the defaults' sides.
    client.send({ type: 'technique', name: 'rsm_gather' });
    const first = await client.frame('the first rsm_gather frame',
        (s) => s.technique === 'rsm_gather' && s.quality === 'interactive');
    assert.equal(sides(first.stats), '1024/256', `drawn at the defaults' sides: ${JSON.stringify(first.stats.lighting)}`);
    assert.equal(first.stats.lighting.shadow_side_asked, 4096);
    assert.equal(first.stats.lighting.rsm_side_asked, 1024);
    const cap = first.stats.budget?.light_view_cap;
    assert.deepEqual([cap?.shadow_side, cap?.rsm_side, cap?.shadow_side_asked, cap?.rsm_side_asked], [1024, 256, 4096, 1024]);
    assert.match(first.stats.budget.reason, /light views drawn again at shadow maps 1024 of 4096 texels, RSMs 256 of 1024: .*not measured yet/);

    // A light drag: every frame draws its light views again, within the cap its budget set.
    let last = first.stats.frame;
    for (let i = 0; i < 6; i++) {
        client.send({ type: 'light', id: 'light0', light: { intensity: 10 + i } });
        const f = await client.frame(`the answer to light change ${i}`, (s) => s.quality === 'interactive' && s.frame > last);
        last = f.stats.frame;
        const { lighting, budget } = f.stats;
        const capped = budget?.light_view_cap;
        assert.equal(f.stats.counts?.light_views_reused, undefined, 'a light change draws the light views');
        if (capped) {
            assert.ok(lighting.shadow_side <= capped.shadow_side && lighting.rsm_side <= capped.rsm_side,
                `${sides(f.stats)} within the cap ${capped.shadow_side}/${capped.rsm_side}`);
            assert.ok(capped.shadow_side >= 1024 && capped.rsm_side >= 256, 'never below the defaults\' sides');
            assert.match(budget.reason, /light views drawn again at/);
        } else {
            assert.equal(sides(f.stats), '4096/1024', 'no cap: the asked sides');
        }
    }

    // Still: a refinement step draws them as asked.
    const refined = await client.frame('a refinement frame', (s) => s.quality === 'balanced' || s.quality === 'final', 60000);
    assert.equal(sides(refined.stats), '4096/1024');
    assert.equal(refined.stats.lighting.shadow_side_asked, undefined);
    assert.equal(refined.stats.budget, undefined, 'refinement frames carry no budget');
});
