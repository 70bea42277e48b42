// Which steering inputs a drawn frame shows. The client numbers its steering messages (`seq`) and
// the server echoes in each frame the highest number its state includes (`stats.input_seq`,
// protocol/PROTOCOL.md), which settles it exactly. Against a server that does not echo, the frame's
// render start is estimated on the client's clock (its arrival less the round trip and the
// server's render and encode times) and inputs sent before it count as shown.

/** The render start of a frame that arrived at `arrivedAt`, as the latency estimates it. */
export function estimatedRenderStart(arrivedAt, stats, rttMs = 0) {
    return arrivedAt - (rttMs ?? 0) - (stats?.frame_ms ?? 0) - (stats?.encode_ms ?? 0);
}

/** Steering inputs no drawn frame has shown yet, oldest first. */
export class PendingInputs {
    constructor(keep = 1000) {
        this.keep = keep;
        this.items = []; // {at, seq}; seq null for an input sent without a number
        // Set by the first frame that echoes a number: from then on a frame without one shows none
        // of the numbered inputs (its state predates them on this connection).
        this.echoed = false;
    }

    add(at, seq = null) {
        this.items.push({ at, seq: Number.isInteger(seq) ? seq : null });
        // A long stall without frames: drop the second oldest, so the oldest input's time stays.
        if (this.items.length > this.keep) this.items.splice(1, 1);
    }

    /** When the oldest input still waiting was sent; null when none waits. */
    get oldestAt() {
        return this.items.length ? this.items[0].at : null;
    }

    /**
     * A frame was drawn: removes the inputs it shows and returns the time of the oldest of them
     * (null: it shows none). `inputSeq` is the frame's `stats.input_seq`, `renderStart` the
     * estimate used when the server does not echo numbers.
     */
    takeShown({ inputSeq, renderStart }) {
        if (Number.isInteger(inputSeq)) this.echoed = true;
        let oldest = null;
        if (this.echoed) {
            // Numbers rise with each message, so the inputs shown are a prefix of the queue; an
            // unnumbered one counts as shown with the numbered input before it.
            while (this.items.length && Number.isInteger(inputSeq) &&
                (this.items[0].seq === null || this.items[0].seq <= inputSeq)) {
                oldest ??= this.items[0].at;
                this.items.shift();
            }
            return oldest;
        }
        while (this.items.length && this.items[0].at <= renderStart) {
            oldest ??= this.items[0].at;
            this.items.shift();
        }
        return oldest;
    }

    clear() {
        this.items.length = 0;
    }
}
