#!/usr/bin/env bash
# The steps of the gi-server image, shared by deploy/Dockerfile (each RUN calls one) and
# deploy/container/host-run.sh (which runs them on a machine without a container engine), so that
# both install the same packages, build the same way, lay out the same files and create the same
# user.
#
#   steps.sh packages build|runtime [--clean]   install the list's missing Debian packages
#                                               (--clean: drop apt's caches, for image layers)
#   steps.sh client-assets SRC                  fill SRC/client/vendor/ from npm when it is stale
#   steps.sh build SRC BUILD_DIR                Release build of gi-server and gi-render
#   steps.sh configure SRC BUILD_DIR            only its CMake configuration (a quick check)
#   steps.sh stage SRC BUILD_DIR PREFIX         the runtime layout: PREFIX/{bin,client,presets}
#   steps.sh user                               the non-root user gi (uid/gid 10001)
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# The Dockerfile's `USER 10001:10001` and the Kubernetes manifests' runAsUser use these numbers.
GI_USER=gi
GI_UID=10001

say() { echo "steps.sh: $*"; }
die() {
    echo "steps.sh: $*" >&2
    exit 1
}

# Package names of a list file: one per line, '#' starts a comment.
list_packages() { sed -e 's/#.*//' -e 's/[[:space:]]//g' "$1" | grep -v '^$'; }

packages() {
    local kind="${1:?build or runtime}" clean="${2:-}" list missing=()
    list="$HERE/$kind-packages.txt"
    [[ -f "$list" ]] || die "no package list $list"
    while read -r p; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" && continue
        # As deploy/install-deps.sh: node and npm may come from outside Debian (e.g. nodesource).
        case "$p" in
            nodejs) command -v node >/dev/null 2>&1 && continue ;;
            npm) command -v npm >/dev/null 2>&1 && continue ;;
        esac
        missing+=("$p")
    done < <(list_packages "$list")
    if ((${#missing[@]})); then
        [[ $(id -u) -eq 0 ]] || die "missing packages (install them as root): ${missing[*]}"
        say "installing ${missing[*]}"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq
        apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    else
        say "$kind packages: all $(list_packages "$list" | wc -l) present"
    fi
    if [[ "$clean" == --clean ]]; then
        apt-get clean
        rm -rf /var/lib/apt/lists/*
    fi
}

# client/vendor/ (lil-gui, uPlot) is git-ignored and copied from node_modules by npm's postinstall
# (client/tools/vendor.mjs).
client_assets() {
    local src="${1:?SRC}"
    [[ -f "$src/client/tools/vendor.mjs" ]] || return 0
    if node "$src/client/tools/vendor.mjs" --check >/dev/null 2>&1; then
        say "client/vendor is current"
        return 0
    fi
    say "npm ci (client/vendor)"
    (cd "$src" && npm ci --no-audit --no-fund --loglevel=error && node client/tools/vendor.mjs)
}

configure() {
    local src="${1:?SRC}" dir="${2:?BUILD_DIR}"
    cmake -S "$src" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGIS_BUILD_TESTS=OFF >/dev/null
}

build() {
    configure "$@"
    cmake --build "$2" --target gi-server gi-render
}

stage() {
    local src="${1:?SRC}" dir="${2:?BUILD_DIR}" prefix="${3:?PREFIX}"
    for b in gi-server gi-render; do [[ -x "$dir/bin/$b" ]] || die "no $dir/bin/$b (build it first)"; done
    install -d -m 0755 "$prefix/bin" "$prefix/client" "$prefix/presets"
    install -m 0755 "$dir/bin/gi-server" "$dir/bin/gi-render" "$prefix/bin/"
    # What gi-server serves: the client without its tests and tools.
    cp -R "$src/client/." "$prefix/client/"
    rm -rf "$prefix/client/test" "$prefix/client/tools"
    install -m 0644 "$src/presets/presets.json" "$prefix/presets/"
    chmod -R a+rX "$prefix"
    say "staged $(find "$prefix" -type f | wc -l) files in $prefix"
}

user() {
    if getent passwd "$GI_USER" >/dev/null; then
        local uid
        uid="$(id -u "$GI_USER")"
        [[ "$uid" == "$GI_UID" ]] || say "note: user $GI_USER exists with uid $uid, not $GI_UID"
        return 0
    fi
    getent group "$GI_USER" >/dev/null ||
        groupadd --system --gid "$GI_UID" "$GI_USER" 2>/dev/null || groupadd --system "$GI_USER"
    useradd --system --uid "$GI_UID" --gid "$GI_USER" --no-create-home --home-dir /nonexistent \
        --shell /usr/sbin/nologin "$GI_USER" 2>/dev/null ||
        useradd --system --gid "$GI_USER" --no-create-home --home-dir /nonexistent --shell /usr/sbin/nologin \
            "$GI_USER"
    say "created user $GI_USER ($(id "$GI_USER"))"
}

cmd="${1:-}"
shift || true
case "$cmd" in
    packages) packages "$@" ;;
    client-assets) client_assets "$@" ;;
    configure) configure "$@" ;;
    build) build "$@" ;;
    stage) stage "$@" ;;
    user) user ;;
    uid) echo "$GI_UID" ;;
    *) sed -n '2,14p' "${BASH_SOURCE[0]}" >&2; exit 2 ;;
esac
