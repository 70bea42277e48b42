// Parameter schemas (welcome: a technique's params_schema and frame_params_schema) turned into
// control descriptions: what widget, range, step, label and help text each parameter gets.
// Pure (no DOM) so node's test runner checks it; controls.js builds the lil-gui widgets from these
// descriptions.

import { validateJson } from './protocol.js';

/** The kind of widget a parameter schema gets: 'number', 'integer', 'boolean', 'enum' or 'text'. */
export function widgetKind(schema) {
    if (Array.isArray(schema?.enum)) return 'enum';
    if (schema?.type === 'integer') return 'integer';
    if (schema?.type === 'number') return 'number';
    if (schema?.type === 'boolean') return 'boolean';
    return 'text';
}

/** A round step of about 1/200 of the range (1, 2 or 5 times a power of ten). */
export function niceStep(min, max) {
    const raw = (max - min) / 200;
    if (!(raw > 0) || !Number.isFinite(raw)) return 0.01;
    const p = 10 ** Math.floor(Math.log10(raw));
    const m = raw / p;
    return Number(((m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p).toPrecision(6));
}

/** "vpl_grid (VPLs per side)": the name with the unit, as the control's label. */
export function paramLabel(name, schema) {
    return schema?.['x-unit'] ? `${name} (${schema['x-unit']})` : name;
}

function formatNumber(v) {
    return Number.isInteger(v) ? String(v) : String(Number(v.toPrecision(6)));
}

/** "range 1 to 256 VPLs per side", "at least 0 m", or '' for a schema without bounds. */
export function rangeText(schema) {
    const unit = schema?.['x-unit'] ? ` ${schema['x-unit']}` : '';
    if (Number.isFinite(schema?.minimum) && Number.isFinite(schema?.maximum)) {
        return `range ${formatNumber(schema.minimum)} to ${formatNumber(schema.maximum)}${unit}`;
    }
    if (Number.isFinite(schema?.minimum)) return `at least ${formatNumber(schema.minimum)}${unit}`;
    if (Number.isFinite(schema?.maximum)) return `at most ${formatNumber(schema.maximum)}${unit}`;
    return '';
}

/** One line of help: the description, then range, default and source. */
export function paramHelp(schema) {
    const parts = [];
    if (schema?.description) parts.push(schema.description);
    const range = rangeText(schema);
    if (range) parts.push(range);
    if (Array.isArray(schema?.enum)) parts.push(`one of ${schema.enum.join(', ')}`);
    if (schema?.default !== undefined) parts.push(`default ${schema.default}`);
    if (schema?.['x-source']) parts.push(`source: ${schema['x-source']}`);
    return parts.join(' · ');
}

/**
 * What control a parameter gets: {name, kind, label, help, min?, max?, step?, options?,
 * initial}. Numbers with both bounds get a slider over exactly the schema's range, so a slider
 * cannot produce a value the server would refuse.
 */
export function controlSpec(name, schema, value) {
    const kind = widgetKind(schema);
    const spec = { name, kind, label: paramLabel(name, schema), help: paramHelp(schema) };
    const initial = value !== undefined ? value : schema?.default;
    if (kind === 'integer' || kind === 'number') {
        if (Number.isFinite(schema.minimum)) spec.min = schema.minimum;
        if (Number.isFinite(schema.maximum)) spec.max = schema.maximum;
        if (kind === 'integer') spec.step = 1;
        else if (spec.min !== undefined && spec.max !== undefined) spec.step = niceStep(spec.min, spec.max);
        spec.initial = typeof initial === 'number' ? initial : (spec.min ?? 0);
    } else if (kind === 'boolean') {
        spec.initial = Boolean(initial);
    } else if (kind === 'enum') {
        spec.options = [...schema.enum];
        spec.initial = schema.enum.some((o) => o === initial) ? initial : schema.enum[0];
    } else {
        spec.initial = initial === undefined ? '' : String(initial);
    }
    return spec;
}

/** {name: default} of a parameter schema: what a technique's parameters reset to. */
export function schemaDefaults(schema) {
    return Object.fromEntries(Object.entries(schema?.properties ?? {})
        .filter(([, s]) => s.default !== undefined)
        .map(([k, s]) => [k, s.default]));
}

/**
 * The parameters in which a rendered frame (stats.params) differs from the session's own values:
 * what the adaptive-quality preset of that frame changed. [[name, frameValue, ownValue]].
 */
export function presetChanges(frameParams, ownParams) {
    if (!frameParams || !ownParams) return [];
    return Object.entries(frameParams)
        .filter(([k, v]) => Object.hasOwn(ownParams, k) && ownParams[k] !== v)
        .map(([k, v]) => [k, v, ownParams[k]]);
}

/**
 * A number typed into a parameter's field: {value} when the schema accepts it, else {error}, a
 * sentence naming the parameter and its range. A slider cannot leave the range, but the field
 * accepts any text, and lil-gui would clamp 9999 to the maximum and send that.
 */
export function checkTypedNumber(name, schema, text) {
    const typed = String(text ?? '').trim();
    const value = typed === '' ? NaN : Number(typed);
    const range = rangeText(schema);
    const within = range ? ` (${range})` : '';
    if (!Number.isFinite(value)) return { error: `${name}: "${typed}" is not a number${within}; not sent.` };
    if (schema?.type === 'integer' && !Number.isInteger(value)) {
        return { error: `${name}: ${typed} is not a whole number${within}; not sent.` };
    }
    if (validateJson(value, schema)) return { error: `${name}: ${typed} is out of range${within}; not sent.` };
    return { value };
}

/**
 * The properties of a parameter schema in the order the controls show them: the server's order
 * (most important first), or `x-order` where the schema carries it, since a JSON object's key
 * order may not survive every encoder.
 */
export function orderedProperties(schema) {
    const entries = Object.entries(schema?.properties ?? {});
    const rank = (s) => (Number.isFinite(s?.['x-order']) ? s['x-order'] : Infinity);
    return entries
        .map((entry, i) => ({ entry, i }))
        .sort((a, b) => (rank(a.entry[1]) - rank(b.entry[1])) || (a.i - b.i))
        .map(({ entry }) => entry);
}

/**
 * What "Reset parameters" sends. The protocol has no message that forgets explicit values, but a
 * `technique` message naming the current technique resets its parameters and forgets the explicit
 * ones, so the adaptive presets apply to them again: {technique: true} when any technique
 * parameter is explicit or off its default. Frame parameters can only be set: `frame` holds those
 * whose value differs from the default (a frame parameter set before stays explicit, at its
 * default).
 */
export function resetPlan({ techniqueSchema, frameSchema, params = {}, explicit = new Set() }) {
    const techniqueDefaults = schemaDefaults(techniqueSchema);
    const technique = Object.keys(techniqueSchema?.properties ?? {})
        .some((k) => explicit.has(k) || (Object.hasOwn(params, k) && params[k] !== techniqueDefaults[k]));
    const frame = Object.fromEntries(Object.entries(schemaDefaults(frameSchema))
        .filter(([k, v]) => Object.hasOwn(params, k) && params[k] !== v));
    return { technique, frame, techniqueDefaults };
}
