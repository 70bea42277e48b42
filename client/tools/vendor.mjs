// Copies the browser builds of the client's npm dependencies (lil-gui, uPlot) from node_modules into
// client/vendor/, which index.html's import map points at. client/vendor/ is git-ignored and
// rebuilt by `npm ci` / `npm install` (the postinstall script of package.json runs this file), so
// no third-party source is committed. Copies, not symlinks: gi-server serves only real files
// inside its --client-dir.
//
//   node client/tools/vendor.mjs           copy (what postinstall runs)
//   node client/tools/vendor.mjs --check   exit 1 unless client/vendor/ matches node_modules
import { copyFileSync, existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const REPO = fileURLToPath(new URL('../../', import.meta.url));
const MODULES = path.join(REPO, 'node_modules');
export const VENDOR_DIR = path.join(REPO, 'client', 'vendor');

/** [package, file in the package, name in client/vendor]; the names the import map uses. */
export const VENDOR_FILES = Object.freeze([
    ['lil-gui', 'dist/lil-gui.esm.min.js', 'lil-gui.esm.js'],
    ['lil-gui', 'LICENSE.md', 'lil-gui.LICENSE.md'],
    ['uplot', 'dist/uPlot.esm.js', 'uPlot.esm.js'],
    ['uplot', 'dist/uPlot.min.css', 'uPlot.min.css'],
    ['uplot', 'LICENSE', 'uPlot.LICENSE'],
]);

function packageVersion(name) {
    return JSON.parse(readFileSync(path.join(MODULES, name, 'package.json'), 'utf8')).version;
}

/** Problems that make client/vendor/ unusable or stale; empty when it matches node_modules. */
export function checkVendor() {
    const problems = [];
    for (const [pkg, file, name] of VENDOR_FILES) {
        const source = path.join(MODULES, pkg, file);
        const target = path.join(VENDOR_DIR, name);
        if (!existsSync(source)) problems.push(`node_modules/${pkg}/${file} is missing: run npm ci`);
        else if (!existsSync(target)) {
            problems.push(`client/vendor/${name} is missing: run npm ci (or node client/tools/vendor.mjs)`);
        }
        else if (!readFileSync(source).equals(readFileSync(target))) {
            problems.push(`client/vendor/${name} differs from node_modules/${pkg}/${file}: run node client/tools/vendor.mjs`);
        }
    }
    return problems;
}

export function copyVendor() {
    mkdirSync(VENDOR_DIR, { recursive: true });
    for (const [pkg, file, name] of VENDOR_FILES) {
        const source = path.join(MODULES, pkg, file);
        if (!existsSync(source)) throw new Error(`node_modules/${pkg}/${file} is missing: run npm ci first`);
        copyFileSync(source, path.join(VENDOR_DIR, name));
    }
    const versions = Object.fromEntries([...new Set(VENDOR_FILES.map(([pkg]) => pkg))].map((p) => [p, packageVersion(p)]));
    writeFileSync(path.join(VENDOR_DIR, 'versions.json'), `${JSON.stringify(versions, null, 2)}\n`);
    return versions;
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
    try {
        if (process.argv.includes('--check')) {
            const problems = checkVendor();
            for (const p of problems) console.error(`vendor: ${p}`);
            process.exit(problems.length ? 1 : 0);
        }
        const versions = copyVendor();
        console.log(`vendor: client/vendor/ <- ${Object.entries(versions).map(([p, v]) => `${p}@${v}`).join(', ')}`);
    } catch (e) {
        console.error(`vendor: ${e.message}`);
        process.exit(1);
    }
}
