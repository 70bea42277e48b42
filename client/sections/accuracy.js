// The accuracy view: the Accuracy section (reference mode, noise target, spp cap, size), measuring the
// view through POST /api/render with a CPU reference, the result and the overlay line, and the layer
// over the stream (the API render, the reference, or their difference). Hears: frame, rate, role.
import {
    COMPARE_MODES, COMPARE_RANGES, DEFAULT_COMPARE, buildCompareRequest, canCompare, diffImage, formatCompare,
    referenceLabel, validateCompareRequest, viewKey,
} from '../accuracy.js';
import { addBlock, block, describe, makeSection } from '../controls.js';
import { describeHttpError } from '../messages.js';
import { RENDER_REQUEST_SCHEMA } from '../schemas.js';
import { formatMs } from '../stats.js';

export function createAccuracySection({ ui, state, settings, saveSettings, store, camera, authHeaders, actions }) {
    const { showMessage } = actions;
    const gui = makeSection(ui.sections, 'Accuracy', { id: 'accuracy', closed: false });
    const model = {
        mode: COMPARE_MODES.includes(settings.compareMode) ? settings.compareMode : DEFAULT_COMPARE.mode,
        // The control shows percent; the settings and the request hold the fraction.
        noisePct: Math.round(1000 * settings.compareNoiseTarget) / 10,
        maxSpp: settings.compareMaxSpp,
        maxSide: settings.compareMaxSide,
        view: settings.compareView,
        gain: settings.diffGain,
        measure: () => measureAccuracy(),
    };
    const save = (key) => (v) => {
        settings[key] = v;
        saveSettings();
    };
    const modeCtl = describe(gui.add(model, 'mode', COMPARE_MODES).name('reference'), 'compare-mode',
        'the CPU reference the frame is measured against (one-bounce-unoccluded matches what the VPL techniques simulate)');
    const { noiseTarget: noiseRange, maxSpp: sppRange } = COMPARE_RANGES;
    const noiseCtl = describe(gui.add(model, 'noisePct', 100 * noiseRange.min, 100 * noiseRange.max, 0.5)
        .name('noise target (%)'), 'compare-noise',
        'the reference renders until its own noise, estimated from its samples\' spread, is at most this share of '
        + 'its indirect light: lower is cleaner and slower (a direct reference is exact and ignores it)')
        .onChange((v) => save('compareNoiseTarget')(v / 100));
    describe(gui.add(model, 'maxSpp', sppRange.min, sppRange.max, 1).name('max spp'), 'compare-max-spp',
        'the most samples per pixel the reference may take on the way to the noise target; the server refuses '
        + 'more than its limit (gi-server\'s is 1024) and says so').onChange(save('compareMaxSpp'));
    // A direct reference is one exact sample: its noise target means nothing.
    const showMode = (mode) => noiseCtl.enable(mode !== 'direct');
    showMode(model.mode);
    modeCtl.onChange((v) => {
        save('compareMode')(v);
        showMode(v);
    });
    describe(gui.add(model, 'maxSide', 32, 256, 16).name('size (px)'), 'compare-size',
        'the longer side of the measured image; the current view\'s aspect is kept').onChange(save('compareMaxSide'));
    const measureCtl = describe(gui.add(model, 'measure').name('Measure this view'), 'compare-run',
        'render this view through POST /api/render with a CPU reference and report the error');
    const progress = addBlock(gui, block('div', 'compare-progress block'));
    progress.hidden = true;
    progress.append(Object.assign(document.createElement('progress'), { className: 'busy' }));
    const progressText = progress.appendChild(block('span', 'compare-progress-text'));
    const result = addBlock(gui, block('div', 'compare-result block'));
    result.dataset.block = 'compare-result';
    result.textContent = 'Not measured yet. Measuring costs a few seconds of CPU time on the server.';
    // How to read the figures (corrected or not, what "indirect" means): under them, once there are some.
    const resultHint = addBlock(gui, block('p', 'hint block compare-hint'));
    resultHint.dataset.block = 'compare-hint';
    resultHint.hidden = true;
    const views = { 'live stream': 'live', 'API render': 'api', reference: 'ref', difference: 'diff' };
    const viewCtl = describe(gui.add(model, 'view', views).name('show'),
        'compare-view', 'the live stream, the measured API render of the view, the CPU reference, or the difference '
        + 'between render and reference');
    viewCtl.onChange((v) => {
        save('compareView')(v);
        showCompareLayer();
    });
    describe(gui.add(model, 'gain', 1, 32, 1).name('difference gain'), 'compare-gain',
        'the difference view multiplies |API render − reference| by this').onChange((v) => {
        save('diffGain')(v);
        showCompareLayer();
    });
    addBlock(gui, block('p', 'hint block',
        '"API render" is the frame the server measured, "reference" its CPU reference, "difference" the two '
        + 'apart (the stream instead of the reference when a server sends none).'));
    const section = {
        gui,
        running(text) {
            progress.hidden = text === null;
            progressText.textContent = text ?? '';
            measureCtl.name(text === null ? 'Measure this view' : 'Cancel');
        },
        /** A sentence and/or [label, text] rows, and the hint on how to read them (hidden when null). */
        showResult(text, lines, hint = null) {
            result.replaceChildren();
            if (text) result.append(block('p', '', text));
            for (const [k, v] of lines ?? []) {
                const div = block('div', 'kv');
                div.append(block('span', 'k', k), block('span', 'v', v));
                result.append(div);
            }
            resultHint.hidden = !hint;
            resultHint.textContent = hint ?? '';
        },
        /** True when the view on screen is no longer the one measured. */
        stale() {
            const current = currentCompareRequest();
            return !current || !state.compare || viewKey(current) !== state.compare.key;
        },
        frameDrawn() {
            if (model.view === 'diff' && state.compare) showCompareLayer();
        },
    };

    /** The compare request for the frame on screen, or null when there is none to measure. */
    function currentCompareRequest() {
        const drawn = state.lastDrawn;
        if (!drawn?.stats) return null;
        const m = model;
        return buildCompareRequest({
            scene: state.scene,
            technique: drawn.stats.technique ?? state.technique,
            params: drawn.stats.params ?? state.params,
            camera: camera.toCamera(),
            // Every light, so the reference sees what the stream renders; a protocol-1 server only
            // knows its one light.
            lights: state.lightList ? state.lights : undefined,
            light: state.lightList ? undefined : state.light ?? undefined,
            frameSize: [drawn.width, drawn.height],
            maxSide: m.maxSide,
            mode: m.mode,
            noiseTarget: m.noisePct / 100,
            maxSpp: m.maxSpp,
        });
    }

    async function measureAccuracy() {
        if (state.compareRunning) {
            state.compareRunning.abort.abort();
            return;
        }
        if (!canCompare(state.scene)) {
            showMessage('Uploaded scenes belong to this session\'s stream: the HTTP API cannot render them, '
                + 'so they cannot be measured.');
            return;
        }
        const request = currentCompareRequest();
        if (!request) {
            showMessage('No frame to measure yet.');
            return;
        }
        const problem = validateCompareRequest(request, RENDER_REQUEST_SCHEMA);
        if (problem) {
            showMessage(`Not sent: ${problem.where}: ${problem.message}`);
            return;
        }
        const abort = new AbortController();
        const started = performance.now();
        state.compareRunning = { abort, started };
        const label = referenceLabel(request);
        const tick = () => section.running(
            `rendering the reference (${label}): ${((performance.now() - started) / 1000).toFixed(1)} s`);
        tick();
        const timer = setInterval(tick, 100);
        try {
            const res = await fetch('api/render', {
                method: 'POST',
                headers: { 'Content-Type': 'application/json', ...authHeaders() },
                body: JSON.stringify(request),
                signal: abort.signal,
            });
            const body = await res.json().catch(() => null);
            if (!res.ok) throw new Error(describeHttpError(res.status, body));
            const image = await canvasFromBase64Png(body.image_base64);
            // The reference, tone-mapped like the frame (servers that predate it send none).
            const reference = body.reference_base64 ? await canvasFromBase64Png(body.reference_base64) : null;
            state.compare = {
                request, key: viewKey(request), result: body.stats?.compare ?? null, stats: body.stats, image, reference,
            };
            const f = formatCompare(state.compare.result);
            section.showResult(null, f ? [
                ...f.rows, ['frame time', formatMs(body.stats?.frame_ms)],
                ['measured in', `${((performance.now() - started) / 1000).toFixed(1)} s`],
            ] : [['result', 'the server sent no comparison']], f?.hint ?? null);
            showAccuracyLine();
            showCompareLayer();
        } catch (e) {
            if (e.name === 'AbortError') section.showResult('Cancelled.');
            else {
                section.showResult(`Failed: ${e.message}`);
                showMessage(`Accuracy: ${e.message}`);
            }
        } finally {
            clearInterval(timer);
            state.compareRunning = null;
            section.running(null);
        }
    }

    async function canvasFromBase64Png(base64) {
        const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
        const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
        const canvas = document.createElement('canvas');
        canvas.width = bitmap.width;
        canvas.height = bitmap.height;
        canvas.getContext('2d').drawImage(bitmap, 0, 0);
        bitmap.close();
        return canvas;
    }

    /**
     * The accuracy layer over the stream: the API render, the CPU reference, or the difference between
     * the two (without a reference: between the API render and the frame on screen).
     */
    function showCompareLayer() {
        const view = model.view;
        const reference = state.compare?.reference ?? null;
        const image = view === 'ref' ? reference : state.compare?.image;
        const visible = view !== 'live' && image && !state.viewer;
        ui.compareCanvas.hidden = !visible;
        ui.layerLabel.hidden = !visible;
        if (!visible) return;
        const { width, height } = image;
        ui.compareCanvas.width = width;
        ui.compareCanvas.height = height;
        const out = ui.compareCanvas.getContext('2d', { willReadFrequently: true });
        out.drawImage(image, 0, 0);
        if (view === 'ref') {
            const ref = state.compare.result?.reference ?? {};
            ui.layerLabel.textContent = `CPU reference (${ref.mode ?? '?'}, ${ref.spp ?? '?'} spp, PNG ${width}×${height})`;
            return;
        }
        if (view === 'api') {
            const error = formatCompare(state.compare.result)?.overlay ?? 'no comparison';
            ui.layerLabel.textContent = `API render of the measured view (PNG ${width}×${height}); ${error} `
                + `vs the ${state.compare.request.compare.mode} reference`;
            return;
        }
        const a = out.getImageData(0, 0, width, height).data;
        out.drawImage(reference ?? ui.canvas, 0, 0, width, height);
        const b = out.getImageData(0, 0, width, height).data;
        const diff = diffImage(a, b, model.gain);
        out.putImageData(new ImageData(diff.data, width, height), 0, 0);
        const what = reference ? '|API render − reference|' : '|stream − API render|';
        ui.layerLabel.textContent = `${what} × ${model.gain} (mean ${diff.meanAbs.toFixed(1)} of 255)`
            + `${!reference && section.stale() ? '; the view has changed since the measurement' : ''}`;
    }

    function showAccuracyLine() {
        const result = state.compare?.result;
        ui.ovAccuracy.hidden = !result;
        if (!result) return;
        const f = formatCompare(result);
        const stale = section.stale() ? ' (earlier view)' : '';
        ui.ovAccuracy.textContent = `${f.overlay} vs ${state.compare.request.compare.mode}${stale}`;
    }

    store.on('frame', () => {
        section.frameDrawn();
        showAccuracyLine();
    });
    store.on('rate', showAccuracyLine);
    store.on('role', (viewer) => {
        gui.show(!viewer);
        showCompareLayer();
    });
    return section;
}
