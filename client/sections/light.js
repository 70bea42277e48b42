// The Light section: the session's lights (select, on/off), add and remove, the selected light's
// controls, the gizmo toggle, and what the frame on screen says about each light. Hears: lights,
// lighting, role.
import { addBlock, block, describe, makeSection } from '../controls.js';
import { LIGHT_TYPES, intensityUnit, lightLabel, lightStatuses, lightType, lightingLines } from '../lights.js';

export function createLightSection({ ui, state, settings, saveSettings, store, actions }) {
    const { addLight, removeSelectedLight, changeLight, selectLight } = actions;
    const gui = makeSection(ui.sections, 'Light', { id: 'light' });
    const model = {
        addType: 'point',
        add: () => addLight(model.addType),
        remove: () => removeSelectedLight(),
        enabled: true, intensity: 1, color: [1, 1, 1], cone_deg: 45, gizmo: settings.gizmo,
        reset: () => {
            const light = state.light;
            const home = light ? state.lightHomes.get(light.id ?? '') : null;
            if (home) changeLight(structuredClone(home), light.id ?? null);
        },
    };
    const list = addBlock(gui, block('ul', 'light-list block'));
    list.dataset.block = 'lights';
    const addTypeCtl = describe(gui.add(model, 'addType', [...LIGHT_TYPES]).name('new light'), 'light-add-type',
        'the type of light "Add light" adds: a spot, a point light (shines every way) or a directional light '
        + '(parallel rays, like the sun)');
    const addCtl = describe(gui.add(model, 'add').name('Add light'), 'light-add',
        'adds a light of the type above, placed from the current view: a point light above the orbit target, '
        + 'a directional light shining along the view and somewhat down, a spot aimed at the target');
    const removeCtl = describe(gui.add(model, 'remove').name('Remove selected light'), 'light-remove',
        'removes the selected light from this session');
    const folder = gui.addFolder('selected light');
    folder.domElement.dataset.folder = 'selected-light';
    const enabledCtl = describe(folder.add(model, 'enabled').name('on'), 'light-enabled', 'the selected light on or off');
    enabledCtl.onChange((v) => changeLight({ enabled: v }));
    let intensityMax = 100;
    const intensityCtl = describe(folder.add(model, 'intensity', 0, intensityMax, 0.1).name('intensity (cd)'),
        'light-intensity', 'luminous intensity in candela; for a directional light, illuminance in lux');
    intensityCtl.onChange((v) => changeLight({ intensity: v }));
    const colorCtl = describe(folder.addColor(model, 'color', 1).name('colour'), 'light-color',
        'the light\'s colour (linear RGB)');
    colorCtl.onChange((v) => changeLight({ color: v.map((c) => Math.round(c * 1e4) / 1e4) }));
    const coneCtl = describe(folder.add(model, 'cone_deg', 1, 85, 0.5).name('cone (deg)'), 'light-cone',
        'outer half-angle of the spot cone, 1 to 85 degrees');
    coneCtl.onChange((v) => changeLight({ cone_deg: v }));
    const resetCtl = describe(folder.add(model, 'reset').name('Reset light'), 'light-reset',
        'back to the light as the scene defined it (lights added here have none)');
    describe(gui.add(model, 'gizmo').name('show gizmo'), 'light-gizmo',
        'handles in the view for the selected light: drag the disc to move it, the small dot to aim it')
        .onChange((on) => {
            settings.gizmo = on;
            saveSettings();
            store.emit('gizmo');
        });
    const status = addBlock(gui, block('div', 'lighting-status block'));
    status.dataset.block = 'lighting';
    addBlock(gui, block('p', 'hint block',
        'Click a light to edit it. Drag the gizmo in the view, or Ctrl-drag to aim and Ctrl+Shift-drag to move '
        + 'the selected light (touch: pick "aim light" or "move light" as the drag tool under Camera). A point '
        + 'light only moves, a directional light only turns.'));
    let listKey = '';
    let statusKey = '';
    let rows = new Map(); // light id ('' without ids) -> its row in the list

    function renderList() {
        const selected = state.light;
        const key = JSON.stringify([state.lights.map((l) => [l.id, l.name, l.type, l.enabled]), selected?.id ?? null]);
        if (key === listKey) return;
        listKey = key;
        statusKey = '';
        rows = new Map();
        list.replaceChildren(...state.lights.map((light) => {
            const id = light.id ?? null;
            const li = block('li', 'light-row');
            li.dataset.lightId = id ?? '';
            li.classList.toggle('selected', light === selected);
            const pick = li.appendChild(block('button', 'light-select'));
            pick.type = 'button';
            pick.title = 'edit this light';
            pick.setAttribute('aria-pressed', String(light === selected));
            pick.append(block('span', 'light-name', lightLabel(light)), block('span', 'light-type', lightType(light)));
            pick.addEventListener('click', () => selectLight(id));
            const toggle = li.appendChild(Object.assign(document.createElement('input'), {
                type: 'checkbox', className: 'light-toggle', checked: light.enabled !== false,
            }));
            toggle.setAttribute('aria-label', `${lightLabel(light)} on`);
            toggle.title = 'on or off';
            toggle.addEventListener('change', () => changeLight({ enabled: toggle.checked }, id));
            const reason = li.appendChild(block('div', 'light-reason'));
            reason.hidden = true;
            rows.set(id ?? '', { li, reason });
            return li;
        }));
        if (state.lights.length === 0) list.append(block('li', 'hint', 'No lights: add one below.'));
    }

    const section = {
        gui,
        update() {
            renderList();
            addTypeCtl.show(state.lightList);
            addCtl.show(state.lightList);
            removeCtl.show(state.lightList);
            const l = state.light;
            removeCtl.disable(!l?.id);
            folder.show(Boolean(l));
            if (!l) return;
            folder.title(`${lightLabel(l)} (${lightType(l)})`);
            model.enabled = l.enabled !== false;
            // The server's floats (60.000003814697266) shown as the numbers they stand for.
            const round = (v, digits) => Math.round(v * 10 ** digits) / 10 ** digits;
            model.intensity = round(l.intensity ?? model.intensity, 3);
            if (model.intensity > intensityMax) {
                intensityMax = Math.ceil(model.intensity * 4);
                intensityCtl.max(intensityMax);
            }
            intensityCtl.name(`intensity (${intensityUnit(l)})`);
            model.color = [...(l.color ?? [1, 1, 1])];
            model.cone_deg = round(l.cone_deg ?? model.cone_deg, 2);
            coneCtl.show(lightType(l) === 'spot');
            resetCtl.disable(!state.lightHomes.has(l.id ?? ''));
            for (const c of [enabledCtl, intensityCtl, colorCtl, coneCtl]) c.updateDisplay();
        },
        /**
         * What the frame on screen says about the lights (stats.lighting): the server's note, its
         * warning, and per light whether it was rendered or why not.
         */
        showLighting(lighting) {
            renderList();
            const key = JSON.stringify([lighting ?? null, listKey]);
            if (key === statusKey) return;
            statusKey = key;
            for (const st of lightStatuses(state.lights, lighting)) {
                const row = rows.get(st.id ?? '');
                if (!row) continue;
                row.li.classList.toggle('rendered', st.rendered === true);
                row.li.classList.toggle('skipped', st.rendered === false);
                row.reason.hidden = st.rendered !== false;
                row.reason.textContent = st.rendered === false ? `not rendered: ${st.reason}` : '';
            }
            status.replaceChildren(...lightingLines(lighting).map((line) => block('p', line.kind, line.text)));
        },
    };
    store.on('lights', () => section.update());
    store.on('lighting', (lighting) => section.showLighting(lighting));
    store.on('role', (viewer) => gui.show(!viewer));
    return section;
}
