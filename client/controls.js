// Sidebar widgets on lil-gui: each sidebar section is a lil-gui root (its title bar collapses it),
// and the parameter folders are generated from the server's parameter schemas through
// params.js, so a parameter added on the server shows up here without client work.

import GUI from 'lil-gui';

import { controlSpec, paramHelp } from './params.js';

export { GUI };

/** A collapsible sidebar section titled `title`, appended to `container`. */
export function makeSection(container, title, { id, closed = false } = {}) {
    const gui = new GUI({ container, title, closeFolders: false });
    gui.domElement.classList.add('section');
    if (id) gui.domElement.dataset.section = id;
    if (closed) gui.close();
    return gui;
}

/** Appends `element` (a custom block: a list, a chart, a progress bar) to a section or folder. */
export function addBlock(gui, element) {
    gui.$children.append(element);
    return element;
}

/** Marks a controller for tests and styles (data-control) and gives it the help text. */
export function describe(controller, id, help) {
    controller.domElement.dataset.control = id;
    if (help) {
        controller.domElement.title = help;
        // A button's help stays a tooltip: a line inside the button would break it.
        if (controller.domElement.classList.contains('lil-function')) return controller;
        const line = document.createElement('div');
        line.className = 'control-help';
        line.textContent = help;
        controller.domElement.append(line);
    }
    return controller;
}

/** A controller for a parameter spec (params.js controlSpec) on `holder[spec.name]`. */
function addSpecController(gui, holder, spec) {
    switch (spec.kind) {
    case 'integer':
    case 'number': {
        if (spec.min !== undefined && spec.max !== undefined) {
            return gui.add(holder, spec.name, spec.min, spec.max, spec.step);
        }
        const c = gui.add(holder, spec.name);
        if (spec.min !== undefined) c.min(spec.min);
        if (spec.max !== undefined) c.max(spec.max);
        if (spec.step !== undefined) c.step(spec.step);
        return c;
    }
    case 'enum': return gui.add(holder, spec.name, spec.options);
    default: return gui.add(holder, spec.name);
    }
}

function isEditing(controller) {
    const active = document.activeElement;
    return active !== null && active !== document.body && controller.domElement.contains(active);
}

/**
 * The generated parameter folders of the Technique section. build(groups, values, onChange)
 * replaces them: groups are [{title, schema, closed}], onChange(name, value) runs when the user
 * sets a value. update(values) shows values without calling onChange; a control the user is
 * typing into keeps what they typed unless `force` (a refused value is put back).
 */
export class ParamPanel {
    constructor(gui) {
        this.gui = gui;
        this.folders = [];
        this.controls = new Map(); // name -> {controller, holder, spec}
    }

    build(groups, values, onChange) {
        for (const folder of this.folders) folder.destroy();
        this.folders = [];
        this.controls.clear();
        for (const { title, schema, closed } of groups) {
            const props = Object.entries(schema?.properties ?? {});
            if (props.length === 0) continue;
            const folder = this.gui.addFolder(title);
            folder.domElement.classList.add('param-folder');
            for (const [name, paramSchema] of props) {
                const spec = controlSpec(name, paramSchema, values?.[name]);
                const holder = { [name]: spec.initial };
                const controller = addSpecController(folder, holder, spec).name(spec.label);
                describe(controller, `param-${name}`, paramHelp(paramSchema));
                controller.domElement.dataset.param = name;
                // Numbers report every slider step; the sender coalesces them per animation frame.
                controller.onChange((v) => onChange(name, spec.kind === 'integer' ? Math.round(v) : v));
                this.controls.set(name, { controller, holder, spec });
            }
            if (closed) folder.close();
            this.folders.push(folder);
        }
    }

    update(values, { force = false } = {}) {
        for (const [name, v] of Object.entries(values ?? {})) {
            const c = this.controls.get(name);
            if (!c || (!force && isEditing(c.controller)) || c.holder[name] === v) continue;
            c.holder[name] = v;
            c.controller.updateDisplay();
        }
    }

    has(name) {
        return this.controls.has(name);
    }
}
