// Regenerates client/schemas.js from protocol/schema/**.json, protocol/http/render_request.json and
// protocol/messages.json;
// run after changing a schema:
//   node client/tools/update-schemas.mjs
// (protocol.test.mjs fails while the two differ.)
import { writeFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { loadMessageTable, loadProtocolSchemas, loadRenderRequestSchema, loadServerSchemas } from './protocol-files.mjs';

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
`);
console.log(`wrote ${target} (${Object.keys(schemas).length} schemas)`);
