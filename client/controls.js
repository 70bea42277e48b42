// Parameter widgets generated from the parameter schemas in welcome (a technique's params_schema
// and frame_params_schema), so a parameter added on the server shows up here without client work.

const SLIDER_STEPS = 1000;

/** The kind of widget a parameter schema gets: 'number', 'integer', 'boolean', 'enum' or 'text'. */
export function widgetKind(schema) {
    if (Array.isArray(schema.enum)) return 'enum';
    if (schema.type === 'integer') return 'integer';
    if (schema.type === 'number') return 'number';
    if (schema.type === 'boolean') return 'boolean';
    return 'text';
}

/** A round step of about 1/200 of the range (1, 2 or 5 times a power of ten). */
export function niceStep(min, max) {
    const raw = (max - min) / 200;
    if (!(raw > 0) || !Number.isFinite(raw)) return 0.01;
    const p = 10 ** Math.floor(Math.log10(raw));
    const m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

/** Slider position (0..SLIDER_STEPS) <-> value, logarithmic where the schema says x-log-scale. */
export function sliderMapping(schema) {
    const { minimum: min, maximum: max } = schema;
    const log = schema['x-log-scale'] === true && min > 0;
    const isInt = schema.type === 'integer';
    const toValue = (pos) => {
        const t = pos / SLIDER_STEPS;
        const v = log ? min * (max / min) ** t : min + t * (max - min);
        return isInt ? Math.round(v) : roundToStep(v, niceStep(min, max) / (log ? 100 : 1));
    };
    const toPosition = (v) => {
        const t = log ? Math.log(v / min) / Math.log(max / min) : (v - min) / (max - min || 1);
        return Math.round(Math.min(1, Math.max(0, t)) * SLIDER_STEPS);
    };
    return { toValue, toPosition, log };
}

function roundToStep(v, step) {
    const digits = Math.max(0, -Math.floor(Math.log10(step)));
    return Number((Math.round(v / step) * step).toFixed(digits));
}

function element(tag, props = {}, children = []) {
    const el = document.createElement(tag);
    Object.assign(el, props);
    for (const c of children) el.append(c);
    return el;
}

function labelText(name, schema) {
    const unit = schema['x-unit'] ? ` (${schema['x-unit']})` : '';
    return `${name}${unit}`;
}

function tooltip(schema) {
    return [schema.description, schema['x-source'] ? `source: ${schema['x-source']}` : '']
        .filter(Boolean)
        .join('\n');
}

function numberControl(name, schema, onCommit) {
    const isInt = schema.type === 'integer';
    const hasRange = Number.isFinite(schema.minimum) && Number.isFinite(schema.maximum);
    const step = isInt ? 1 : hasRange ? niceStep(schema.minimum, schema.maximum) : 'any';
    const box = element('input', { type: 'number', step: String(step), name });
    if (Number.isFinite(schema.minimum)) box.min = String(schema.minimum);
    if (Number.isFinite(schema.maximum)) box.max = String(schema.maximum);
    const parts = [];
    let setValue = (v) => { box.value = String(v); };
    if (hasRange) {
        const map = sliderMapping(schema);
        const slider = element('input', { type: 'range', min: '0', max: String(SLIDER_STEPS), step: '1' });
        slider.setAttribute('aria-label', name);
        slider.addEventListener('input', () => {
            const v = map.toValue(Number(slider.value));
            box.value = String(v);
            onCommit(v);
        });
        setValue = (v) => {
            box.value = String(v);
            slider.value = String(map.toPosition(v));
        };
        parts.push(slider);
    }
    box.addEventListener('change', () => {
        const v = Number(box.value);
        if (box.value.trim() !== '' && Number.isFinite(v)) onCommit(isInt ? Math.round(v) : v);
    });
    parts.push(box);
    return { inputs: parts, setValue, focusables: parts };
}

function booleanControl(name, onCommit) {
    const box = element('input', { type: 'checkbox', name });
    box.addEventListener('change', () => onCommit(box.checked));
    return { inputs: [box], setValue: (v) => { box.checked = Boolean(v); }, focusables: [box] };
}

function enumControl(name, schema, onCommit) {
    const options = schema.enum.map((o) => element('option', { value: String(o), textContent: String(o) }));
    const select = element('select', { name }, options);
    // Enum values may be numbers in a schema; send them back as the type they were given in.
    select.addEventListener('change', () => onCommit(schema.enum.find((o) => String(o) === select.value)));
    return { inputs: [select], setValue: (v) => { select.value = String(v); }, focusables: [select] };
}

function textControl(name, onCommit) {
    const box = element('input', { type: 'text', name });
    box.addEventListener('change', () => onCommit(box.value));
    return { inputs: [box], setValue: (v) => { box.value = String(v); }, focusables: [box] };
}

function controlFor(name, schema, onCommit) {
    switch (widgetKind(schema)) {
    case 'number':
    case 'integer': return numberControl(name, schema, onCommit);
    case 'boolean': return booleanControl(name, onCommit);
    case 'enum': return enumControl(name, schema, onCommit);
    default: return textControl(name, onCommit);
    }
}

/**
 * Fills `container` with one row per parameter of each group ({title, schema}); `onChange(name,
 * value)` runs when the user sets a value. Returns {update(values)} to show values from the
 * server; a control the user is working with at that moment keeps what they typed.
 */
export function buildParamPanel(container, groups, values, onChange) {
    container.replaceChildren();
    const controls = new Map();
    for (const { title, schema } of groups) {
        const props = Object.entries(schema?.properties ?? {});
        if (props.length === 0) continue;
        const fieldset = element('fieldset', { className: 'param-group' }, [element('legend', { textContent: title })]);
        for (const [name, paramSchema] of props) {
            const control = controlFor(name, paramSchema, (v) => onChange(name, v));
            control.inputs.at(-1).id = `param-${name}`;
            const label = element('label', { textContent: labelText(name, paramSchema), htmlFor: `param-${name}` });
            const row = element('div', { className: `param param-${widgetKind(paramSchema)}`, title: tooltip(paramSchema) },
                [label, element('div', { className: 'param-inputs' }, control.inputs)]);
            fieldset.append(row);
            controls.set(name, control);
            control.setValue(values?.[name] ?? paramSchema.default ?? '');
        }
        container.append(fieldset);
    }
    return {
        update(newValues) {
            for (const [name, v] of Object.entries(newValues ?? {})) {
                const control = controls.get(name);
                if (!control || control.focusables.includes(document.activeElement)) continue;
                control.setValue(v);
            }
        },
        has: (name) => controls.has(name),
    };
}
