#!/usr/bin/env bash
# Installs every Debian package the build, the tests and the browser tests need, then the
# client's npm packages from the committed lock file. Idempotent: quiet when all is present,
# and runs `apt-get update` only when something is missing.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

PACKAGES=(
    # toolchain
    build-essential cmake ninja-build pkg-config clang-format
    # headless OpenGL: EGL (surfaceless) and OSMesa on Mesa llvmpipe
    libegl-dev libegl1-mesa-dev libgl-dev libgl1-mesa-dri libosmesa6-dev libgbm-dev
    # scene, math, JSON, images
    # (openimageio-tools: OIIO's CMake config names its command-line tools)
    libglm-dev nlohmann-json3-dev libtinygltf-dev libstb-dev libopenimageio-dev
    openimageio-tools libturbojpeg0-dev libwebp-dev libpng-dev
    # compressed glTF: Draco and meshopt decoding
    libdraco-dev libmeshoptimizer-dev
    # zipped .gltf uploads (a .gltf with its .bin and textures)
    libzip-dev
    # reference renderer
    libembree-dev libtbb-dev
    # network
    libwebsockets-dev
    # tests and benchmarks (gnuplot-nox: gi-bench report's plots)
    libgtest-dev libgmock-dev libbenchmark-dev gnuplot-nox
    # end-to-end and browser tests
    nodejs npm chromium
    # libFuzzer targets (deploy/test.sh's fuzz stage)
    clang libclang-rt-14-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        # nodejs/npm may come from outside Debian's packages (e.g. a nodesource build): accept
        # any working binary of the same name.
        case "$p" in
            nodejs) command -v node >/dev/null 2>&1 && continue ;;
            npm) command -v npm >/dev/null 2>&1 && continue ;;
        esac
        missing+=("$p")
    fi
done

if ((${#missing[@]})); then
    echo "install-deps: installing ${missing[*]}"
    SUDO=""
    if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Node packages for the end-to-end tests and the client, from the committed lock file. npm ci's
# postinstall copies the client's browser libraries (lil-gui, uPlot) into the git-ignored
# client/vendor/ (client/tools/vendor.mjs), so it runs again when that copy is missing.
if [[ -f "$ROOT/package-lock.json" ]]; then
    stamp="$ROOT/node_modules/.install-stamp"
    if [[ ! -f "$stamp" || "$ROOT/package-lock.json" -nt "$stamp" || ! -f "$ROOT/client/vendor/versions.json" ]]; then
        echo "install-deps: npm ci"
        (cd "$ROOT" && npm ci --no-audit --no-fund --loglevel=error)
        touch "$stamp"
    fi
fi
