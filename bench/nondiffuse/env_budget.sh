#!/usr/bin/env bash
# The environment probes under env_budget_ms (docs/nondiffuse.md, "Probe budget"): builtin:gallery
# with every effect on (the room probe and the gold sphere's), each budget a configuration of
# one `gi-bench table` run (frames interleaved, one cached CPU reference). Every frame renders its
# probes again here (gi-bench does not keep light views), so the probe passes' time is the cost a
# light change pays in the live view; after the warm-up frame each configuration's plan comes from
# what its own probes measured.
#
#   bench/nondiffuse/env_budget.sh [BUILD_DIR]    (default build/release; about 3 minutes on 2 cores)
#
# Environment: SIZE (128x128), SPP (1024), FRAMES (9), BUDGETS ("0 10 20 40 80").
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build/release}"
SIZE="${SIZE:-128x128}"
SPP="${SPP:-1024}"
FRAMES="${FRAMES:-9}"
BUDGETS="${BUDGETS:-0 10 20 40 80}"
OUT="$ROOT/build/bench-env-budget"
mkdir -p "$OUT"

all="effect_specular=on,effect_glossy=on,effect_env=on,effect_mirrors=on"
args=()
for b in $BUDGETS; do args+=(--config "rsm_gather:$all,env_budget_ms=$b"); done
# Time: per-pass medians, interleaved; error: one table run against the reference.
"$BUILD/bin/gi-bench" passes --scene builtin:gallery --size "$SIZE" --frames "$FRAMES" --timing finish \
    "${args[@]}" --json "$OUT/passes.json" >"$OUT/passes.txt" 2>"$OUT/passes.log"
"$BUILD/bin/gi-bench" table --scene builtin:gallery --size "$SIZE" --frames "$FRAMES" --spp "$SPP" \
    --reference one-bounce --caustic-min-roughness 0.35 --timing finish "${args[@]}" \
    --json "$OUT/table.json" >"$OUT/table.txt" 2>"$OUT/table.log"

python3 - "$OUT/table.json" "$OUT/passes.json" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
timed = {r["config"]: r for r in json.load(open(sys.argv[2]))["rows"]}
print(f"reference: one-bounce, {doc['reference_spp']} spp (caustics off lobes smoother than 0.35 left out)")
# Each run plans from its own measurements: the error run's plan is given where it differs.
print("| env_budget_ms | probes, env_size | predicted ms | probe passes ms | frame ms | frame / no budget | FLIP | relative RMSE |")
print("|---|---|---|---|---|---|---|---|")
base = None
for r in doc["rows"]:
    t = timed[r["config"]]
    c, e = t["counts"], r["error"]["one-bounce"]
    probes = sum(v for k, v in t["passes"].items() if k.startswith(("env_render", "env_prefilter")))
    base = base or t["frame_ms"]
    predicted = c.get("env_predicted_ms")
    plan = f"{int(c['env_probes'])} of {int(c['env_probes_wanted'])}, {int(c['env_size'])}"
    rc = r["counts"]
    if (rc["env_probes"], rc["env_size"]) != (c["env_probes"], c["env_size"]):
        plan += f" (error run: {int(rc['env_probes'])}, {int(rc['env_size'])})"
    print(f"| {r['params']['env_budget_ms']:g} | {plan} | {'-' if predicted is None else f'{predicted:.1f}'} | "
          f"{probes:.1f} | {t['frame_ms']:.1f} | {t['frame_ms'] / base:.2f} | {e['flip']:.4f} | "
          f"{e['relative_rmse']:.4f} |")
print(f"reference noise (relative, of the image): {doc['rows'][0]['error']['one-bounce']['reference_noise']:.4f}")
PY
