// Regenerates client/schemas.js from protocol/schema/**.json, protocol/http/render_request.json and
// protocol/messages.json;
// run after changing a schema:
//   node client/tools/update-schemas.mjs
// (protocol.test.mjs fails while the two differ.)
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import {
    PROTOCOL_DIR, loadCodecTable, loadMessageTable, loadProtocolSchemas, loadRenderRequestSchema, loadServerSchemas,
} from './protocol-files.mjs';

// The codec lists of the schemas come from protocol/codecs.json: each list is rewritten in place (the
// one line that holds it), so the files keep their hand-written layout.
const codecs = loadCodecTable();
const all = codecs.map((c) => c.name);
const lossless = codecs.filter((c) => c.lossless).map((c) => c.name);
function setEnum(relative, key, names) {
    const file = path.join(PROTOCOL_DIR, relative);
    const text = readFileSync(file, 'utf8');
    const lines = text.split('\n');
    const i = lines.findIndex((l) => l.includes(`"${key}": {`) && l.includes('"enum": ['));
    if (i < 0) throw new Error(`${relative}: no one-line "${key}" with an enum`);
    lines[i] = lines[i].replace(/"enum": \[[^\]]*\]/, `"enum": ${JSON.stringify(names).replaceAll(',', ', ')}`)
        .replace(/"maxItems": \d+/, `"maxItems": ${names.length}`); // a list of codecs: each at most once
    const next = lines.join('\n');
    if (next !== text) {
        writeFileSync(file, next);
        console.log(`wrote the codec list of ${relative}`);
    }
}
setEnum('schema/hello.json', 'codecs', all);
setEnum('schema/snapshot.json', 'codec', lossless);
setEnum('http/render_request.json', 'format', all);

const target = fileURLToPath(new URL('../schemas.js', import.meta.url));
const schemas = loadProtocolSchemas();
const entries = (table) => Object.entries(table)
    .map(([type, schema]) => `    ${type}: ${JSON.stringify(schema)},`)
    .join('\n');
const body = entries(schemas);
const serverSchemas = loadServerSchemas();
const table = loadMessageTable();
delete table.$comment;
writeFileSync(target, `// Generated from protocol/schema/*.json and protocol/http/render_request.json by
// client/tools/update-schemas.mjs; do not edit.
// A copy because gi-server serves only client/; client/test/protocol.test.mjs checks it is current.
export const CLIENT_SCHEMAS = Object.freeze({
${body}
});

// POST /api/render (the accuracy view's requests).
export const RENDER_REQUEST_SCHEMA = Object.freeze(${JSON.stringify(loadRenderRequestSchema())});

// What the server sends as text (protocol/schema/server).
export const SERVER_SCHEMAS = Object.freeze({
${entries(serverSchemas)}
});

// protocol/messages.json: every message, who may send it and who answers it.
export const MESSAGES = Object.freeze(${JSON.stringify(table)});

// protocol/codecs.json: the frame header's codec byte, name and MIME type of every codec.
export const CODEC_TABLE = Object.freeze(${JSON.stringify(codecs)});
`);
console.log(`wrote ${target} (${Object.keys(schemas).length} schemas)`);
