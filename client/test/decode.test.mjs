import { test } from 'node:test';
import assert from 'node:assert/strict';

import { createFrameDecoder } from '../decode.js';

// A page's decoders, recorded: which one decoded what, and what was closed.
function fakeScope({ secure = true, decoderTypes = ['image/jpeg', 'image/webp'], withDecoder = true } = {}) {
    const log = [];
    class FakeImageDecoder {
        static asked = [];
        static async isTypeSupported(type) {
            FakeImageDecoder.asked.push(type);
            return decoderTypes.includes(type);
        }
        constructor({ data, type }) {
            this.type = type;
            this.bytes = data.length;
        }
        async decode() {
            if (this.type === 'image/broken') throw new Error('bad data');
            log.push(`decoder ${this.type} ${this.bytes}`);
            return { image: { close: () => log.push(`frame closed ${this.type}`) } };
        }
        close() { log.push(`decoder closed ${this.type}`); }
    }
    const scope = {
        isSecureContext: secure,
        async createImageBitmap(blob) {
            log.push(`bitmap ${blob.type} ${blob.size}`);
            return { close: () => log.push(`bitmap closed ${blob.type}`) };
        },
    };
    if (withDecoder) scope.ImageDecoder = FakeImageDecoder;
    return { scope, log, FakeImageDecoder };
}

const bytes = new Uint8Array([1, 2, 3, 4]);

test('a secure page decodes the types ImageDecoder takes with it, straight from the bytes', async () => {
    const { scope, log, FakeImageDecoder } = fakeScope();
    const decoder = createFrameDecoder(scope);
    const jpeg = await decoder.decode(bytes, 'image/jpeg');
    assert.equal(jpeg.way, 'ImageDecoder');
    jpeg.close();
    const png = await decoder.decode(bytes, 'image/png');
    assert.equal(png.way, 'createImageBitmap', 'a type it does not take goes through a bitmap');
    png.close();
    await decoder.decode(bytes, 'image/jpeg');
    assert.deepEqual(log, ['decoder image/jpeg 4', 'decoder closed image/jpeg', 'frame closed image/jpeg',
        'bitmap image/png 4', 'bitmap closed image/png', 'decoder image/jpeg 4', 'decoder closed image/jpeg']);
    assert.deepEqual(FakeImageDecoder.asked, ['image/jpeg', 'image/png'], 'each type is asked about once');
});

test('a page that is not a secure context, or has no ImageDecoder, decodes through a bitmap', async () => {
    for (const options of [{ secure: false }, { withDecoder: false }]) {
        const { scope, log } = fakeScope(options);
        const decoded = await createFrameDecoder(scope).decode(bytes, 'image/jpeg');
        assert.equal(decoded.way, 'createImageBitmap', JSON.stringify(options));
        assert.deepEqual(log, ['bitmap image/jpeg 4']);
    }
});

test('a frame that fails to decode rejects and leaves no decoder open', async () => {
    const { scope, log } = fakeScope({ decoderTypes: ['image/broken'] });
    await assert.rejects(createFrameDecoder(scope).decode(bytes, 'image/broken'), /bad data/);
    assert.deepEqual(log, ['decoder closed image/broken']);
});

test('an ImageDecoder that cannot say what it takes leaves every type to the bitmap path', async () => {
    const { scope } = fakeScope();
    scope.ImageDecoder.isTypeSupported = () => Promise.reject(new Error('not allowed'));
    const decoded = await createFrameDecoder(scope).decode(bytes, 'image/jpeg');
    assert.equal(decoded.way, 'createImageBitmap');
});
