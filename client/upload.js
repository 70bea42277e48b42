// Scene uploads: POST /api/upload?name=N.glb (or N.zip: a .gltf with its .bin and textures) with the
// session's resume token in X-GI-Session (PROTOCOL.md, HTTP API); the server answers
// {"scene": "upload:N.glb"}, a name only that session can load. XMLHttpRequest because fetch()
// reports no upload progress.

import { describeHttpError } from './messages.js';

/**
 * A name the server accepts for `fileName`: letters, digits, '.', '_' and '-', not starting with
 * '.', ending in .glb or .zip, at most 100 characters. Null when the file is neither.
 */
export function uploadName(fileName) {
    const kind = typeof fileName === 'string' ? /\.(glb|zip)$/i.exec(fileName) : null;
    if (!kind) return null;
    let stem = fileName.slice(0, -4).split(/[\\/]/).pop().replace(/[^A-Za-z0-9._-]+/g, '_').replace(/^\.+/, '');
    if (!stem) stem = 'scene';
    return `${stem.slice(0, 96)}.${kind[1].toLowerCase()}`;
}

/** The Content-Type of an upload named by uploadName. */
export function uploadType(name) {
    return name.endsWith('.zip') ? 'application/zip' : 'model/gltf-binary';
}

/**
 * Uploads `file` (a Blob) as `name`; onProgress(fraction 0..1). Resolves the server's answer,
 * rejects with an Error whose message is meant for the user.
 */
export function uploadScene(file, name, { resumeToken, serverToken, onProgress } = {}) {
    return new Promise((resolve, reject) => {
        const xhr = new XMLHttpRequest();
        xhr.open('POST', `api/upload?name=${encodeURIComponent(name)}`);
        xhr.setRequestHeader('Content-Type', uploadType(name));
        if (resumeToken) xhr.setRequestHeader('X-GI-Session', resumeToken);
        if (serverToken) xhr.setRequestHeader('Authorization', `Bearer ${serverToken}`);
        xhr.upload.onprogress = (e) => {
            if (e.lengthComputable) onProgress?.(e.loaded / e.total);
        };
        xhr.onload = () => {
            let body = null;
            try {
                body = JSON.parse(xhr.responseText);
            } catch { /* not JSON: described by the status */ }
            if (xhr.status >= 200 && xhr.status < 300 && typeof body?.scene === 'string') {
                onProgress?.(1);
                resolve(body);
            } else {
                reject(new Error(describeHttpError(xhr.status, body)));
            }
        };
        xhr.onerror = () => reject(new Error('the upload failed: the server could not be reached'));
        xhr.send(file);
    });
}
