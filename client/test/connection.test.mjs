// StreamConnection against a fake WebSocket: a user's close is status 1000 (the server ends the
// session at once), a lost connection is retried, and a refused one stays closed.
import { afterEach, beforeEach, test } from 'node:test';
import assert from 'node:assert/strict';

import { BACKOFF_START_MS, StreamConnection } from '../connection.js';

class FakeWebSocket {
    static OPEN = 1;
    static instances = [];

    constructor(url, protocol) {
        Object.assign(this, { url, protocol, readyState: 0, sent: [], closedWith: null });
        FakeWebSocket.instances.push(this);
    }

    open() {
        this.readyState = FakeWebSocket.OPEN;
        this.onopen?.();
    }

    send(text) {
        this.sent.push(text);
    }

    close(code, reason) {
        this.closedWith = { code, reason };
        this.readyState = 3;
    }

    /** The server or the network closes it. */
    drop(code) {
        this.readyState = 3;
        this.onclose?.({ code });
    }
}

let savedWebSocket;
beforeEach(() => {
    savedWebSocket = globalThis.WebSocket;
    globalThis.WebSocket = FakeWebSocket;
    FakeWebSocket.instances = [];
});
afterEach(() => {
    globalThis.WebSocket = savedWebSocket;
});

function recorder() {
    const log = [];
    const handlers = {
        onOpen: () => log.push('open'),
        onClose: (code) => log.push(`close ${code}`),
        onState: (state) => log.push(`state ${state}`),
    };
    return { log, handlers };
}

test('a user close sends status 1000 and does not reconnect', (t) => {
    t.mock.timers.enable({ apis: ['setTimeout'] });
    const { log, handlers } = recorder();
    const conn = new StreamConnection('ws://h/ws', handlers);
    conn.connect();
    const socket = FakeWebSocket.instances[0];
    assert.equal(socket.protocol, 'gi-stream');
    socket.open();
    assert.ok(conn.send({ type: 'ping' }));
    assert.deepEqual(socket.sent, ['{"type":"ping"}']);
    conn.close();
    assert.equal(socket.closedWith?.code, 1000);
    assert.equal(conn.send({ type: 'ping' }), false, 'nothing is sent after the close');
    t.mock.timers.tick(60000);
    assert.equal(FakeWebSocket.instances.length, 1, 'no reconnect');
    assert.equal(log.at(-1), 'state closed');
});

test('a lost connection is retried after the backoff; a refused one is not', (t) => {
    t.mock.timers.enable({ apis: ['setTimeout'] });
    const { log, handlers } = recorder();
    const conn = new StreamConnection('ws://h/ws', handlers);
    conn.connect();
    FakeWebSocket.instances[0].open();
    FakeWebSocket.instances[0].drop(1006);
    assert.ok(log.includes('close 1006'), 'onClose gets the status');
    assert.equal(log.at(-1), 'state waiting');
    t.mock.timers.tick(BACKOFF_START_MS);
    assert.equal(FakeWebSocket.instances.length, 2, 'reconnected after the first backoff step');

    FakeWebSocket.instances[1].open();
    conn.stopReconnecting(); // e.g. after an unauthorized error
    FakeWebSocket.instances[1].drop(1008);
    t.mock.timers.tick(60000);
    assert.equal(FakeWebSocket.instances.length, 2, 'no reconnect after stopReconnecting');
    assert.equal(log.at(-1), 'state closed');
});
