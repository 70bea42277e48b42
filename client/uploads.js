// Uploads from the page: the Scene section's file picker and files dropped on the view go to
// POST /api/upload (upload.js) with progress, then become this session's scene. Emits upload
// (progress) and scenes.
import { sceneMsg } from './protocol.js';
import { formatBytes } from './stats.js';
import { uploadName, uploadScene } from './upload.js';

/** Wires the picker and the drop zone; `isOpen()` says whether the stream is connected. */
export function bindUploads({ ui, state, store, actions }, { isOpen, serverToken }) {
    const { steer, showMessage } = actions;

    async function uploadFile(file) {
        if (state.viewer) return;
        const name = uploadName(file?.name);
        if (!name) {
            showMessage(`Only binary glTF (.glb) files, or a .gltf zipped with its files (.zip), can be uploaded, not "${file?.name ?? '?'}".`);
            return;
        }
        const resumeToken = state.welcome?.resume_token;
        if (!resumeToken || !isOpen()) {
            showMessage('Connect first: an upload belongs to a session.');
            return;
        }
        const size = formatBytes(file.size);
        store.emit('upload', 0, `uploading ${name} (${size})`);
        try {
            const answer = await uploadScene(file, name, {
                resumeToken,
                serverToken,
                onProgress: (f) => store.emit('upload', f, `uploading ${name}: ${(100 * f).toFixed(0)} % of ${size}`),
            });
            if (!state.uploads.includes(answer.scene)) state.uploads.push(answer.scene);
            store.emit('upload', 1, `uploaded ${name}; loading it…`);
            if (steer(sceneMsg(answer.scene))) state.scene = answer.scene;
            store.emit('scenes');
            setTimeout(() => store.emit('upload', null), 3000);
        } catch (e) {
            store.emit('upload', null);
            showMessage(`Upload of ${name}: ${e.message}`);
        }
    }

    let depth = 0;
    const hasFiles = (e) => [...(e.dataTransfer?.types ?? [])].includes('Files');
    ui.viewport.addEventListener('dragenter', (e) => {
        if (!hasFiles(e) || state.viewer) return;
        e.preventDefault();
        depth += 1;
        ui.dropHint.hidden = false;
    });
    ui.viewport.addEventListener('dragover', (e) => {
        if (!hasFiles(e) || state.viewer) return;
        e.preventDefault();
        e.dataTransfer.dropEffect = 'copy';
    });
    ui.viewport.addEventListener('dragleave', () => {
        depth = Math.max(0, depth - 1);
        if (depth === 0) ui.dropHint.hidden = true;
    });
    ui.viewport.addEventListener('drop', (e) => {
        if (!hasFiles(e)) return;
        e.preventDefault();
        depth = 0;
        ui.dropHint.hidden = true;
        const file = e.dataTransfer.files?.[0];
        if (file) uploadFile(file);
    });
    ui.fileInput.addEventListener('change', () => {
        const file = ui.fileInput.files?.[0];
        ui.fileInput.value = '';
        if (file) uploadFile(file);
    });
}
