#!/usr/bin/env bash
# Error against time of the non-diffuse effects (docs/nondiffuse.md) on builtin:gallery: one
# `gi-bench table` run (every configuration timed side by side against one cached CPU reference),
# then the plot docs/images/nondiffuse_gallery.png and the table between the nondiffuse markers of
# docs/accuracy.md (gi-bench report keeps that block when it regenerates the file).
#
#   bench/nondiffuse/run.sh [BUILD_DIR]      (default build/release; about 5 minutes on 2 cores)
#
# Environment: SIZE (128x128), SPP (1024), FRAMES (3).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build/release}"
SIZE="${SIZE:-128x128}"
SPP="${SPP:-1024}"
FRAMES="${FRAMES:-3}"
OUT="$ROOT/build/bench-nondiffuse"
mkdir -p "$OUT"

# The GL pipeline renders one bounce plus specular reflections of the directly lit scene; the
# reference is one-bounce with the caustics off lobes smoother than glossy_split left out (docs).
all="effect_specular=on,effect_glossy=on,effect_env=on,effect_mirrors=on"
# The first configuration's parameters render the reference (gi-bench table): every effect on, so the
# reference has the full reflection model (effect_specular=off would drop its specular lobes).
configs=(
    "rsm_gather:$all"
    "rsm_gather:effect_specular=off,effect_glossy=off,effect_env=off,effect_mirrors=off"
    "rsm_gather:effect_specular=on,effect_glossy=off,effect_env=off,effect_mirrors=off"
    "rsm_gather:effect_specular=on,effect_glossy=on,effect_env=off,effect_mirrors=off"
    "rsm_gather:effect_specular=on,effect_glossy=on,effect_env=off,effect_mirrors=on"
    "rsm_gather:$all,env_size=16"
    "rsm_gather:$all,env_size=32"
    "rsm_gather:$all,env_size=64"
    "rsm_gather:$all,env_size=256"
    "rsm_gather:$all,env_samples=8"
    "rsm_gather:$all,env_samples=128"
    "rsm_gather:$all,env_parallax=off"
    "rsm_gather:$all,mirror_blur=on"
    "rsm_gather:$all,vpl_grid=8"
    "rsm_gather:$all,vpl_grid=32"
    "rsm_gather:effect_specular=on,effect_glossy=off,effect_env=on,effect_mirrors=on"
    "multires_splat:$all,refinement=illumination"
    "multires_gather:$all"
)
args=()
for c in "${configs[@]}"; do args+=(--config "$c"); done
"$BUILD/bin/gi-bench" table --scene builtin:gallery --size "$SIZE" --frames "$FRAMES" --spp "$SPP" \
    --reference one-bounce --caustic-min-roughness 0.35 --timing finish "${args[@]}" \
    --json "$OUT/table.json" | tee "$OUT/table.txt"

python3 "$ROOT/bench/nondiffuse/report.py" "$OUT/table.json" "$ROOT/docs/accuracy.md" \
    "$ROOT/docs/images/nondiffuse_gallery.png" "$SIZE" "$SPP"
