// The Stats section: the overlay and chart toggles, and the details of the frame on screen (quality,
// budget, refinement, queue, VPLs, triangles, what differs from the panel). Hears: frame.
import { budgetLine } from '../budget.js';
import { addBlock, block, describe, keyValueRows, makeSection } from '../controls.js';
import { presetChanges } from '../params.js';
import { formatMs, trianglesText } from '../stats.js';

export function createStatsSection({ ui, state, settings, saveSettings, store, chart }) {
    const gui = makeSection(ui.sections, 'Stats', { id: 'stats' });
    const model = { overlay: settings.overlay, chart: settings.chart };
    const applyOverlay = () => {
        ui.overlay.hidden = !settings.overlay;
        ui.ovChart.hidden = !settings.chart;
        ui.ovLegend.hidden = !settings.chart;
        if (!settings.chart) ui.ovChartNote.hidden = true;
    };
    describe(gui.add(model, 'overlay').name('overlay'), 'stats-overlay', 'frame rate, latency and times over the view')
        .onChange((on) => {
            settings.overlay = on;
            saveSettings();
            applyOverlay();
        });
    describe(gui.add(model, 'chart').name('pass chart'), 'stats-chart', 'stacked per-pass GPU time, last 10 s')
        .onChange((on) => {
            settings.chart = on;
            saveSettings();
            applyOverlay();
            if (on) chart.resize();
        });
    const details = addBlock(gui, block('div', 'stats-details block'));
    details.dataset.block = 'stats-details';
    const rows = keyValueRows(details);
    applyOverlay();
    const section = {
        gui,
        showDetails(stats) {
            if (!stats) return;
            const changed = presetChanges(stats.params, state.params);
            const budget = budgetLine(stats.budget);
            const r = stats.refine;
            rows.show([
                ['quality', `${stats.quality ?? '–'}${stats.refined ? ' (refined)' : ''}`
                    + `${stats.scale !== undefined ? `, scale ${stats.scale}` : ''}`],
                ...(budget ? [['frame budget', budget.text], ['why', budget.reason || '–']] : []),
                ...(r ? [['refinement', `${r.step ?? stats.quality}: ${r.tiles_done ?? '?'} tiles, `
                    + `${Math.round(100 * (r.share ?? 0))} %, ${formatMs(r.elapsed_ms, 0)}`
                    + `${r.vpl_parts > 1 ? `, tile at ${r.vpl_parts_done} of ${r.vpl_parts} VPL parts` : ''}`
                    + `${r.complete ? ', complete' : `, ${formatMs(r.eta_ms, 0)} left`}`]] : []),
                ['queue', formatMs(stats.queue_ms)],
                ['readback', formatMs(stats.readback_ms)],
                ['timing', stats.timing ?? '–'],
                ['VPLs', stats.counts?.vpl_count ?? '–'],
                ['triangles', trianglesText(stats.counts)],
                ['dropped', stats.dropped_frames ?? 0],
                ['viewers', stats.viewers ?? 0],
                ['round trip', formatMs(state.rttMs)],
                ['this frame differs', changed.length
                    ? changed.map(([k, v]) => `${k}=${typeof v === 'number' ? Number(v.toPrecision(4)) : v}`).join(', ')
                    : 'no (the panel\'s values)'],
            ]);
        },
    };
    store.on('frame', (stats) => section.showDetails(stats));
    return section;
}
