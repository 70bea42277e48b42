// Streaming benchmark (not a test): starts gi-server, connects one WebSocket client that orbits the
// camera on every frame it acknowledges, and reports the frames per second the client saw, with the
// median render, encode and round-trip times.
// usage: node bench/stream_fps.mjs [--server build/release/bin/gi-server] [--size 512x512]
//        [--technique rsm_gather] [--seconds 10] [--gl egl|osmesa] [--codec jpeg|webp|png]
//        [--param name=value ...]
import { spawn } from 'node:child_process';
import net from 'node:net';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import WebSocket from 'ws';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const opts = { server: path.join(root, 'build/release/bin/gi-server'), size: '512x512', technique: 'rsm_gather',
               seconds: 10, gl: process.env.GI_GL || 'egl', codec: 'jpeg', params: {} };
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; i++) {
    const key = argv[i].replace(/^--/, '');
    const value = argv[++i];
    if (value === undefined) throw new Error(`--${key} needs a value`);
    if (key === 'param') {
        const [k, v] = value.split('=');
        opts.params[k] = Number.isNaN(Number(v)) ? v : Number(v);
    } else if (key in opts) {
        opts[key] = key === 'seconds' ? Number(value) : value;
    } else {
        throw new Error(`unknown option --${key}`);
    }
}
const [width, height] = opts.size.split('x').map(Number);

const freePort = () => new Promise((resolve) => {
    const s = net.createServer().listen(0, '127.0.0.1', () => { const p = s.address().port; s.close(() => resolve(p)); });
});
const median = (v) => { const s = [...v].sort((a, b) => a - b); return s.length ? s[Math.floor(s.length / 2)] : 0; };

const port = await freePort();
const server = spawn(opts.server, ['--host', '127.0.0.1', '--port', String(port), '--gl', opts.gl,
                                   '--technique', opts.technique, '--client-dir', path.join(root, 'client')],
                     { stdio: ['ignore', 'ignore', 'inherit'] });
for (let i = 0; i < 100; i++) {
    try { if ((await fetch(`http://127.0.0.1:${port}/healthz`)).ok) break; } catch { /* not up yet */ }
    await new Promise((r) => setTimeout(r, 100));
}

const ws = new WebSocket(`ws://127.0.0.1:${port}/ws`, 'gi-stream');
const render = [], encode = [], roundTrip = [];
let frames = 0, start = 0, angle = 0, sentAt = 0, lastStats = null;
const sendCamera = () => {
    angle += 0.02;
    sentAt = performance.now();
    ws.send(JSON.stringify({ type: 'camera', position: [3.9 * Math.sin(angle), 1, 3.9 * Math.cos(angle)], target: [0, 1, 0] }));
};
ws.on('open', () => {
    // Fixed quality: the benchmark measures the requested state, not the adaptive steps.
    ws.send(JSON.stringify({ type: 'hello', protocol: 1, client: 'stream_fps', codecs: [opts.codec], adaptive: false,
                             size: [width, height] }));
    if (Object.keys(opts.params).length) ws.send(JSON.stringify({ type: 'params', values: opts.params }));
});
ws.on('message', (data, isBinary) => {
    if (!isBinary) {
        const m = JSON.parse(data.toString());
        if (m.type === 'error') console.error('server error:', m.message);
        if (m.type === 'stats') lastStats = m;
        return;
    }
    const id = data.readUInt32LE(4);
    ws.send(JSON.stringify({ type: 'ack', frame: id }));
    if (lastStats && lastStats.size[0] === width && lastStats.size[1] === height) {
        if (!start) start = performance.now();
        else {
            frames++;
            render.push(lastStats.frame_ms);
            encode.push(lastStats.encode_ms);
            roundTrip.push(performance.now() - sentAt);
        }
    }
    if (start && performance.now() - start > opts.seconds * 1000) {
        const elapsed = (performance.now() - start) / 1000;
        console.log(JSON.stringify({
            technique: opts.technique, size: [width, height], gl: opts.gl, params: opts.params,
            frames, fps: +(frames / elapsed).toFixed(2), median_render_ms: +median(render).toFixed(1),
            median_encode_ms: +median(encode).toFixed(2), codec: lastStats.codec, median_input_to_frame_ms: +median(roundTrip).toFixed(1),
            bytes_per_frame: lastStats.bytes,
        }));
        ws.close();
        server.kill('SIGTERM');
        return;
    }
    sendCamera();
});
ws.on('close', () => process.exit(0));
