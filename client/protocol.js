// Wire protocol v2 (protocol/PROTOCOL.md): message builders, the binary frame header and the
// JSON-Schema subset validator. Pure functions without DOM access so node's test runner can load
// this module as it is.

import { CODEC_TABLE, MESSAGES, SERVER_SCHEMAS } from './schemas.js';

export const PROTOCOL_VERSION = 2;
export const SUBPROTOCOL = 'gi-stream';
export const CLIENT_NAME = 'gi-web/0.2';

// Both lists come from protocol/messages.json (through the generated schemas.js).
export const CLIENT_MESSAGE_TYPES = Object.freeze(Object.keys(MESSAGES.client));

// What the server sends as text. A type outside this list is logged and ignored, so a newer
// server's additions cannot break the page.
export const SERVER_MESSAGE_TYPES = Object.freeze(Object.keys(MESSAGES.server));

// The bounds of the resize/hello schemas; the server scales the product size x dpr down to its
// own limits.max_size, so the client only has to stay inside the schema.
export const MIN_VIEWPORT_SIDE = 16;
export const MAX_VIEWPORT_SIDE = 8192;
export const MIN_DPR = 0.25;
export const MAX_DPR = 4;

// ---------------------------------------------------------------------------------------------
// Message builders

const HELLO_FIELDS = ['client', 'token', 'resume', 'view', 'codecs', 'quality', 'max_in_flight', 'adaptive', 'size', 'dpr',
    'frame_target_ms', 'patches'];

/** The opening message; only the fields given (not undefined) are sent, so the server's defaults apply to the rest. */
export function helloMsg(fields = {}) {
    const msg = { type: 'hello', protocol: PROTOCOL_VERSION };
    for (const key of HELLO_FIELDS) {
        const value = fields[key];
        if (value !== undefined) msg[key] = Array.isArray(value) ? [...value] : value;
    }
    return msg;
}

export function cameraMsg({ position, target, up, fov_deg: fovDeg }) {
    const msg = { type: 'camera', position: [...position], target: [...target] };
    if (up !== undefined) msg.up = [...up];
    if (fovDeg !== undefined) msg.fov_deg = fovDeg;
    return msg;
}

/**
 * Changes to one light: the light `id` (else the `id` among the changes) in protocol 2's nested
 * form, where `type` may change the light's type. Without an id the fields go flat, protocol 1's
 * form, which edits the first light; a light type cannot be given there, since `type` is the
 * message's own.
 */
export function lightMsg(changes, id = changes.id) {
    const fields = structuredClone(changes);
    delete fields.id;
    if (id !== undefined && id !== null) return { type: 'light', id, light: fields };
    delete fields.type;
    return { type: 'light', ...fields };
}

/** Adds a light (protocol 2); the server assigns its id and answers with a state message. */
export function lightAddMsg(light) {
    return light === undefined ? { type: 'light_add' } : { type: 'light_add', light: structuredClone(light) };
}

/** Removes the light `id` (protocol 2); the server answers with a state message. */
export function lightRemoveMsg(id) {
    return { type: 'light_remove', id };
}

export function techniqueMsg(name) {
    return { type: 'technique', name };
}

export function paramsMsg(values) {
    return { type: 'params', values: { ...values } };
}

/** Viewport size in CSS pixels; the server renders size x dpr. */
export function resizeMsg(width, height, dpr) {
    const msg = { type: 'resize', size: [width, height] };
    if (dpr !== undefined) msg.dpr = dpr;
    return msg;
}

export function sceneMsg(name) {
    return { type: 'scene', name };
}

/** Adaptive quality on or off; `frameTargetMs` (protocol 2, 20..1000) also changes the frame-time target. */
export function qualityMsg(adaptive, frameTargetMs) {
    const msg = { type: 'quality', adaptive };
    if (frameTargetMs !== undefined) msg.frame_target_ms = frameTargetMs;
    return msg;
}

/** codec 'png' (the server's default) or 'webp'; both lossless. */
export function snapshotMsg(codec) {
    return codec === undefined ? { type: 'snapshot' } : { type: 'snapshot', codec };
}

export function ackMsg(frame) {
    return { type: 'ack', frame };
}

export function pingMsg(t) {
    return t === undefined ? { type: 'ping' } : { type: 'ping', t };
}

/**
 * The viewport to announce (hello, resize) for a canvas of cssWidth x cssHeight CSS pixels:
 * {size: [w, h] whole CSS pixels, dpr}, both clamped into the schema's ranges so that the
 * message is always valid. Capping the pixel count is the server's job (limits.max_size).
 */
export function viewportFor(cssWidth, cssHeight, devicePixelRatio = 1) {
    const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));
    const side = (v) => clamp(Math.round(Number.isFinite(v) ? v : 0), MIN_VIEWPORT_SIDE, MAX_VIEWPORT_SIDE);
    const dpr = Number.isFinite(devicePixelRatio) && devicePixelRatio > 0 ? devicePixelRatio : 1;
    return { size: [side(cssWidth), side(cssHeight)], dpr: clamp(dpr, MIN_DPR, MAX_DPR) };
}

// ---------------------------------------------------------------------------------------------
// Binary frames

export const FRAME_MAGIC = 'GIFR';
export const FRAME_HEADER_BYTES = 16;
// From protocol/codecs.json (through the generated schemas.js): header byte -> name, name -> MIME type.
export const CODECS = Object.freeze(Object.fromEntries(CODEC_TABLE.map((c) => [c.id, c.name])));
export const CODEC_MIME = Object.freeze(Object.fromEntries(CODEC_TABLE.map((c) => [c.name, c.mime])));

function asDataView(buffer) {
    if (buffer instanceof ArrayBuffer) return new DataView(buffer);
    if (ArrayBuffer.isView(buffer)) return new DataView(buffer.buffer, buffer.byteOffset, buffer.byteLength);
    throw new TypeError('frame must be an ArrayBuffer or a typed array');
}

/**
 * Parses and validates the 16-byte header of a binary frame. Returns
 * {frame, width, height, codec, payloadOffset}, codec being 'jpeg', 'png' or 'webp'; throws an Error
 * saying what is wrong on a frame that does not follow the protocol.
 */
export function parseFrameHeader(buffer) {
    const view = asDataView(buffer);
    if (view.byteLength < FRAME_HEADER_BYTES) {
        throw new Error(`frame too short: ${view.byteLength} bytes, the header alone has ${FRAME_HEADER_BYTES}`);
    }
    const magic = String.fromCharCode(view.getUint8(0), view.getUint8(1), view.getUint8(2), view.getUint8(3));
    if (magic !== FRAME_MAGIC) throw new Error(`bad frame magic ${JSON.stringify(magic)}, expected "GIFR"`);
    const width = view.getUint16(8, true);
    const height = view.getUint16(10, true);
    if (width === 0 || height === 0) throw new Error(`bad frame size ${width}x${height}`);
    const codecId = view.getUint8(12);
    const codec = CODECS[codecId];
    if (!codec) throw new Error(`unknown frame codec ${codecId}`);
    // The reserved bytes 13..15 are not checked so that a later minor version may use them.
    return { frame: view.getUint32(4, true), width, height, codec, payloadOffset: FRAME_HEADER_BYTES };
}

/** Builds a frame as the server does; for tests and tools. */
export function buildFrameHeader({ frame, width, height, codec = 'jpeg' }) {
    const header = new ArrayBuffer(FRAME_HEADER_BYTES);
    const view = new DataView(header);
    for (let i = 0; i < 4; ++i) view.setUint8(i, FRAME_MAGIC.charCodeAt(i));
    view.setUint32(4, frame, true);
    view.setUint16(8, width, true);
    view.setUint16(10, height, true);
    const codecId = Number(Object.keys(CODECS).find((k) => CODECS[k] === codec));
    if (!codecId) throw new Error(`unknown codec ${codec}`);
    view.setUint8(12, codecId);
    return header;
}

// ---------------------------------------------------------------------------------------------
// JSON-Schema subset: the same keywords and the same checking order as the server's validator
// (server/core/JsonSchema.cpp), so the client reports what the server would and sends nothing the
// server would reject.

function jsonTypeMatches(value, type) {
    switch (type) {
    case 'object': return value !== null && typeof value === 'object' && !Array.isArray(value);
    case 'array': return Array.isArray(value);
    case 'string': return typeof value === 'string';
    case 'boolean': return typeof value === 'boolean';
    case 'null': return value === null;
    case 'number': return typeof value === 'number';
    case 'integer': return typeof value === 'number' && Number.isInteger(value);
    default: return false;
    }
}

function describeValue(value) {
    let s = JSON.stringify(value);
    if (s === undefined) s = String(value);
    return s.length > 60 ? `${s.slice(0, 57)}...` : s;
}

function escapePointerToken(key) {
    return key.replace(/~/g, '~0').replace(/\//g, '~1');
}

// JSON equality for const and enum: key order of objects does not matter.
function jsonEqual(a, b) {
    if (a === b) return true;
    if (typeof a !== typeof b || a === null || b === null || typeof a !== 'object') return false;
    if (Array.isArray(a) !== Array.isArray(b)) return false;
    if (Array.isArray(a)) return a.length === b.length && a.every((v, i) => jsonEqual(v, b[i]));
    const keys = Object.keys(a);
    return keys.length === Object.keys(b).length && keys.every((k) => Object.hasOwn(b, k) && jsonEqual(a[k], b[k]));
}

// The server measures string lengths in UTF-8 bytes; counting the same way keeps both sides in step.
const utf8 = new TextEncoder();
function byteLength(s) {
    return utf8.encode(s).length;
}

function violation(where, message) {
    return { where, message };
}

function checkType(value, schema, at) {
    if (schema.type === undefined) return null;
    const types = Array.isArray(schema.type) ? schema.type : [schema.type];
    if (types.some((t) => jsonTypeMatches(value, t))) return null;
    return violation(at, `expected ${types.join(' or ')}, got ${describeValue(value)}`);
}

function checkConstAndEnum(value, schema, at) {
    if ('const' in schema && !jsonEqual(value, schema.const)) {
        return violation(at, `must be ${JSON.stringify(schema.const)}, got ${describeValue(value)}`);
    }
    if (Array.isArray(schema.enum) && !schema.enum.some((option) => jsonEqual(option, value))) {
        return violation(at, `must be one of ${JSON.stringify(schema.enum)}, got ${describeValue(value)}`);
    }
    return null;
}

function checkNumber(value, schema, at) {
    if (!Number.isFinite(value)) return violation(at, 'must be a finite number');
    if (schema.minimum !== undefined && value < schema.minimum) {
        return violation(at, `must be >= ${schema.minimum}, got ${describeValue(value)}`);
    }
    if (schema.maximum !== undefined && value > schema.maximum) {
        return violation(at, `must be <= ${schema.maximum}, got ${describeValue(value)}`);
    }
    if (schema.exclusiveMinimum !== undefined && value <= schema.exclusiveMinimum) {
        return violation(at, `must be > ${schema.exclusiveMinimum}, got ${describeValue(value)}`);
    }
    if (schema.exclusiveMaximum !== undefined && value >= schema.exclusiveMaximum) {
        return violation(at, `must be < ${schema.exclusiveMaximum}, got ${describeValue(value)}`);
    }
    return null;
}

function checkString(value, schema, at) {
    const len = byteLength(value);
    if (schema.minLength !== undefined && len < schema.minLength) {
        return violation(at, `must have at least ${schema.minLength} characters`);
    }
    if (schema.maxLength !== undefined && len > schema.maxLength) {
        return violation(at, `must have at most ${schema.maxLength} characters`);
    }
    return null;
}

function checkArray(value, schema, at) {
    if (schema.minItems !== undefined && value.length < schema.minItems) {
        return violation(at, `must have at least ${schema.minItems} items, got ${value.length}`);
    }
    if (schema.maxItems !== undefined && value.length > schema.maxItems) {
        return violation(at, `must have at most ${schema.maxItems} items, got ${value.length}`);
    }
    if (schema.items !== undefined) {
        for (let i = 0; i < value.length; ++i) {
            const v = checkValue(value[i], schema.items, `${at}/${i}`);
            if (v) return v;
        }
    }
    return null;
}

function checkObject(value, schema, at) {
    for (const key of schema.required ?? []) {
        if (!Object.hasOwn(value, key)) return violation(at, `missing required field '${key}'`);
    }
    const props = schema.properties ?? null;
    const additional = schema.additionalProperties;
    for (const [key, child] of Object.entries(value)) {
        const where = `${at}/${escapePointerToken(key)}`;
        let v = null;
        if (props && Object.hasOwn(props, key)) {
            v = checkValue(child, props[key], where);
        } else if (additional === false) {
            v = violation(where, `unknown field '${key}'`);
        } else if (additional !== undefined) {
            v = checkValue(child, additional, where);
        }
        if (v) return v;
    }
    return null;
}

function checkValue(value, schema, at) {
    if (schema === true || schema === undefined) return null;
    if (schema === false) return violation(at, 'is not allowed here');
    if (schema === null || typeof schema !== 'object') return null;
    const checks = [checkType, checkConstAndEnum];
    if (typeof value === 'number') checks.push(checkNumber);
    if (typeof value === 'string') checks.push(checkString);
    if (Array.isArray(value)) checks.push(checkArray);
    else if (value !== null && typeof value === 'object') checks.push(checkObject);
    for (const check of checks) {
        const v = check(value, schema, at);
        if (v) return v;
    }
    return null;
}

/**
 * Checks `value` against a JSON schema of the protocol's subset. Returns null when it conforms,
 * else the first violation as {where: JSON pointer ("" for the root), message}.
 */
export function validateJson(value, schema) {
    return checkValue(value, schema, '');
}

/**
 * Checks an outgoing client message. `schemas` maps each message type to its schema
 * (protocol/schema/<type>.json). Returns null when the message may be sent, else
 * {code, where, message} with the error code the server would answer with.
 */
export function validateClientMessage(msg, schemas) {
    if (msg === null || typeof msg !== 'object' || Array.isArray(msg)) {
        return { code: 'invalid_message', where: '', message: `expected object, got ${describeValue(msg)}` };
    }
    if (!Object.hasOwn(msg, 'type')) {
        return { code: 'invalid_message', where: '/type', message: "missing required field 'type'" };
    }
    if (typeof msg.type !== 'string') {
        return { code: 'invalid_message', where: '/type', message: `expected string, got ${describeValue(msg.type)}` };
    }
    const schema = Object.hasOwn(schemas, msg.type) ? schemas[msg.type] : undefined;
    if (!schema) {
        return { code: 'unknown_type', where: '/type', message: `unknown message type '${msg.type}'` };
    }
    const v = validateJson(msg, schema);
    return v ? { code: 'invalid_message', ...v } : null;
}

/**
 * Checks parameter values against the parameter schemas from welcome (the technique's
 * params_schema and frame_params_schema). Returns null or {code: 'invalid_param', where, message}.
 */
export function validateParamValues(values, ...paramSchemas) {
    for (const [name, value] of Object.entries(values)) {
        const schema = paramSchemas.map((s) => s?.properties?.[name]).find((s) => s !== undefined);
        const where = `/values/${escapePointerToken(name)}`;
        if (!schema) return { code: 'invalid_param', where, message: `unknown parameter '${name}'` };
        const v = validateJson(value, schema);
        if (v) return { code: 'invalid_param', where: where + v.where, message: v.message };
    }
    return null;
}

/**
 * Checks a message the server sent against protocol/schema/server/<type>.json. Returns null when it
 * conforms (or is of a type this client does not know: newer servers may add some), else
 * {where, message}.
 */
export function validateServerMessage(msg) {
    const schema = Object.hasOwn(SERVER_SCHEMAS, msg?.type) ? SERVER_SCHEMAS[msg.type] : undefined;
    return schema ? validateJson(msg, schema) : null;
}

/** Whether `type` is a server message this client knows (SERVER_MESSAGE_TYPES). */
export function isKnownServerMessage(type) {
    return SERVER_MESSAGE_TYPES.includes(type);
}

/** Parses a server text message; returns null for anything that is not a JSON object with a type. */
export function parseServerMessage(text) {
    let msg;
    try {
        msg = JSON.parse(text);
    } catch {
        return null;
    }
    if (msg === null || typeof msg !== 'object' || Array.isArray(msg) || typeof msg.type !== 'string') return null;
    return msg;
}
