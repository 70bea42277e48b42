// Session lifecycle under repetition: connect, first frame, close, many times over. Every session's
// teardown (joining its render thread, freeing its GL context) must finish, and the server's memory
// must stop growing once the allocator has warmed up. bench/load/ runs the long version (1000 cycles).
// Run: GI_SERVER=build/dev/bin/gi-server node --test tests/e2e/lifecycle.test.mjs
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';

import { Client, REPO, ServerProcess, sleep } from './helpers.mjs';

const WARMUP_CYCLES = 10;
const MEASURED_CYCLES = 30;
// llvmpipe's caches settle during the warm-up, and the server hands freed heap back to the system
// once teardowns drain, so the resident size between sessions is what is still live: it moved by
// under 2 MiB over 30 cycles in repeated runs (untrimmed, the allocator's arenas kept 50-70 MiB
// more or less depending on thread timing). A leaked session (GL context, renderer, threads) costs
// about 15 MiB, so two leaked sessions in 30 exceed this bound.
const RSS_GROWTH_LIMIT_MIB = 24;

let server = null;

before(async () => {
    server = await ServerProcess.start(['--scene', 'builtin:cornell', '--technique', 'none', '--size', '32x32',
        '--client-dir', path.join(REPO, 'client')]);
});

after(async () => {
    await server?.stop();
});

function rssMiB(pid) {
    const match = /^VmRSS:\s+(\d+)\s+kB/m.exec(readFileSync(`/proc/${pid}/status`, 'utf8'));
    return match ? Number(match[1]) / 1024 : NaN;
}

async function cycle(i) {
    const client = await Client.open(server, { size: [32, 32], adaptive: false, client: `cycle-${i}` });
    await client.frame(`cycle ${i}: first frame`);
    await client.close();
}

async function waitForTeardowns() {
    const deadline = Date.now() + 10000;
    let health = null;
    while (Date.now() < deadline) {
        health = await server.health();
        if (health.sessions === 0 && health.teardowns_pending === 0) return health;
        await sleep(50);
    }
    assert.fail(`sessions or teardowns did not drain: ${JSON.stringify(health)}`);
}

test('connect/close cycles free every session and the memory stops growing', async () => {
    for (let i = 0; i < WARMUP_CYCLES; ++i) await cycle(i);
    await waitForTeardowns();
    const before = rssMiB(server.proc.pid);
    for (let i = 0; i < MEASURED_CYCLES; ++i) {
        await cycle(WARMUP_CYCLES + i);
        // Closing with 1000 ends the session at once; its teardown runs on the reaper thread.
        if (i % 10 === 9) await waitForTeardowns();
    }
    await waitForTeardowns();
    const afterCycles = rssMiB(server.proc.pid);
    console.log(`RSS ${before.toFixed(1)} -> ${afterCycles.toFixed(1)} MiB over ${MEASURED_CYCLES} cycles`);
    assert.ok(afterCycles - before < RSS_GROWTH_LIMIT_MIB,
        `RSS grew ${(afterCycles - before).toFixed(1)} MiB over ${MEASURED_CYCLES} cycles (limit ${RSS_GROWTH_LIMIT_MIB})`);
    const metrics = (await server.http('/metrics')).body.toString();
    assert.match(metrics, /^gis_sessions_started_total 40$/m);
    const reported = /^process_resident_memory_bytes (\d+(?:\.\d+)?(?:e\+\d+)?)$/m.exec(metrics);
    assert.ok(reported, 'metrics report the resident size');
    const reportedMiB = Number(reported[1]) / (1024 * 1024);
    assert.ok(Math.abs(reportedMiB - afterCycles) < 16,
        `process_resident_memory_bytes says ${reportedMiB.toFixed(1)} MiB, /proc says ${afterCycles.toFixed(1)}`);
    assert.match(metrics, /^gis_teardowns_pending 0$/m);
});
