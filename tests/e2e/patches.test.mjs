// End-to-end test of patches (hello.patches): while a still view refines in tiles, a client that
// draws patches is sent only the regions pasted since the last send. Composed in order, they must
// give exactly the image the server would send whole, and a client that does not draw patches (a
// viewer joining later) must get whole images.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';

import { Client, decodePng, ServerProcess } from './helpers.mjs';

const SIZE = [160, 128];
let server = null;
const clients = [];

before(async () => {
    // Small slices make many tiles (and so many patches) even at this size.
    server = await ServerProcess.start(['--scene', 'builtin:cornell', '--technique', 'rsm_gather',
        '--slice-ms', '5', '--settle-ms', '100']);
});

after(async () => {
    for (const c of clients) await c.close();
    await server?.stop();
});

/** Frames until the final step is complete: [{stats, header, payload}]. */
async function framesUntilFinal(client, what) {
    const frames = [];
    for (;;) {
        const frame = await client.frame(what, () => true, 60000);
        frames.push(frame);
        if (frame.stats.quality === 'final' && frame.stats.refine?.complete) return frames;
    }
}

test('patches compose the whole refined image; a viewer without patches gets it whole', async (t) => {
    t.after(() => {
        if (t.passed === false) console.error(`--- gi-server log ---\n${server.log}`);
    });
    const controller = await Client.open(server, { codecs: ['png'], patches: true, size: SIZE, dpr: 1, max_in_flight: 2 });
    clients.push(controller);
    // Explicit parameters win over every step's preset: all steps render these 64 VPLs.
    controller.send({ type: 'params', values: { vpl_grid: 8 } });
    const frames = await framesUntilFinal(controller, 'refinement with patches');

    const finalFrames = frames.slice(frames.findIndex((f) => f.stats.quality === 'final'));
    const patches = finalFrames.filter((f) => f.stats.patch);
    assert.ok(patches.length >= 2, `the final step was sent as patches (${patches.length} of ${finalFrames.length} frames)`);
    const [width, height] = finalFrames.at(-1).stats.size;
    assert.deepEqual([width, height], SIZE, 'the refined image has the requested size');

    // Compose the final step's patches over an empty image, noting which pixels they cover.
    const composed = Buffer.alloc(width * height * 4);
    const covered = new Uint8Array(width * height);
    for (const f of finalFrames) {
        const img = decodePng(f.payload);
        const { x, y } = f.stats.patch ?? { x: 0, y: 0 };
        assert.ok(x + img.width <= width && y + img.height <= height, `patch ${JSON.stringify(f.stats.patch)} inside the image`);
        for (let row = 0; row < img.height; row++) {
            img.rgba.copy(composed, ((y + row) * width + x) * 4, row * img.width * 4, (row + 1) * img.width * 4);
            covered.fill(1, (y + row) * width + x, (y + row) * width + x + img.width);
        }
    }
    assert.equal(covered.indexOf(0), -1, 'the final step\'s patches cover every pixel');

    // The same state rendered whole by the HTTP API (byte-identical to a whole frame): rsm_gather's
    // tiles equal the whole frame exactly, so the composition must too.
    const state = (await controller.inbox.nextOfType('state', 'state', 1).catch(() => null))?.state
        ?? controller.welcome.state;
    const body = JSON.stringify({ scene: 'builtin:cornell', technique: 'rsm_gather', params: finalFrames.at(-1).stats.params,
        size: SIZE, format: 'png', camera: state.camera });
    const res = await server.http('/api/render', { method: 'POST', body, headers: { 'Content-Type': 'application/json' } });
    assert.equal(res.status, 200, `POST /api/render: ${res.body.toString().slice(0, 300)}`);
    const whole = decodePng(res.body);
    let worst = 0, sum = 0;
    for (let i = 0; i < composed.length; i++) {
        if (i % 4 === 3) continue;
        const d = Math.abs(composed[i] - whole.rgba[i]);
        worst = Math.max(worst, d);
        sum += d;
    }
    const mean = sum / (width * height * 3);
    assert.ok(worst <= 2 && mean < 0.05, `composed patches against the whole image: max ${worst}, mean ${mean.toFixed(4)} of 255`);

    // A viewer that does not draw patches joins the still view: it is sent the image whole again.
    const viewer = await Client.open(server, { view: controller.welcome.view_token, codecs: ['png'] });
    clients.push(viewer);
    const resent = await viewer.frame('the image whole for the viewer', (s) => s.quality === 'final');
    assert.equal(resent.stats.patch, undefined, 'no patch to a viewer that did not ask for them');
    const img = decodePng(resent.payload);
    assert.deepEqual([img.width, img.height], SIZE);
    assert.ok(img.rgba.equals(Buffer.from(composed.map((v, i) => (i % 4 === 3 ? img.rgba[i] : v)))),
        'the whole image the viewer gets is the composed one');
});
