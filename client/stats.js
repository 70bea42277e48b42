// Client-side frame statistics: frame rate, input-to-frame latency, network time and the rolling
// per-pass history behind the stacked timing chart. Pure (times are passed in, in milliseconds
// of one clock such as performance.now()), so node's test runner checks it.
import { estimatedRenderStart, PendingInputs } from './inputs.js';

/** Frames drawn within the last `windowMs`. */
export class RateCounter {
    constructor(windowMs = 1000) {
        this.windowMs = windowMs;
        this.times = [];
    }

    tick(now) {
        this.times.push(now);
        this.rate(now);
    }

    rate(now) {
        while (this.times.length && this.times[0] <= now - this.windowMs) this.times.shift();
        return (this.times.length * 1000) / this.windowMs;
    }
}

function median(values) {
    if (!values.length) return null;
    const s = [...values].sort((a, b) => a - b);
    const m = s.length >> 1;
    return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2;
}

/**
 * Input-to-frame latency: the time from a steering input (camera, light, parameters...) to the
 * first drawn frame that shows it, by the input number the frame echoes (`stats.input_seq`), else
 * by its estimated render start (client/inputs.js). The latency is measured from the oldest input
 * the frame shows (what a user feels when a drag starts).
 */
export class LatencyTracker {
    constructor(keep = 15) {
        this.keep = keep;
        this.inputs = new PendingInputs();
        this.samples = [];
        this.last = null;
    }

    input(now, seq = null) {
        this.inputs.add(now, seq);
    }

    /** A frame that arrived at `arrivedAt` was drawn at `drawnAt`; returns its latency or null. */
    frameDrawn(arrivedAt, drawnAt, stats, rttMs = 0) {
        const oldest = this.inputs.takeShown({ inputSeq: stats?.input_seq,
            renderStart: estimatedRenderStart(arrivedAt, stats, rttMs) });
        if (oldest === null) return null;
        this.last = drawnAt - oldest;
        this.samples.push(this.last);
        if (this.samples.length > this.keep) this.samples.shift();
        return this.last;
    }

    /** The median of the recent samples (null before the first). */
    get typical() {
        return median(this.samples);
    }

    reset() {
        this.inputs.clear();
        this.samples.length = 0;
        this.last = null;
    }
}

/**
 * Network time of a frame: half the ping round trip (the way there) plus the time between its
 * stats and its binary arriving (the transfer of the image, the stats being sent just before it).
 */
export function networkMs(rttMs, statsArrivedAt, binaryArrivedAt) {
    const transfer = Number.isFinite(statsArrivedAt) && Number.isFinite(binaryArrivedAt)
        ? Math.max(0, binaryArrivedAt - statsArrivedAt) : 0;
    return (Number.isFinite(rttMs) ? rttMs / 2 : 0) + transfer;
}

/**
 * The connection's round trip as frames' timing needs it: the least of the last few pings' round
 * trips. A ping whose answer waited behind a stall (a frozen network, a proxy holding messages)
 * measures the stall, not the way; taken as the round trip, it put every frame drawn after the
 * stall's end before the input it answered, and the page then said "rendering…" for input no
 * later frame would ever be counted as answering.
 */
export class RoundTrip {
    constructor(samples = 8) {
        this.samples = samples;
        this.recent = [];
    }

    /** Adds a ping's round trip (ms); returns the estimate. Not finite or negative: ignored. */
    add(ms) {
        if (Number.isFinite(ms) && ms >= 0) {
            this.recent.push(ms);
            if (this.recent.length > this.samples) this.recent.shift();
        }
        return this.ms;
    }

    reset() {
        this.recent = [];
    }

    /** The estimate (ms), or null before any ping came back. */
    get ms() {
        return this.recent.length ? Math.min(...this.recent) : null;
    }
}

/** A pass's time: its GPU time where measured, else its CPU time. */
export function passMs(pass) {
    if (Number.isFinite(pass?.gpu_ms)) return pass.gpu_ms;
    if (Number.isFinite(pass?.cpu_ms)) return pass.cpu_ms;
    return 0;
}

/**
 * The per-pass times of the last `windowS` seconds: push(tSeconds, stats.passes) per frame,
 * series(now) for the chart.
 */
export class PassHistory {
    constructor(windowS = 10) {
        this.windowS = windowS;
        this.samples = []; // {t, values: Map name -> ms}
        this.version = 0; // changes whenever the samples do: a chart drawn at this version is current
    }

    push(t, passes) {
        this.samples.push({ t, values: new Map((passes ?? []).map((p) => [p.name, passMs(p)])) });
        this.version += 1;
        this.prune(t);
    }

    prune(now) {
        const end = this.windowEnd(now);
        const before = this.samples.length;
        while (this.samples.length && this.samples[0].t < end - this.windowS) this.samples.shift();
        if (this.samples.length !== before) this.version += 1;
    }

    /**
     * Where the chart's window ends: now while frames arrive, else at the newest frame, so a still
     * view (or a stalled server) keeps its last seconds on the chart instead of scrolling them out.
     */
    windowEnd(now) {
        const newest = this.samples.at(-1)?.t;
        return newest !== undefined && newest < now - this.windowS ? newest : now;
    }

    /** Seconds since the newest sample, or null without one. */
    ageS(now) {
        const newest = this.samples.at(-1)?.t;
        return newest === undefined ? null : now - newest;
    }

    clear() {
        this.samples.length = 0;
        this.version += 1;
    }

    /** Pass names in pipeline order: the newest frame's order, then names only older frames had. */
    names() {
        const names = [];
        for (let i = this.samples.length - 1; i >= 0; --i) {
            for (const name of this.samples[i].values.keys()) if (!names.includes(name)) names.push(name);
        }
        return names;
    }

    /**
     * {names, times, values, stacked}: values[k][i] is pass k's time in frame i (0 where the frame
     * had no such pass); stacked[k][i] the sum of passes 0..k, the top of pass k's band.
     */
    series() {
        const names = this.names();
        const times = this.samples.map((s) => s.t);
        const values = names.map((n) => this.samples.map((s) => s.values.get(n) ?? 0));
        return { names, times, values, stacked: stackSeries(values) };
    }
}

/**
 * When the overlay's pass chart redraws. Every `periodMs` while no input waits for its frame; while one
 * waits, not before that frame is drawn (and then just after it is shown: `onFrameDrawn`), so that a
 * redraw of the chart, several ms of the page's main thread on a busy machine, never holds up the
 * key's handling or the frame's decode and draw; at most `maxDeferMs` after the last redraw all the same
 * (a server that stalls leaves input waiting, and the chart then says so).
 */
export class ChartSchedule {
    constructor({ periodMs = 250, maxDeferMs = 1000 } = {}) {
        this.periodMs = periodMs;
        this.maxDeferMs = maxDeferMs;
        this.drawnAt = -Infinity;
    }

    /** On the overlay's tick at `now` (ms): whether to redraw now; `pending`: an input awaits its frame. */
    onTick(now, pending) {
        const since = now - this.drawnAt;
        // A tick a little early on its timer is still the next tick, not one to skip.
        if (since < this.periodMs * 0.8) return false;
        return !pending || since >= this.maxDeferMs;
    }

    /** After a frame is drawn at `now`: whether a redraw is due, to be run once the frame is shown. */
    onFrameDrawn(now) {
        return now - this.drawnAt >= this.periodMs;
    }

    drawn(now) {
        this.drawnAt = now;
    }
}

/** Running sums over the series: out[k][i] = values[0][i] + ... + values[k][i]. */
export function stackSeries(values) {
    const out = [];
    values.forEach((row, k) => {
        out.push(row.map((v, i) => (k === 0 ? 0 : out[k - 1][i]) + (Number.isFinite(v) ? v : 0)));
    });
    return out;
}

/** The chart's y-axis labels: "0 ms", "50 ms", "1.5 ms". */
export function msTickLabels(ticks) {
    return ticks.map((t) => `${Number(t.toPrecision(4))} ms`);
}

/** Pixels the y axis needs for `labels` in a font of `charPx` per character, plus the tick. */
export function axisSize(labels, charPx = 6) {
    const longest = Math.max(4, ...(labels ?? []).map((l) => String(l ?? '').length));
    return Math.ceil(longest * charPx + 10);
}

export function formatMs(v, digits = 1) {
    return Number.isFinite(v) ? `${v.toFixed(digits)} ms` : '–';
}

export function formatBytes(n) {
    if (!Number.isFinite(n)) return '–';
    if (n < 1024) return `${n} B`;
    if (n < 1024 * 1024) return `${(n / 1024).toFixed(1)} KB`;
    return `${(n / 1024 / 1024).toFixed(2)} MB`;
}

/** Drawn triangles; for a scene with instanced meshes also how many are held, in how many placements. */
export function trianglesText(counts) {
    if (counts?.triangles === undefined) return '–';
    if (!counts.instances) return String(counts.triangles);
    return `${counts.triangles} (${counts.triangles_stored} held, ${counts.instances} instances)`;
}
