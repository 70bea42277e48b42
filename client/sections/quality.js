// The Resolution & quality section: the frame-time target, the pixel budget, and what the session
// renders at (frame size, pixel ratio, target, refinement slice). Hears: viewport, welcome, role.
import { PIXEL_BUDGETS, frameTargetOptions, frameTargetSupported } from '../budget.js';
import { addBlock, block, describe, makeSection } from '../controls.js';
import { CLIENT_SCHEMAS } from '../schemas.js';

export function createQualitySection({ ui, state, settings, saveSettings, store, actions }) {
    const { sendQuality, sendResize } = actions;
    const gui = makeSection(ui.sections, 'Resolution & quality', { id: 'quality' });
    const model = { frameTarget: settings.frameTargetMs ?? 'default', pixelBudget: settings.pixelBudget };
    const targetCtl = describe(gui.add(model, 'frameTarget', frameTargetOptions(null)).name('frame time target'),
        'frame-target', 'what interactive frames must take at most while you steer: smooth renders fewer VPLs and '
        + 'pixels, sharp more; refinement of the still view follows');
    targetCtl.onChange((v) => {
        settings.frameTargetMs = v === 'default' ? null : v;
        saveSettings();
        sendQuality();
        update();
    });
    const budgetCtl = describe(gui.add(model, 'pixelBudget', Object.fromEntries(PIXEL_BUDGETS.map((b) => [b.label, b.px])))
        .name('pixel budget'), 'pixel-budget',
    'the most pixels a frame may have: on high-density screens the device pixel ratio sent to the server is lowered '
        + 'to stay within it');
    budgetCtl.onChange((v) => {
        settings.pixelBudget = v;
        saveSettings();
        sendResize();
        update();
    });
    const info = addBlock(gui, block('div', 'quality-info block'));
    info.dataset.block = 'quality-info';

    function update() {
        const supported = frameTargetSupported(state.welcome, CLIENT_SCHEMAS);
        targetCtl.show(supported && !state.viewer);
        if (supported) {
            targetCtl.options(frameTargetOptions(state.welcome?.limits?.frame_target_ms));
            model.frameTarget = settings.frameTargetMs ?? 'default';
            targetCtl.updateDisplay();
        }
        const vp = state.viewport;
        const lines = [];
        if (vp) {
            const device = window.devicePixelRatio || 1;
            const px = [Math.round(vp.size[0] * vp.dpr), Math.round(vp.size[1] * vp.dpr)];
            lines.push(['frame size', `${px[0]}×${px[1]} (${(px[0] * px[1] / 1e6).toFixed(2)} MP)`]);
            lines.push(['pixel ratio', vp.dpr < device ? `${vp.dpr} of this screen's ${device}` : String(vp.dpr)]);
        }
        if (state.frameTargetMs !== null) lines.push(['session target', `${state.frameTargetMs} ms`]);
        const slice = state.welcome?.limits?.slice_ms;
        if (Number.isFinite(slice)) lines.push(['refinement slice', `${slice} ms`]);
        info.replaceChildren(...lines.map(([k, v]) => {
            const div = block('div', 'kv');
            div.append(block('span', 'k', k), block('span', 'v', v));
            return div;
        }));
    }

    const section = {
        gui,
        update,
        setViewer(viewer) {
            gui.show(!viewer);
        },
    };
    store.on('viewport', update);
    store.on('welcome', update);
    store.on('role', (viewer) => section.setViewer(viewer));
    return section;
}
