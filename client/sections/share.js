// The Share section: the view-only link and the lossless snapshot. Hears: welcome, role, share-link.
import { addBlock, block, describe, makeSection } from '../controls.js';

export function createShareSection({ ui, store, actions }) {
    const { copyShareLink, requestSnapshot } = actions;
    const gui = makeSection(ui.sections, 'Share', { id: 'share' });
    const model = {
        copy: () => copyShareLink(),
        snapshot: () => requestSnapshot(),
    };
    const copyCtl = describe(gui.add(model, 'copy').name('Copy view-only link'), 'share-link',
        'a link that shows this view live without steering it');
    const linkBox = addBlock(gui, block('div', 'share-box block'));
    const linkInput = linkBox.appendChild(Object.assign(document.createElement('input'), {
        type: 'text', readOnly: true, className: 'share-url', id: 'share-url',
    }));
    linkInput.setAttribute('aria-label', 'view-only link');
    linkBox.hidden = true;
    describe(gui.add(model, 'snapshot').name('Snapshot (PNG)'), 'snapshot',
        'render the current view at final quality and full size, and save it losslessly');
    const section = {
        gui,
        update() {
            linkBox.hidden = true;
        },
        showLink(link) {
            linkInput.value = link;
            linkBox.hidden = false;
            linkInput.select();
        },
        setViewer(viewer) {
            copyCtl.show(!viewer);
        },
    };
    store.on('welcome', () => section.update());
    store.on('role', (viewer) => section.setViewer(viewer));
    store.on('share-link', (link) => section.showLink(link));
    return section;
}
