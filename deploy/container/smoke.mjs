// Smoke check of a running gi-server (deploy/container/host-run.sh): a session over the WebSocket
// (hello, welcome, one frame), then SIGTERM to the server while the session is open: the client
// must get `shutdown`, and closes as a well-behaved client does, so the drain ends early.
//
//   node deploy/container/smoke.mjs --url ws://127.0.0.1:PORT/ws --pid PID
import WebSocket from 'ws';

const args = process.argv.slice(2);
const option = (name) => {
    const i = args.indexOf(name);
    return i >= 0 ? args[i + 1] : undefined;
};
const url = option('--url');
const pid = Number(option('--pid'));
if (!url || !(pid > 0)) {
    console.error('usage: node deploy/container/smoke.mjs --url ws://HOST:PORT/ws --pid PID');
    process.exit(2);
}

const fail = (why) => {
    console.error(`smoke: FAIL: ${why}`);
    process.exit(1);
};
const timer = setTimeout(() => fail('no result within 60 s'), 60000);

const ws = new WebSocket(url, 'gi-stream');
const seen = [];
ws.on('error', (e) => fail(`WebSocket error: ${e.message}`));
ws.on('open', () => ws.send(JSON.stringify({ type: 'hello', protocol: 1, client: 'gi-smoke', adaptive: false, size: [64, 64] })));
ws.on('message', (data, binary) => {
    if (binary) {
        const frame = data.readUInt32LE(4);
        ws.send(JSON.stringify({ type: 'ack', frame }));
        if (!seen.includes('frame')) {
            seen.push('frame');
            console.log(`smoke: frame ${frame} (${data.length} bytes); sending SIGTERM to ${pid}`);
            process.kill(pid, 'SIGTERM');
        }
        return;
    }
    const msg = JSON.parse(data.toString());
    if (msg.type === 'welcome') {
        seen.push('welcome');
        console.log(`smoke: welcome, session ${msg.session}, ${msg.techniques.length} techniques`);
    } else if (msg.type === 'shutdown') {
        seen.push('shutdown');
        console.log(`smoke: shutdown, grace ${msg.grace_s} s; closing`);
        ws.close(1000, 'done');
    } else if (msg.type === 'error') {
        fail(`error ${msg.code}: ${msg.message}`);
    }
});
ws.on('close', (code) => {
    clearTimeout(timer);
    const want = ['welcome', 'frame', 'shutdown'];
    if (want.some((w) => !seen.includes(w))) fail(`closed (${code}) after [${seen}], expected [${want}]`);
    console.log('smoke: ok');
    process.exit(0);
});
