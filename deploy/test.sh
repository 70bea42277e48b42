#!/usr/bin/env bash
# Installs what is missing, builds (Release, warnings as errors) and runs every test through CTest.
# Exits non-zero on any failure. BUILD_DIR and JOBS may be overridden.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build/ci}"
JOBS="${JOBS:-$(nproc)}"

bash "$ROOT/deploy/install-deps.sh"

cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGIS_WERROR=ON >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"

# Tests that render share the 2 cores with llvmpipe's own threads: run them two at a time.
cd "$BUILD_DIR"
ctest --output-on-failure -j 2 --timeout 600 "$@"
