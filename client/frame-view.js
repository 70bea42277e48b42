// Frames on the view: the binary frame header read, at most one decode in flight (a whole frame
// replaces those waiting, patches queue in order: frames.js), decoded off the main thread and drawn
// whole or as a patch of a refining image, every frame acknowledged on the connection that brought it,
// and a requested snapshot saved as it arrives. `onDrawn(frame, decodeMs, bytes)` follows each draw.
import { createFrameDecoder } from './decode.js';
import { enqueueFrame, patchPlacement } from './frames.js';
import { ackMsg, CODEC_MIME, parseFrameHeader } from './protocol.js';

export function createFrameView({ ui, state, connection, send, showMessage, onDrawn }) {
    const ctx = ui.canvas.getContext('2d');
    const decoder = createFrameDecoder();
    let lastWay = null; // how the last frame was decoded (decode.js)

    function handleBinary(buffer) {
        const arrivedAt = performance.now();
        let header;
        try {
            header = parseFrameHeader(buffer);
        } catch (e) {
            showMessage(`Bad frame from the server: ${e.message}`);
            return;
        }
        const entry = state.statsByFrame.get(header.frame);
        state.statsByFrame.delete(header.frame);
        // The snapshot is saved as it arrives: the draw queue below may skip frames.
        if (state.snapshotWanted && entry?.stats?.snapshot) {
            state.snapshotWanted = false;
            saveSnapshot(header, buffer);
        }
        const frame = { header, buffer, entry, arrivedAt, socket: connection.socket };
        if (state.decoding) {
            // At most one decode in flight: a whole frame replaces those that wait (acknowledged so
            // their slots free), a patch waits its turn.
            const { queue, dropped } = enqueueFrame(state.pending, frame);
            dropped.forEach(acknowledge);
            state.pending = queue;
            return;
        }
        decodeAndDraw(frame);
    }

    async function decodeAndDraw(frame) {
        state.decoding = true;
        const { header, buffer } = frame;
        let decoded = null;
        try {
            const started = performance.now();
            const payload = new Uint8Array(buffer, header.payloadOffset);
            // Decoded off the main thread (decode.js); the draw below is a copy.
            decoded = await decoder.decode(payload, CODEC_MIME[header.codec]);
            lastWay = decoded.way;
            const { image } = decoded;
            const decodeMs = performance.now() - started;
            if (frame.socket === connection.socket) {
                const patch = patchPlacement(frame.entry?.stats, header);
                if (frame.entry?.stats?.patch && !patch) {
                    // Drawn as a whole frame it would stretch a region over the view.
                    showMessage(`Frame ${header.frame}: a patch outside its image was not drawn.`);
                } else if (patch) {
                    // A region of a refining image: the picture so far, stretched to the image's size,
                    // under it.
                    if (ui.canvas.width !== patch.width || ui.canvas.height !== patch.height) {
                        const before = await createImageBitmap(ui.canvas);
                        ui.canvas.width = patch.width;
                        ui.canvas.height = patch.height;
                        ctx.drawImage(before, 0, 0, patch.width, patch.height);
                        before.close();
                    }
                    ctx.drawImage(image, patch.x, patch.y);
                } else {
                    if (ui.canvas.width !== header.width || ui.canvas.height !== header.height) {
                        ui.canvas.width = header.width;
                        ui.canvas.height = header.height;
                    }
                    ctx.drawImage(image, 0, 0, header.width, header.height);
                }
                onDrawn(frame, decodeMs, buffer.byteLength);
            }
        } catch (e) {
            showMessage(`Frame ${header.frame} could not be decoded: ${e.message}`);
        } finally {
            decoded?.close();
            // Acknowledge even a frame that failed to decode, else the server would wait forever.
            acknowledge(frame);
            state.decoding = false;
            const next = state.pending.shift();
            if (next) decodeAndDraw(next);
        }
    }

    function acknowledge(frame) {
        // An ack belongs to the connection that received the frame; after a reconnect it means nothing.
        if (frame.socket === connection.socket) send(ackMsg(frame.header.frame));
    }

    function saveSnapshot(header, buffer) {
        const blob = new Blob([new Uint8Array(buffer, header.payloadOffset)], { type: CODEC_MIME[header.codec] });
        const scene = (state.scene || 'scene').replace(/[^A-Za-z0-9_-]+/g, '-');
        const link = Object.assign(document.createElement('a'), {
            href: URL.createObjectURL(blob),
            download: `gi-${scene}-${state.technique ?? 'frame'}-${header.frame}.${header.codec}`,
        });
        document.body.append(link);
        link.click();
        link.remove();
        showMessage(`Snapshot saved: ${link.download} (${header.width}×${header.height}, lossless)`, 'info');
        // The download has started from the object URL by the time the timer runs.
        setTimeout(() => URL.revokeObjectURL(link.href), 1000);
    }

    return { handleBinary, get decodedBy() { return lastWay; } };
}
