// The Scene section: the scene list (the server's and this session's uploads), upload progress, the
// "plan effects" toggle, what the file asks for and is not shown, and the effect plan of the frame on
// screen. Hears: scenes, params, role, frame, upload.
import { addBlock, block, describe, makeSection } from '../controls.js';
import { sceneMsg } from '../protocol.js';
import { notShownLines, notShownSummary } from '../scene-notes.js';

export function createSceneSection({ ui, state, store, actions }) {
    const { steer, flushOutbox, queueParams } = actions;
    const gui = makeSection(ui.sections, 'Scene', { id: 'scene' });
    const model = { scene: '', autoEffects: false, upload: () => ui.fileInput.click() };
    let sceneCtl = describe(gui.add(model, 'scene', ['']).name('scene'), 'scene',
        'built-in scenes, the server\'s scene directories and this session\'s uploads');
    sceneCtl.onChange((name) => {
        if (!name || name === state.scene) return;
        flushOutbox();
        if (steer(sceneMsg(name))) state.scene = name;
    });
    const uploadCtl = describe(gui.add(model, 'upload').name('Upload .glb or .zip…'), 'upload',
        'a .glb, or a .zip holding a .gltf with its .bin and textures; or drop one on the view. '
        + 'It is loaded for this session only');
    const progress = addBlock(gui, block('div', 'upload-progress block'));
    progress.hidden = true;
    const bar = progress.appendChild(Object.assign(document.createElement('progress'), { max: 1, value: 0 }));
    const progressText = progress.appendChild(block('span', 'upload-text'));
    const effectsCtl = describe(gui.add(model, 'autoEffects').name('plan effects'), 'auto-effects',
        'effects = auto: the server measures which lighting effects this view needs and switches the rest off');
    effectsCtl.onChange((on) => queueParams({ effects: on ? 'auto' : 'manual' }));
    // What the file asks for and is not shown (stats.not_shown): hidden while there is nothing.
    const notes = addBlock(gui, block('div', 'not-shown block'));
    notes.dataset.block = 'not-shown';
    notes.hidden = true;
    const notesSummary = notes.appendChild(block('p', 'not-shown-summary'));
    const notesList = notes.appendChild(block('ul', 'not-shown-list'));
    let lastNotesKey = '';
    const planFolder = gui.addFolder('effect plan');
    planFolder.domElement.dataset.folder = 'plan';
    const plan = addBlock(planFolder, block('div', 'plan block'));
    plan.dataset.block = 'plan';
    const planSummary = plan.appendChild(block('p', 'plan-summary'));
    const planList = plan.appendChild(block('ul', 'plan-list'));
    let lastPlanKey = '';

    const section = {
        gui,
        setScenes() {
            const names = [...new Set([...state.scenes, ...state.uploads, ...(state.scene ? [state.scene] : [])])];
            model.scene = state.scene ?? '';
            sceneCtl.options(names.length ? names : ['']);
            sceneCtl.updateDisplay();
        },
        update() {
            model.autoEffects = state.params.effects === 'auto';
            effectsCtl.updateDisplay();
        },
        setViewer(viewer) {
            sceneCtl.disable(viewer);
            uploadCtl.show(!viewer);
            effectsCtl.show(!viewer);
        },
        progress(fraction, text) {
            progress.hidden = fraction === null;
            if (fraction !== null) bar.value = fraction;
            progressText.textContent = text ?? '';
        },
        /**
         * The effect plan of the frame on screen: each effect on or off, and why. Without a plan the
         * renderer's own non-diffuse decisions (stats.nondiffuse: "on: reason" / "off: reason") are
         * listed, since they run whatever the mode.
         */
        showNotShown(notShown) {
            const lines = notShownLines(notShown);
            const key = JSON.stringify(lines);
            if (key === lastNotesKey) return;
            lastNotesKey = key;
            notes.hidden = lines.length === 0;
            notesSummary.textContent = notShownSummary(lines);
            notesList.replaceChildren(...lines.map((line) => {
                const li = block('li', 'not-shown-item', line.text);
                li.dataset.feature = line.feature;
                return li;
            }));
        },
        showPlan(p, nondiffuse) {
            const key = `${state.params.effects}:${JSON.stringify(p ?? null)}:${JSON.stringify(nondiffuse ?? null)}`;
            if (key === lastPlanKey) return;
            lastPlanKey = key;
            if (typeof p?.pending === 'string') {
                // The server is still measuring the scene (its ray structure for the planner).
                planSummary.textContent = `Effects: ${p.pending}.`;
                planList.replaceChildren();
                return;
            }
            if (!p || p.mode === 'manual' || !Array.isArray(p.decisions)) {
                planSummary.textContent = 'Manual: the technique\'s parameters decide which effects run. '
                    + 'Turn on "plan effects" to let the server measure what this view needs.';
                const entries = Object.entries(nondiffuse ?? {});
                planList.replaceChildren(...entries.map(([effect, text]) => {
                    const on = String(text).startsWith('on');
                    const li = block('li', `decision ${on ? 'on' : 'off'}`);
                    li.dataset.effect = effect;
                    const head = li.appendChild(block('div', 'decision-head'));
                    head.append(block('span', 'decision-name', effect), block('span', 'badge', on ? 'on' : 'off'));
                    li.append(block('div', 'decision-reason', String(text).replace(/^(on|off): /, '')));
                    return li;
                }));
                return;
            }
            const why = state.params.effects === 'auto' ? 'planned for this view'
                : 'planned by the final refinement step (adaptive quality)';
            planSummary.textContent = `Effects ${why}, from ${p.rays ?? '?'} rays `
                + `in ${Number.isFinite(p.analysis_ms) ? p.analysis_ms.toFixed(0) : '?'} ms:`;
            planList.replaceChildren(...p.decisions.map((d) => {
                const li = block('li', `decision ${d.enabled ? 'on' : 'off'}`);
                li.dataset.effect = d.effect;
                const head = li.appendChild(block('div', 'decision-head'));
                head.append(block('span', 'decision-name', d.effect),
                    block('span', 'badge', `${d.enabled ? 'on' : 'off'}${d.forced ? ', forced' : ''}`
                        + `${d.available === false ? ', no knob' : ''}`));
                li.append(block('div', 'decision-reason', d.reason ?? ''));
                return li;
            }));
        },
    };
    store.on('scenes', () => section.setScenes());
    store.on('params', () => section.update());
    store.on('role', (viewer) => section.setViewer(viewer));
    store.on('upload', (fraction, text) => section.progress(fraction, text));
    store.on('frame', (stats) => {
        section.showPlan(stats?.plan, stats?.nondiffuse);
        section.showNotShown(stats?.not_shown);
    });
    return section;
}
