// The live per-pass timing chart of the stats overlay: uPlot, stacked areas over the last few
// seconds, one band per render pass, with a legend of the newest frame's times. The data comes
// from stats.js PassHistory.

import uPlot from 'uplot';

import { axisSize, msTickLabels } from './stats.js';

const PALETTE = ['#5aa9ff', '#ffc857', '#4cd17b', '#ff6b6b', '#c792ea', '#2ec4b6', '#ff9f1c', '#e4e6ea',
    '#8d99ae', '#f72585', '#b5e48c', '#4361ee'];

export class PassChart {
    /** `container` holds the chart, `legend` (a list element) the pass names with their times. */
    constructor(container, legend, { windowS = 10, height = 110 } = {}) {
        this.container = container;
        this.legend = legend;
        this.windowS = windowS;
        this.height = height;
        this.now = 0;
        this.colors = new Map(); // pass name -> colour, kept while the page lives
        this.names = [];
        this.plot = null;
        this.drawn = null; // {end, version} of the last redraw; null after a resize
        this.legendText = null; // the legend's names and times as last shown
        this.redraws = 0;
    }

    /**
     * Whether a redraw would show what the chart shows: the same window end (the chart stops scrolling
     * 10 s after the last frame) over the same samples (PassHistory.version), at the size resize() set.
     */
    isCurrent(end, version) {
        const d = this.drawn;
        return d !== null && d.end === end && d.version === version;
    }

    colorOf(name) {
        if (!this.colors.has(name)) this.colors.set(name, PALETTE[this.colors.size % PALETTE.length]);
        return this.colors.get(name);
    }

    width() {
        return Math.max(120, Math.floor(this.container.clientWidth || 260));
    }

    build(names) {
        this.plot?.destroy();
        this.names = names;
        // uPlot draws series in order and fills each down to 0: the top band (the sum of every
        // pass) first, each lower sum over it, so band k shows pass k's colour.
        const series = [{}];
        for (let k = names.length - 1; k >= 0; --k) {
            const color = this.colorOf(names[k]);
            series.push({ label: names[k], stroke: color, fill: `${color}cc`, width: 1, points: { show: false } });
        }
        const axis = { stroke: '#9aa0aa', font: '10px system-ui, sans-serif', grid: { stroke: '#30343b', width: 1 },
            ticks: { stroke: '#30343b', width: 1, size: 3 } };
        this.plot = new uPlot({
            width: this.width(),
            height: this.height,
            legend: { show: false },
            cursor: { show: false },
            select: { show: false },
            scales: {
                x: { time: false, range: () => [this.now - this.windowS, this.now] },
                y: { range: (u, min, max) => [0, Math.max(1, max * 1.1)] },
            },
            axes: [
                { ...axis, size: 18, values: (u, ticks) => ticks.map((t) => `${Math.round(t - this.now)}s`) },
                // Room for the longest label, unit included: a fixed width clipped "1200".
                { ...axis, size: (u, values) => axisSize(values), values: (u, ticks) => msTickLabels(ticks) },
            ],
            series,
        }, [[], ...names.map(() => [])], this.container);
        this.plot.root.setAttribute('aria-label', 'per-pass render time, stacked, milliseconds over the last seconds');
    }

    /** Draws PassHistory.series() with the window ending at `nowS` seconds; `version`: the history's. */
    update({ names, times, values, stacked }, nowS, version = null) {
        this.now = nowS;
        this.drawn = { end: nowS, version };
        this.redraws += 1;
        if (!this.plot || names.length !== this.names.length || names.some((n, i) => n !== this.names[i])) {
            this.build(names);
        }
        const data = [times];
        for (let k = names.length - 1; k >= 0; --k) data.push(stacked[k]);
        this.plot.setData(data);
        this.showLegend(names, values);
    }

    showLegend(names, values) {
        if (!this.legend) return;
        const times = values.map((v) => v.at(-1));
        const msText = (t) => (Number.isFinite(t) ? t.toFixed(1) : '–');
        const text = names.map((name, k) => `${name} ${msText(times[k])}`).join('\n');
        // New elements each tick restyle and lay out the overlay for nothing when no time changed.
        if (text === this.legendText) return;
        this.legendText = text;
        // Rows are kept per pass and only their times written (new rows would be styled and laid out
        // again, about a hundred objects, at every tick while times change); a pass new to the list
        // gets a row, and the rows are put in order only when the order changed.
        const byName = new Map([...this.legend.children].map((li) => [li.dataset.pass, li]));
        const rows = names.map((name, k) => {
            let li = byName.get(name);
            if (!li) {
                li = document.createElement('li');
                li.dataset.pass = name;
                const swatch = Object.assign(document.createElement('span'), { className: 'swatch' });
                swatch.style.background = this.colorOf(name);
                const span = (className) => Object.assign(document.createElement('span'), { className });
                li.append(swatch, Object.assign(span('pass-name'), { textContent: name }), span('pass-ms'));
            }
            const ms = li.querySelector('.pass-ms');
            if (ms.textContent !== msText(times[k])) ms.textContent = msText(times[k]);
            return li;
        });
        const shown = this.legend.children;
        if (rows.length !== shown.length || rows.some((li, k) => shown[k] !== li)) this.legend.replaceChildren(...rows);
    }

    resize() {
        this.plot?.setSize({ width: this.width(), height: this.height });
        this.drawn = null;
    }
}
