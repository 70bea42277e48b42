// The Camera section: the drag tool, field of view, fly speed, reset and "frame the model", and the
// keys. Hears: camera, bounds, role.
import { DRAG_TOOLS, MAX_FOV_DEG, MIN_FOV_DEG } from '../camera.js';
import { addBlock, block, describe, makeSection } from '../controls.js';

const TOOL_NAMES = {
    orbit: 'orbit', pan: 'pan', zoom: 'zoom', fly: 'fly (WASD + look)', 'light-aim': 'aim light', 'light-move': 'move light',
};

export function createCameraSection({ ui, settings, saveSettings, store, camera, actions }) {
    const { scheduleCamera, resetCamera, frameModel } = actions;
    const gui = makeSection(ui.sections, 'Camera', { id: 'camera' });
    if (!DRAG_TOOLS.includes(settings.tool)) settings.tool = 'orbit';
    const model = {
        tool: settings.tool,
        fov: 40,
        speed: settings.flySpeed,
        reset: () => resetCamera(),
        frame: () => frameModel(),
    };
    const toolOptions = Object.fromEntries(DRAG_TOOLS.map((t) => [TOOL_NAMES[t], t]));
    describe(gui.add(model, 'tool', toolOptions).name('drag tool'), 'drag-tool',
        'what a drag (or one finger) does; Shift or right-drag always pans, Ctrl-drag aims the light')
        .onChange((t) => {
            settings.tool = t;
            saveSettings();
            ui.canvas.dataset.tool = t;
        });
    const fovCtl = describe(gui.add(model, 'fov', MIN_FOV_DEG, MAX_FOV_DEG, 1).name('field of view (deg)'), 'fov',
        'vertical field of view');
    fovCtl.onChange((v) => {
        camera.setFov(v);
        scheduleCamera();
    });
    describe(gui.add(model, 'speed', 0.05, 3, 0.05).name('fly speed'), 'fly-speed',
        'WASD speed in scene sizes per second (Shift: three times as fast)')
        .onChange((v) => {
            settings.flySpeed = v;
            saveSettings();
        });
    describe(gui.add(model, 'reset').name('Reset camera'), 'reset-camera', 'back to the scene\'s camera (Home or R)');
    const frameCtl = describe(gui.add(model, 'frame').name('Frame the model'), 'frame-model',
        'orbit around the model\'s centre from far enough to see all of it, keeping the view direction (.)');
    frameCtl.show(false);
    addBlock(gui, block('p', 'hint block',
        'Drag: the tool above · Shift- or right-drag: pan · wheel or pinch: zoom · two fingers: pan · '
        + 'W A S D: fly, E/Q: up/down · arrows: orbit (fly: look) · +/−: zoom · Home or R: reset · '
        + '. (full stop): frame the model · F: fullscreen. Click the view first for the keys.'));
    ui.canvas.dataset.tool = model.tool;
    const section = {
        gui,
        update() {
            if (Math.abs(model.fov - camera.fovDeg) > 1e-9) {
                model.fov = camera.fovDeg;
                fovCtl.updateDisplay();
            }
        },
        /** Framing needs the scene's bounds (protocol 2's state.bounds). */
        setBounds(known) {
            frameCtl.show(known);
        },
    };
    store.on('camera', () => section.update());
    store.on('bounds', (known) => section.setBounds(known));
    store.on('role', (viewer) => gui.show(!viewer));
    return section;
}
