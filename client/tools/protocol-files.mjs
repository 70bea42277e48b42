// Reads the shared protocol files (protocol/schema, protocol/http, protocol/vectors) for the JS tests
// and client/tools/update-schemas.mjs.
import { readFileSync, readdirSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

export const PROTOCOL_DIR = fileURLToPath(new URL('../../protocol/', import.meta.url));

function jsonFilesIn(dir) {
    return readdirSync(dir)
        .filter((f) => f.endsWith('.json'))
        .sort()
        .map((f) => ({ name: f, path: path.join(dir, f) }));
}

/** {type: schema} for every protocol/schema/<type>.json. */
export function loadProtocolSchemas() {
    const schemas = {};
    for (const f of jsonFilesIn(path.join(PROTOCOL_DIR, 'schema'))) {
        schemas[path.basename(f.name, '.json')] = JSON.parse(readFileSync(f.path, 'utf8'));
    }
    return schemas;
}

/** {type: schema} for every protocol/schema/server/<type>.json (what the server sends as text). */
export function loadServerSchemas() {
    const schemas = {};
    for (const f of jsonFilesIn(path.join(PROTOCOL_DIR, 'schema', 'server'))) {
        schemas[path.basename(f.name, '.json')] = JSON.parse(readFileSync(f.path, 'utf8'));
    }
    return schemas;
}

/** protocol/messages.json: every message, who may send it and who answers it. */
export function loadMessageTable() {
    return JSON.parse(readFileSync(path.join(PROTOCOL_DIR, 'messages.json'), 'utf8'));
}

/** protocol/codecs.json's rows: {id, name, mime, extensions, lossy, lossless}. */
export function loadCodecTable() {
    return JSON.parse(readFileSync(path.join(PROTOCOL_DIR, 'codecs.json'), 'utf8')).codecs;
}

/** protocol/http/render_request.json: the body of POST /api/render. */
export function loadRenderRequestSchema() {
    return JSON.parse(readFileSync(path.join(PROTOCOL_DIR, 'http', 'render_request.json'), 'utf8'));
}

/** [{name, message}] for protocol/vectors/<kind>/*.json, kind being 'valid' or 'invalid'. */
export function loadVectors(kind) {
    return jsonFilesIn(path.join(PROTOCOL_DIR, 'vectors', kind)).map((f) => ({
        name: f.name,
        message: JSON.parse(readFileSync(f.path, 'utf8')),
    }));
}
