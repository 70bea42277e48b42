// The stats overlay over the view: frame rate and input-to-frame latency, the per-pass chart and why
// it stopped, the refinement line, the busy badge, stale figures, the frame's times, size and codec,
// the frame budget line, the reconnect countdown and fading toasts. main.js calls it as frames arrive
// and four times a second; it emits rate (the accuracy view refreshes its line).
import { budgetLine } from './budget.js';
import { formatCountdown } from './connection.js';
import { busyText, formatSeconds } from './progress.js';
import { formatBytes, formatMs } from './stats.js';

export function createOverlay({ ui, state, settings, store }, { rate, latency, passes, chart, chartSchedule, refine, watch, toasts, frameTargetMs }) {
    /** The 4-per-second tick: rate, busy badge, stale figures, chart, countdown and fading toasts. */
    function showRate() {
        const now = performance.now();
        const fps = rate.rate(now);
        const lat = latency.typical;
        ui.ovRate.textContent = `${fps.toFixed(0)} fps · input→frame ${lat === null ? '–' : formatMs(lat, 0)}`
            + ` · decode ${formatMs(state.decodeMs)}`;
        showProgress(now);
        if (chartSchedule.onTick(now, watch.pending)) showChart(now);
        if (state.connState === 'waiting' && state.retryAt !== null) {
            ui.connText.textContent = `disconnected, retrying in ${formatCountdown(state.retryAt - now)}`;
        }
        for (const entry of toasts.expire(now)) document.querySelector(`.message[data-id="${entry.id}"]`)?.remove();
    }

    /** The pass chart and, when it stopped scrolling, why (ChartSchedule says when). */
    function showChart(now = performance.now()) {
        chartSchedule.drawn(now);
        if (!settings.chart || !settings.overlay) return;
        const nowS = now / 1000;
        passes.prune(nowS);
        const end = passes.windowEnd(nowS);
        if (!chart.isCurrent(end, passes.version)) chart.update(passes.series(), end, passes.version);
        const age = passes.ageS(nowS);
        // A chart that stops scrolling says why instead of looking like a live one.
        ui.ovChartNote.hidden = end === nowS && age !== null;
        const why = state.connState !== 'open' ? ' (not connected)'
            : watch.pending ? ' (waiting for the server)' : ' (the view is still)';
        ui.ovChartNote.textContent = age === null ? 'no frame timings yet'
            : `last frame ${formatSeconds(age * 1000)} ago${why}`;
    }

    let chartAfterShown = false;
    /**
     * After a frame is drawn: a chart redraw that input put off runs once that frame is on screen
     * (the task after its animation frame), not before it.
     */
    function frameDrawn(now = performance.now()) {
        if (chartAfterShown || !chartSchedule.onFrameDrawn(now)) return;
        chartAfterShown = true;
        requestAnimationFrame(() => setTimeout(() => {
            chartAfterShown = false;
            showChart();
        }, 0));
    }

    /**
     * The refinement line of the overlay, the busy badge and the stale mark. Stale: the figures are
     * those of a frame from before input that has waited too long for one that shows it.
     */
    function showProgress(now = performance.now()) {
        const connected = state.connState === 'open';
        const view = connected ? refine.view(now) : null;
        ui.ovRefine.hidden = !view;
        if (view) {
            ui.ovRefine.dataset.kind = view.kind;
            ui.ovRefineText.textContent = view.text;
            ui.ovRefineBar.hidden = view.share === null;
            if (view.share !== null) ui.ovRefineBar.value = view.share;
        }
        const late = connected && !state.viewer ? watch.lateMs(now, frameTargetMs()) : null;
        const busy = connected ? busyText({ lateMs: late, refine: view }) : null;
        ui.busy.hidden = busy === null;
        ui.busy.textContent = busy ?? '';
        ui.busy.dataset.kind = late !== null ? 'late' : 'refining';
        const stale = connected && !state.viewer && watch.stale(now, frameTargetMs());
        ui.overlay.classList.toggle('stale', stale);
        ui.ovStale.hidden = !stale;
        if (stale) {
            ui.ovStale.textContent = `stale: figures from before your input ${formatSeconds(now - watch.pendingSince)} ago`;
        }
    }

    function showFrameStats(header, stats, { decodeMs, net, bytes }) {
        const ms = (v) => (Number.isFinite(v) ? v.toFixed(1) : '–');
        const budget = budgetLine(stats?.budget);
        ui.ovBudget.hidden = !budget;
        if (budget) {
            ui.ovBudget.textContent = budget.text;
            ui.ovBudget.title = budget.reason;
            ui.ovBudget.classList.toggle('capped', budget.capped);
        }
        ui.ovTimes.textContent = `render ${ms(stats?.frame_ms)} · encode ${ms(stats?.encode_ms)} · net ${ms(net)} ms`;
        state.decodeMs = decodeMs;
        ui.ovBytes.textContent = [
            `${formatBytes(bytes)}/frame`,
            `${header.width}×${header.height} ${stats?.codec ?? header.codec}`,
            `${stats?.quality ?? '–'}${stats?.refined ? ' (refined)' : ''}${stats?.snapshot ? ' snapshot' : ''}`,
        ].join(' · ');
        store.emit('rate');
    }

    return { showRate, showProgress, showFrameStats, frameDrawn };
}
