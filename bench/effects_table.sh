#!/usr/bin/env bash
# The effect plan against everything on, per built-in scene (docs/effects.md). Everything on = `ssbc`
# (clamp_b 40, one compensation step) with vpl_shadows; the plan = the same with effects=auto.
# Frame times: `gi-bench passes`, both configurations interleaved frame by frame (glFinish timing),
# median of FRAMES. Relative RMSE: `gi-render --compare` against a one-bounce CPU reference at SPP
# (cached under $GI_CACHE_DIR or ~/.cache/gi-render). Planning time is the planner's own (once per
# scene load or material view change, not per frame).
# usage: bench/effects_table.sh [SIZE] [SPP] [FRAMES]   (defaults 256x256 256 7)
set -euo pipefail
BIN=${BIN:-build/dev/bin}
SIZE=${1:-256x256}
SPP=${2:-256}
FRAMES=${3:-7}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
ALL=(--technique ssbc --param vpl_shadows=true --size "$SIZE" --quiet)

echo "| scene | plan turns off | all on ms | plan ms | saved | planning ms | all on rel. RMSE | plan rel. RMSE | plan - all on |"
echo "|---|---|---|---|---|---|---|---|---|"
for scene in cornell cornell-empty cornell-dense crease cornell-black; do
    ref="$WORK/$scene.exr"
    "$BIN/gi-render" --scene "builtin:$scene" --size "$SIZE" --reference one-bounce --spp "$SPP" --out "$ref" --quiet
    "$BIN/gi-render" --scene "builtin:$scene" "${ALL[@]}" --compare "$ref" --stats "$WORK/all.json" >/dev/null
    "$BIN/gi-render" --scene "builtin:$scene" "${ALL[@]}" --compare "$ref" --stats "$WORK/plan.json" \
        --param effects=auto >/dev/null
    spec=$(jq -r 'if .technique == "none" then "none" else
        "\(.technique):vpl_shadows=\(.params.vpl_shadows),ssbc_iterations=\(.params.ssbc_iterations)" end' "$WORK/plan.json")
    "$BIN/gi-bench" passes --scene "builtin:$scene" --size "$SIZE" --frames "$FRAMES" \
        --config ssbc:vpl_shadows=true --config "$spec" --json "$WORK/passes.json" >/dev/null 2>&1
    jq -r --arg scene "$scene" --slurpfile plan "$WORK/plan.json" --slurpfile passes "$WORK/passes.json" '
        def r(n): . * n | round / n;
        . as $all | $plan[0] as $p | $passes[0].rows[0].frame_ms as $ta |
        ($passes[0].rows | last | .frame_ms) as $tp |
        ([$p.plan.decisions[] | select(.enabled | not) | .effect] | join(", ")) as $off |
        "| \($scene) | \(if $off == "" then "-" else $off end) | \($ta | r(10)) | \($tp | r(10)) | \((1 - $tp / $ta) * 100 | r(10))% | \($p.plan.analysis_ms | r(10)) | \($all.compare.relative_rmse * 100 | r(100))% | \($p.compare.relative_rmse * 100 | r(100))% | \(($p.compare.relative_rmse - $all.compare.relative_rmse) * 100 | r(100))% |"
    ' "$WORK/all.json"
done
