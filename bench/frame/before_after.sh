#!/usr/bin/env bash
# Per-pass times of two gi-bench builds side by side on this machine: runs `gi-bench passes` with
# each binary in turn, ROUNDS times in ABBA order (before, after, after, before, ...: whichever runs
# second in a pair is a few per cent slower on a shared 2-core machine), so both see the same load,
# and prints each pass's median over all frames of all rounds, before and after, with the ratio.
#
#   bench/frame/before_after.sh OLD/gi-bench NEW/gi-bench [ROUNDS] [SCENE] [SIZE]
#
# A refactoring that should not change the work (same frames, same passes) shows ratios near 1;
# the spread between rounds of one binary is printed as the noise to compare them with.
set -euo pipefail
before=${1:?usage: before_after.sh OLD_GI_BENCH NEW_GI_BENCH [ROUNDS] [SCENE] [SIZE]}
after=${2:?usage: before_after.sh OLD_GI_BENCH NEW_GI_BENCH [ROUNDS] [SCENE] [SIZE]}
rounds=${3:-3}
scene=${4:-builtin:cornell}
size=${5:-256x256}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# CONFIGS="none rsm_gather" narrows the set (default: every technique at its defaults).
configs=()
for c in ${CONFIGS:-none rsm_gather ssbc multires_splat multires_gather isr hier_isr second_order}; do
    configs+=(--config "$c")
done
for ((r = 0; r < rounds; ++r)); do
    order="before after"
    ((r % 2 == 1)) && order="after before"
    for side in $order; do
        bin=$before
        [[ $side == after ]] && bin=$after
        "$bin" passes --scene "$scene" --size "$size" --frames 5 "${configs[@]}" --json "$work/$side.$r.json" \
            > /dev/null 2>&1
    done
done
python3 - "$work" "$rounds" "$scene" "$size" <<'PY'
import json, statistics, sys
work, rounds, scene, size = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
def load(side):
    runs = [json.load(open(f"{work}/{side}.{r}.json"))["rows"] for r in range(rounds)]
    out = {}
    for rows in runs:
        for row in rows:
            for name, ms in list(row["passes"].items()) + [("total", row["total_ms"])]:
                out.setdefault((row["config"], name), []).append(ms)
    return out
b, a = load("before"), load("after")
print(f"# {scene} {size}, {rounds} interleaved rounds; per-pass medians of the rounds' medians (ms)")
print("| config | pass | before | after | after/before | before spread |")
print("|---|---|---|---|---|---|")
ratios = []
for key in sorted(set(b) & set(a)):
    mb, ma = statistics.median(b[key]), statistics.median(a[key])
    spread = (max(b[key]) - min(b[key])) / mb if mb > 0 else 0
    ratio = ma / mb if mb > 0 else float("nan")
    if key[1] == "total": ratios.append(ratio)
    print(f"| {key[0]} | {key[1]} | {mb:.2f} | {ma:.2f} | {ratio:.3f} | {spread:.0%} |")
only = sorted(set(b) ^ set(a))
if only: print("passes in one build only:", ", ".join(f"{c}/{p}" for c, p in only))
print(f"geometric mean of the totals' ratios: {statistics.geometric_mean(ratios):.3f}")
PY
