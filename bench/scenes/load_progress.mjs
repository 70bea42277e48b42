// What a client sees while a big scene loads: exports a generated courtyard as .glb (gi-render
// --export), offers its folder with --scene-dir, asks a session for it and prints every `progress`
// message of the load with its time since the request (docs/scenes.md, "Loading").
// --textures N instead loads N quads, each with a texture of its own (--side x --side pixels), to see
// how the GL upload of many textures is sliced (state.load.upload_slices, upload_slice_max_ms).
// usage: node bench/scenes/load_progress.mjs [--scene builtin:atrium-2000k | FILE.glb | --textures N
//        [--side 2048]] [--bin build/ci/bin]
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const args = process.argv.slice(2);
const option = (name, fallback) => {
    const i = args.indexOf(name);
    return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
if (args.includes('--help')) {
    console.log('usage: node bench/scenes/load_progress.mjs [--scene builtin:NAME | FILE.glb | --textures N [--side S]]'
        + ' [--bin DIR]');
    process.exit(0);
}
const scene = option('--scene', 'builtin:atrium-2000k');
const bin = path.resolve(option('--bin', 'build/ci/bin'));
const dir = mkdtempSync(path.join(os.tmpdir(), 'gi-load-progress-'));
const file = path.join(dir, 'scene.glb');
const textures = Number(option('--textures', '0'));
if (textures > 0) {
    const { slowToLoadGlb, texturedQuadsGlb } = await import('../../tests/e2e/glb.mjs');
    writeFileSync(file, texturedQuadsGlb(slowToLoadGlb(Number(option('--side', '2048'))), textures));
} else if (scene.startsWith('builtin:')) {
    execFileSync(path.join(bin, 'gi-render'), ['--scene', scene, '--export', file, '--quiet']);
} else {
    copyFileSync(scene, file);
}
process.env.GI_SERVER ??= path.join(bin, 'gi-server');
// After GI_SERVER is set: the helpers read it when they load.
const { Client, ServerProcess } = await import('../../tests/e2e/helpers.mjs');
const server = await ServerProcess.start(['--size', '64x64', '--scene-dir', dir, '--max-decoded-mb', '4096']);
try {
    const client = await Client.open(server, { adaptive: false });
    const t0 = performance.now();
    client.send({ type: 'scene', name: 'file:scene.glb' });
    for (;;) {
        const m = await client.inbox.next((x) => x.type === 'progress' && x.step === 'scene', 'scene progress', 120000);
        console.log(`${(performance.now() - t0).toFixed(0).padStart(6)} ms  ${m.state}  share ${m.share.toFixed(2)}`
            + `  eta ${Math.round(m.eta_ms)} ms  ${m.reason}`);
        if (m.state !== 'loading') break;
    }
    const state = await client.inbox.next((x) => x.type === 'state' && x.state?.load, 'state', 120000);
    const stateAt = performance.now() - t0;
    console.log(`${stateAt.toFixed(0).padStart(6)} ms  state  load ${JSON.stringify(state.state.load)}`);
    await client.close();
} finally {
    await server.stop();
    rmSync(dir, { recursive: true, force: true });
}
