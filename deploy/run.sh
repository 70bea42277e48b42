#!/usr/bin/env bash
# Installs what is missing, builds Release and starts gi-server on the built-in Cornell box.
# Environment: GI_HOST (default 127.0.0.1), GI_PORT (default 8080), GI_GL (egl|osmesa).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build/release}"
HOST="${GI_HOST:-127.0.0.1}"
PORT="${GI_PORT:-8080}"

bash "$ROOT/deploy/install-deps.sh"
cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGIS_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)"

echo "gi-server: open http://$HOST:$PORT/ in a browser (Ctrl-C stops the server)"
exec "$BUILD_DIR/bin/gi-server" --host "$HOST" --port "$PORT" --scene builtin:cornell --client-dir "$ROOT/client" "$@"
