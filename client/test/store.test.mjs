// The store's topics: subscribers hear emits in order, can leave, and one that throws does not
// silence the rest.
import { test } from 'node:test';
import assert from 'node:assert/strict';

import { Store } from '../store.js';

test('subscribers hear their topic in order and may leave', () => {
    const store = new Store({ scene: 'a' });
    const heard = [];
    const off = store.on('scenes', (x) => heard.push(['first', x, store.state.scene]));
    store.on('scenes', (x) => heard.push(['second', x]));
    store.on('params', () => heard.push(['params']));
    store.state.scene = 'b';
    store.emit('scenes', 1);
    off();
    store.emit('scenes', 2);
    store.emit('nobody');
    assert.deepEqual(heard, [['first', 1, 'b'], ['second', 1], ['second', 2]]);
    assert.deepEqual(store.topics(), ['params', 'scenes']);
});

test('a subscriber that throws does not silence the others', () => {
    const store = new Store();
    const heard = [];
    store.on('frame', () => {
        throw new Error('broken panel');
    });
    store.on('frame', () => heard.push('drawn'));
    assert.throws(() => store.emit('frame'), /broken panel/);
    assert.deepEqual(heard, ['drawn']);
});
