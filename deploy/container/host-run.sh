#!/usr/bin/env bash
# deploy/Dockerfile's build and run, on this machine, without a container engine: the same steps
# (deploy/container/steps.sh), the same package lists, the same non-root user, the runtime ENV,
# USER and HEALTHCHECK read from the Dockerfile itself; then a smoke test of the running server
# and a graceful stop. CI runs it as the CTest "deploy_host_run" (with --reuse-build, so nothing is
# compiled twice).
#
#   deploy/container/host-run.sh [--reuse-build BUILD_DIR] [--build-dir DIR] [--prefix DIR] [--keep]
#
#   --reuse-build DIR  take gi-server and gi-render from an existing build tree instead of
#                      compiling them again (the build packages and the CMake configuration
#                      are still checked)
#   --build-dir DIR    where to build otherwise (default build/container)
#   --prefix DIR       the runtime layout, /opt/gi in the image (default: a temporary directory)
#   --keep             leave the prefix in place
#
# Differences from the image, on purpose: the server listens on 127.0.0.1 (GI_HOST from the
# Dockerfile is 0.0.0.0) on a free port; paths under /opt/gi and /tmp map into the prefix; as
# non-root it runs as the current user (no user is created). Exits non-zero on the first failure.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
HERE="$ROOT/deploy/container"
DOCKERFILE="$ROOT/deploy/Dockerfile"
STEPS="$HERE/steps.sh"

reuse="" build_dir="$ROOT/build/container" prefix="" keep=0
while [[ $# -gt 0 ]]; do
    case "$1" in
        --reuse-build) reuse="$(cd "$2" && pwd)"; shift 2 ;;
        --build-dir) build_dir="$2"; shift 2 ;;
        --prefix) prefix="$2"; shift 2 ;;
        --keep) keep=1; shift ;;
        -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
        *) echo "host-run: unknown option $1" >&2; exit 2 ;;
    esac
done

step() { echo "== host-run: $*"; }
fail() {
    echo "host-run: FAIL: $*" >&2
    exit 1
}

# ---- the Dockerfile's runtime stage: ENV, USER, HEALTHCHECK --------------------------------------
# Instructions of one stage with their continuation lines joined.
stage_instructions() {
    awk -v stage="$1" '
        /^FROM / { in_stage = ($0 ~ (" AS " stage "$")) }
        !in_stage || /^[[:space:]]*#/ { next }
        { line = line $0 }
        /\\$/ { sub(/\\$/, "", line); next }
        { print line; line = "" }' "$DOCKERFILE"
}
runtime="$(stage_instructions runtime)"
env_line="$(grep -E '^ENV ' <<<"$runtime" || true)"
user_line="$(grep -E '^USER ' <<<"$runtime" | tail -n 1 || true)"
health_cmd="$(grep -E '^HEALTHCHECK ' <<<"$runtime" | sed -E 's/.* CMD +//' || true)"
[[ -n "$env_line" && -n "$user_line" && -n "$health_cmd" ]] ||
    fail "cannot find ENV, USER and HEALTHCHECK in the runtime stage of $DOCKERFILE"

# ---- drift checks: the Dockerfile, the step script and the package lists agree -------------------
step "checking that deploy/Dockerfile, steps.sh and the package lists agree"
uid="$(bash "$STEPS" uid)"
[[ "$user_line" == "USER $uid:$uid" ]] || fail "Dockerfile has '$user_line', steps.sh creates uid $uid"
for s in "packages build" "packages runtime" "user" "client-assets" "build /src /build" "stage /src /build /opt/gi"; do
    grep -q "steps.sh $s" "$DOCKERFILE" || fail "the Dockerfile does not run 'steps.sh $s'"
done
for list in build-packages.txt runtime-packages.txt; do
    grep -q "deploy/container/$list" "$DOCKERFILE" || fail "the Dockerfile does not copy $list"
done
# The build stage installs a subset of what the project's own installer lists.
while read -r p; do
    grep -qE "(^|[[:space:]])$p([[:space:]]|$)" "$ROOT/deploy/install-deps.sh" ||
        fail "build package $p is not in deploy/install-deps.sh"
done < <(sed -e 's/#.*//' -e 's/[[:space:]]//g' "$HERE/build-packages.txt" | grep -v '^$')

# ---- the build stage -------------------------------------------------------------------------
if [[ -n "$reuse" ]]; then
    # Compiling again would take minutes; the build's configuration (every find_package of the
    # build stage, with its flags) takes seconds and is what a missing build package breaks first.
    step "build: configuring as the image does, then reusing the binaries of $reuse"
    bash "$STEPS" packages build
    configure_dir="$(mktemp -d -t gi-host-configure.XXXXXX)"
    bash "$STEPS" configure "$ROOT" "$configure_dir" || { rm -rf "$configure_dir"; fail "the image's CMake configuration failed"; }
    rm -rf "$configure_dir"
    build_dir="$reuse"
else
    step "build: packages, client assets, Release build in $build_dir"
    bash "$STEPS" packages build
    bash "$STEPS" client-assets "$ROOT"
    bash "$STEPS" build "$ROOT" "$build_dir"
fi
[[ -d "$ROOT/client/vendor" ]] || bash "$STEPS" client-assets "$ROOT"

# ---- the runtime stage -----------------------------------------------------------------------
step "runtime: packages, user, layout"
bash "$STEPS" packages runtime
if [[ -z "$prefix" ]]; then
    prefix="$(mktemp -d -t gi-host-run.XXXXXX)"
fi
mkdir -p "$prefix"
prefix="$(cd "$prefix" && pwd)"
server_pid=""
cleanup() {
    if [[ -n "$server_pid" ]] && kill -0 "$server_pid" 2>/dev/null; then
        kill -KILL "$server_pid" 2>/dev/null || true
    fi
    if [[ "$keep" == 0 ]]; then rm -rf "$prefix"; fi
}
trap cleanup EXIT
chmod 0755 "$prefix"
bash "$STEPS" stage "$ROOT" "$build_dir" "$prefix"
install -d -m 1777 "$prefix/tmp"

# Every library the binaries link directly must come from a package in the runtime list (apt
# brings their own dependencies).
listed="$(sed -e 's/#.*//' -e 's/[[:space:]]//g' "$HERE/runtime-packages.txt" | grep -v '^$')"
declare -A owner_of=()
candidates=()
needed="$(readelf -d "$prefix/bin/gi-server" "$prefix/bin/gi-render" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | sort -u)"
for lib in $needed; do
    path="$(ldconfig -p | awk -v l="$lib" '$1 == l && !found { print $NF; found = 1 }')"
    [[ -n "$path" ]] || fail "the binaries need $lib, which is not installed"
    # dpkg knows one of the names: the /lib symlink's (libc6) or the /usr/lib file's (most others).
    candidates+=("$path" "$(readlink -f "$path")")
done
# One dpkg -S for all (each call reads every package's file list); names it does not know are fine.
while IFS= read -r line; do
    owner_of["${line##*: }"]="${line%%:*}"
done < <(dpkg -S "${candidates[@]}" 2>/dev/null || true)
for ((i = 0; i < ${#candidates[@]}; i += 2)); do
    pkg="${owner_of[${candidates[i]}]:-${owner_of[${candidates[i + 1]}]:-}}"
    [[ -n "$pkg" ]] || fail "no package owns ${candidates[i]}"
    grep -qx "$pkg" <<<"$listed" || fail "${candidates[i]} comes from package '$pkg', missing from runtime-packages.txt"
done
step "every library the binaries link comes from runtime-packages.txt ($((${#candidates[@]} / 2)) libraries)"

run_as=()
if [[ $(id -u) -eq 0 ]]; then
    bash "$STEPS" user
    command -v setpriv >/dev/null || fail "setpriv (util-linux) is needed to drop to the user"
    run_as=(setpriv --reuid="$uid" --regid="$uid" --clear-groups)
    user_name="$(getent passwd "$uid" | cut -d: -f1)"
else
    echo "host-run: note: not root, so no user is created; the server runs as $(id -un)"
    user_name="$(id -un)"
fi

# The image's environment, and nothing else (as in a container), mapped onto the prefix.
# A port the kernel just handed out and released: free unless something takes it in between.
port="$(node -e "const s = require('net').createServer().listen(0, '127.0.0.1', () => { console.log(s.address().port); s.close(); })" 2>/dev/null ||
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
envs=()
for kv in ${env_line#ENV }; do
    key="${kv%%=*}" value="${kv#*=}"
    [[ "$value" == /tmp/* ]] && value="$prefix$value"
    value="${value//\/opt\/gi/$prefix}"
    case "$key" in
        GI_HOST) value=127.0.0.1 ;; # loopback only on a shared machine
        GI_PORT) value="$port" ;;
    esac
    envs+=("$key=$value")
done
envs+=("HOME=/nonexistent" "TMPDIR=$prefix/tmp")
step "starting gi-server as $user_name (uid $(id -u "$user_name")) with: ${envs[*]}"
log="$prefix/tmp/gi-server.log"
"${run_as[@]}" env -i "${envs[@]}" "$prefix/bin/gi-server" >"$log" 2>&1 &
server_pid=$!

# ---- HEALTHCHECK, then smoke ----------------------------------------------------------------
healthy=0
for _ in $(seq 100); do
    if env -i "${envs[@]}" sh -c "$health_cmd" >/dev/null 2>&1; then
        healthy=1
        break
    fi
    kill -0 "$server_pid" 2>/dev/null || { cat "$log" >&2; fail "gi-server exited during start-up"; }
    sleep 0.2
done
[[ "$healthy" == 1 ]] || { cat "$log" >&2; fail "the Dockerfile's HEALTHCHECK did not pass within 20 s"; }
step "HEALTHCHECK passes: $health_cmd"
base="http://127.0.0.1:$port"
curl -fsS "$base/api/techniques" | grep -q '"rsm_gather"' || fail "/api/techniques has no rsm_gather"
curl -fsS -o /dev/null "$base/" || fail "the client is not served at /"
if [[ -f "$prefix/client/vendor/lil-gui.esm.js" ]]; then
    curl -fsS -o /dev/null "$base/vendor/lil-gui.esm.js" || fail "client/vendor is not served"
fi
png="$prefix/tmp/render.png"
curl -fsS -X POST "$base/api/render" -o "$png" \
    -d '{"scene": "builtin:cornell", "technique": "rsm_gather", "params": {"vpl_grid": 4}, "size": [64, 64], "format": "png"}' ||
    fail "POST /api/render failed"
[[ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" == 89504e470d0a1a0a ]] || fail "POST /api/render did not answer a PNG"
step "HTTP API answers: /api/techniques, /, POST /api/render (PNG, $(stat -c %s "$png") bytes)"

if command -v node >/dev/null && [[ -d "$ROOT/node_modules/ws" ]]; then
    node "$HERE/smoke.mjs" --url "ws://127.0.0.1:$port/ws" --pid "$server_pid" || { cat "$log" >&2; fail "WebSocket smoke test"; }
else
    echo "host-run: note: node or the ws package is missing: no WebSocket session; SIGTERM now"
    kill -TERM "$server_pid"
fi
status=0
wait "$server_pid" || status=$?
server_pid=""
grep -q "draining" "$log" || { cat "$log" >&2; fail "the server did not drain on SIGTERM"; }
[[ "$status" == 0 ]] || { cat "$log" >&2; fail "gi-server exited with $status after SIGTERM"; }
step "SIGTERM: drained and exited 0"
[[ "$keep" == 1 ]] && echo "host-run: the layout stays in $prefix"
echo "host-run: ok"
