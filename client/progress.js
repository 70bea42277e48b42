// What the page says while the server works: refinement progress (protocol 2's `stats.refine`
// and `progress` messages), a frame that is late after input ("rendering… 1.2 s"), and whether
// the overlay's figures still describe what is on screen. Pure (times in ms of one clock such as
// performance.now()), so node's test runner checks it.
import { PendingInputs } from './inputs.js';

/** How long "done", "abandoned" and "skipped" stay up. */
// A load's line stays until the load ends (`loaded` or `load_failed` replaces it), up to two minutes.
export const FLASH_MS = Object.freeze({ done: 3000, abandoned: 4000, skipped: 8000, loading: 120000, loaded: 4000 });
// A figure this much older than pending input is stale even while frames are not late.
export const STALE_AFTER_MS = 2000;
// The frame target when the server names none (protocol 1 and older protocol 2 servers).
export const DEFAULT_FRAME_TARGET_MS = 80;

/** "1.2 s" (under a minute), "1 min 5 s" after. */
export function formatSeconds(ms) {
    const s = Math.max(0, ms) / 1000;
    if (s < 60) return `${s.toFixed(1)} s`;
    return `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
}

/** The step that runs: {step, share, etaMs, at}, from `refine` stats or a `progress` message. */
function runningStep(step, share, etaMs, now) {
    return { step, share: Number.isFinite(share) ? share : 0, etaMs: Number.isFinite(etaMs) ? etaMs : null, at: now };
}

const percent = (share) => `${Math.round(100 * Math.min(1, Math.max(0, share)))} %`;

/**
 * Refinement of the still view: fed with every frame's stats and every `progress` message, it
 * says which step runs, how much of the image is done and how long is left, and for a moment
 * afterwards whether refinement finished, was abandoned by input or skipped a step.
 */
export class RefineTracker {
    constructor() {
        this.current = null; // {step, share, etaMs, at}: the step that runs
        this.flash = null; // {kind, text, until}
    }

    reset() {
        this.current = null;
        this.flash = null;
    }

    /** A frame's stats: `refine` on balanced and final tiles; an interactive frame means input came. */
    stats(stats, now) {
        const r = stats?.refine;
        if (r && typeof r === 'object') {
            const step = r.step ?? stats.quality;
            if (r.complete === true) {
                // The next step announces itself ('refining'), or is skipped, or this was the last.
                if (step === 'final') this.finish(now);
                else this.current = null;
                return;
            }
            this.current = runningStep(step, r.share, r.eta_ms, now);
            return;
        }
        if (stats?.quality === 'interactive' || stats?.quality === 'fixed') this.current = null;
    }

    /** A `progress` message: {state, step, share, eta_ms, reason}. */
    message(msg, now) {
        const reason = typeof msg?.reason === 'string' && msg.reason ? msg.reason : '';
        switch (msg?.state) {
        case 'refining':
            this.current = runningStep(msg.step, msg.share, msg.eta_ms, now);
            break;
        case 'done':
            this.finish(now);
            break;
        case 'abandoned':
            this.current = null;
            this.flash = { kind: 'abandoned', text: `refinement abandoned${reason ? `: ${reason}` : ' (input)'}`,
                until: now + FLASH_MS.abandoned };
            break;
        case 'loading': {
            // A scene load: no refinement runs meanwhile; it says what is loading until it ends. A long
            // load repeats the message with how far it got (share > 0) and the time left.
            this.current = null;
            const share = Number.isFinite(msg.share) && msg.share > 0 ? Math.min(1, msg.share) : null;
            const eta = share !== null && Number.isFinite(msg.eta_ms) && msg.eta_ms > 0 ? msg.eta_ms : null;
            this.flash = { kind: 'loading', text: reason || 'loading the scene', share, etaMs: eta, at: now,
                until: now + FLASH_MS.loading };
            break;
        }
        case 'loaded':
            this.flash = { kind: 'loaded', text: reason || 'scene loaded', until: now + FLASH_MS.loaded };
            break;
        case 'load_failed':
            // The error message that follows says why.
            if (this.flash?.kind === 'loading') this.flash = null;
            break;
        case 'skipped':
            // A step is skipped between steps: nothing runs until the next 'refining'.
            this.current = null;
            this.flash = { kind: 'skipped', text: `skipped ${msg.step ?? 'a step'}${reason ? `: ${reason}` : ''}`,
                until: now + FLASH_MS.skipped };
            break;
        default:
            break;
        }
    }

    finish(now) {
        this.current = null;
        // A skipped step says more than "done": it stays up for its own time.
        if (this.flash?.kind === 'skipped' && this.flash.until > now) return;
        this.flash = { kind: 'done', text: 'refined: final quality', until: now + FLASH_MS.done };
    }

    get refining() {
        return this.current !== null;
    }

    /**
     * What to show at `now`: null, or {kind: 'refining' | 'done' | 'abandoned' | 'skipped' | 'loading' |
     * 'loaded', text, share (0..1: refining, and loading once the server said how far it got, else
     * null)}. The time left counts down between messages.
     */
    view(now) {
        if (this.flash && this.flash.until <= now) this.flash = null;
        const c = this.current;
        if (!c) {
            const f = this.flash;
            if (!f) return null;
            if (f.kind !== 'loading' || f.share == null) return { kind: f.kind, text: f.text, share: null };
            const parts = [f.text, percent(f.share)];
            if (f.etaMs !== null) parts.push(`${formatSeconds(Math.max(0, f.etaMs - (now - f.at)))} left`);
            return { kind: 'loading', text: parts.join(' · '), share: f.share };
        }
        const parts = [`refining ${c.step ?? '…'}`, percent(c.share)];
        if (c.etaMs !== null) parts.push(`${formatSeconds(Math.max(0, c.etaMs - (now - c.at)))} left`);
        // A step skipped before this one ("skipped balanced: over budget") stays readable.
        if (this.flash?.kind === 'skipped') parts.push(this.flash.text);
        return { kind: 'refining', text: parts.join(' · '), share: c.share };
    }
}

/**
 * Steering input against the frames drawn: whether input waits for a frame that can show it, how
 * late that frame is, and whether the figures on screen are stale.
 */
export class InputWatch {
    constructor() {
        this.inputs = new PendingInputs();
        this.lastDrawnAt = null;
    }

    reset() {
        this.inputs.clear();
        this.lastDrawnAt = null;
    }

    /** A steering input sent at `now`, numbered `seq` (its message's `seq`). */
    input(now, seq = null) { this.inputs.add(now, seq); }

    /**
     * A frame was drawn at `now`: the inputs it shows no longer wait. `inputSeq` is its
     * `stats.input_seq`; `renderStart`, its estimated render start, decides where the server does
     * not echo one (client/inputs.js).
     */
    frameDrawn(renderStart, now, inputSeq = undefined) {
        this.lastDrawnAt = now;
        this.inputs.takeShown({ inputSeq, renderStart });
    }

    /** When the oldest input no drawn frame shows was sent; null when none waits. */
    get pendingSince() {
        return this.inputs.oldestAt;
    }

    get pending() {
        return this.pendingSince !== null;
    }

    /**
     * ms that input has waited without any frame arriving, once that is over twice the frame
     * target; else null. Frames that keep coming during a drag are not late even when each is
     * a little behind the input.
     */
    lateMs(now, frameTargetMs = DEFAULT_FRAME_TARGET_MS) {
        if (this.pendingSince === null) return null;
        const quietSince = Math.max(this.pendingSince, this.lastDrawnAt ?? -Infinity);
        return now - quietSince > 2 * frameTargetMs ? now - this.pendingSince : null;
    }

    /** True when the frame on screen predates input that has waited too long for a frame to show it. */
    stale(now, frameTargetMs = DEFAULT_FRAME_TARGET_MS) {
        if (this.pendingSince === null || this.lastDrawnAt === null) return false;
        return this.lateMs(now, frameTargetMs) !== null || now - this.pendingSince > STALE_AFTER_MS;
    }
}

/**
 * The busy badge: "rendering… 1.2 s" when a frame is late after input, else the refinement's
 * text while it runs; null when the server is not keeping anyone waiting.
 */
export function busyText({ lateMs = null, refine = null }) {
    if (lateMs !== null) return `rendering… ${formatSeconds(lateMs)}`;
    if (refine?.kind === 'refining' || refine?.kind === 'loading') return refine.text;
    return null;
}
