// Sidebar widgets on lil-gui: each sidebar section is a lil-gui root (its title bar collapses it),
// and the parameter folders are generated from the server's parameter schemas through
// params.js, so a parameter added on the server shows up here without client work.

import GUI from 'lil-gui';

import { checkTypedNumber, controlSpec, orderedProperties, paramHelp } from './params.js';

export { GUI };

/** A collapsible sidebar section titled `title`, appended to `container`. */
/** A DOM element: `tag` with `className` and, when given, `text`. */
export function block(tag, className, text) {
    const el = document.createElement(tag);
    if (className) el.className = className;
    if (text !== undefined) el.textContent = text;
    return el;
}

/**
 * A list of label: value rows in `container` that show(rows) keeps up to date ([label, value] pairs):
 * only the values that changed are written, and the rows are built again only when the labels do. A
 * panel shown beside a live view is told about every frame: new elements each time would restyle and
 * lay out the sidebar for nothing.
 */
export function keyValueRows(container) {
    let labels = null;
    let values = [];
    return {
        show(rows) {
            const key = rows.map(([label]) => label).join('\n');
            if (key !== labels) {
                labels = key;
                values = rows.map(() => block('span', 'v'));
                container.replaceChildren(...rows.map(([label], i) => {
                    const div = block('div', 'kv');
                    div.append(block('span', 'k', label), values[i]);
                    return div;
                }));
            }
            rows.forEach(([, value], i) => {
                const text = String(value);
                if (values[i].textContent !== text) values[i].textContent = text;
            });
        },
    };
}

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

/**
 * A number field that commits what was typed on Enter or blur, and only when `check(text)` accepts
 * it ({value} or {error}). lil-gui itself sets the value on every keystroke, clamped into the
 * slider's range, so 9999 would be sent as the maximum; its input listener is kept from seeing the
 * typing (a capture listener on the row runs first), and the slider, arrow keys and wheel work as
 * before.
 */
export function guardTypedNumber(controller, check, onRefuse) {
    const input = controller.$input;
    if (!input) return;
    controller.domElement.addEventListener('input', (e) => {
        if (e.target === input) e.stopPropagation();
    }, true);
    // 'change' comes before lil-gui's blur handler, which shows the controller's value again.
    input.addEventListener('change', () => {
        const result = check(input.value);
        controller.domElement.classList.toggle('refused', Boolean(result.error));
        if (result.error) {
            onRefuse?.(result.error);
            controller.updateDisplay();
        } else if (result.value !== controller.getValue()) {
            controller.setValue(result.value);
        }
    });
    input.addEventListener('focus', () => controller.domElement.classList.remove('refused'));
}

function isEditing(controller) {
    const active = document.activeElement;
    return active !== null && active !== document.body && controller.domElement.contains(active);
}

/**
 * The generated parameter folders of the Technique section. build(groups, values, onChange,
 * {onRefuse}) replaces them: groups are [{title, schema, closed}], in the schema's order;
 * onChange(name, value) runs when the user sets a value, onRefuse(sentence) when a typed number
 * is outside the schema. update(values) shows values without calling onChange; a control the user
 * is typing into keeps what they typed unless `force` (a refused value is put back).
 */
export class ParamPanel {
    constructor(gui) {
        this.gui = gui;
        this.folders = [];
        this.controls = new Map(); // name -> {controller, holder, spec}
    }

    build(groups, values, onChange, { onRefuse } = {}) {
        for (const folder of this.folders) folder.destroy();
        this.folders = [];
        this.controls.clear();
        for (const { title, schema, closed } of groups) {
            const props = orderedProperties(schema);
            if (props.length === 0) continue;
            const folder = this.gui.addFolder(title);
            folder.domElement.classList.add('param-folder');
            for (const [name, paramSchema] of props) {
                const spec = controlSpec(name, paramSchema, values?.[name]);
                const holder = { [name]: spec.initial };
                const controller = addSpecController(folder, holder, spec).name(spec.label);
                describe(controller, `param-${name}`, paramHelp(paramSchema));
                controller.domElement.dataset.param = name;
                // The label may wrap or be cut on a narrow sidebar: the full name is the name's tooltip.
                controller.$name.title = spec.label;
                if (spec.kind === 'integer' || spec.kind === 'number') {
                    guardTypedNumber(controller, (text) => checkTypedNumber(name, paramSchema, text), onRefuse);
                }
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
