// The Technique & parameters section: the technique, adaptive quality, help, "Reset parameters" and
// the parameter folders generated from the welcome schemas. Hears: techniques, technique, adaptive,
// params, role.
import { ParamPanel, addBlock, block, describe, makeSection } from '../controls.js';
import { schemaDefaults } from '../params.js';
import { techniqueMsg } from '../protocol.js';

export function createTechniqueSection({ ui, state, settings, saveSettings, store, actions }) {
    const {
        steer, flushOutbox, forgetTechniqueParams, resetParams, sendQuality, queueParams, showMessage, showTechnique,
    } = actions;
    const gui = makeSection(ui.sections, 'Technique & parameters', { id: 'technique' });
    const model = {
        technique: '', adaptive: true, help: settings.help,
        reset: () => resetParams(),
    };
    const techniqueCtl = describe(gui.add(model, 'technique', ['']).name('technique'), 'technique',
        'the global-illumination technique; its parameters reset to their defaults');
    techniqueCtl.onChange((name) => {
        if (!name || name === state.technique) return;
        flushOutbox(); // parameters still queued belong to the technique before
        if (!steer(techniqueMsg(name))) return;
        const technique = state.techniques.get(name);
        Object.assign(state.params, schemaDefaults(technique?.params_schema));
        forgetTechniqueParams();
        showTechnique(name);
    });
    const info = addBlock(gui, block('p', 'technique-info block'));
    describe(gui.add(model, 'adaptive').name('adaptive quality'), 'adaptive',
        'render quickly while you steer, then refine the still view (balanced, then final preset)')
        .onChange((on) => {
            state.adaptive = on;
            sendQuality();
        });
    describe(gui.add(model, 'help').name('show help'), 'help', 'show each parameter\'s description, range and source')
        .onChange((on) => {
            settings.help = on;
            saveSettings();
            ui.sidebar.classList.toggle('show-help', on);
        });
    describe(gui.add(model, 'reset').name('Reset parameters'), 'reset-params',
        'every parameter back to its default; the technique\'s parameters follow the adaptive presets again');
    ui.sidebar.classList.toggle('show-help', settings.help);
    // The generated parameter folders go at the end of the section.
    const paramPanel = new ParamPanel(gui);
    const section = {
        gui,
        setTechniques(names) {
            techniqueCtl.options(names.length ? names : ['']);
        },
        adaptive(on) {
            state.adaptive = on;
            model.adaptive = on;
            gui.controllers.find((c) => c.property === 'adaptive')?.updateDisplay();
        },
        show(name) {
            model.technique = name ?? '';
            techniqueCtl.updateDisplay();
            const t = state.techniques.get(name);
            info.textContent = t ? [t.description, t.paper ? `(${t.paper})` : ''].filter(Boolean).join(' ') : '';
        },
    };
    store.on('techniques', (names) => section.setTechniques(names));
    store.on('adaptive', (on) => section.adaptive(on));
    store.on('technique', (name) => {
        section.show(name);
        const technique = state.techniques.get(name);
        paramPanel.build([
            { title: `${name ?? 'technique'} parameters`, schema: technique?.params_schema },
            { title: 'frame parameters', schema: state.welcome?.frame_params_schema, closed: true },
        ], state.params, (param, value) => queueParams({ [param]: value }), { onRefuse: (text) => showMessage(text) });
    });
    store.on('params', (values, options) => paramPanel.update(values ?? state.params, options));
    store.on('role', (viewer) => gui.show(!viewer));
    return section;
}
