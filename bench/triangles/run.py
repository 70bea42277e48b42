#!/usr/bin/env python3
"""Frame time, load time and peak memory against triangle count (docs/scenes.md, "Big scenes").

Exports the generated atrium at each size as a .glb (`gi-render --export`), so the load is the real
glTF path (parse, decode, normals, tangents, validation), then renders each file with `none` and the
default technique at SIZE, FRAMES timed frames after a warm-up (glFinish timing: llvmpipe's timer
queries attribute deferred work to later passes). Sizes are run interleaved, ROUNDS times, and the
median kept, since the machine is shared. Peak memory is the process's maximum resident set.
Also renders builtin:cornell-dense and builtin:atrium for the issue's ratio.

usage: bench/triangles/run.py [--bin build/ci/bin] [--size 512x512] [--frames 3] [--rounds 1]
                              [--sizes 10,50,100,250,500,1000,2000] [--technique NAME]
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchlib import parse, render_arguments, run  # noqa: E402




def main():
    ap = render_arguments(__doc__, rounds=1)
    ap.add_argument("--sizes", default="10,50,100,250,500,1000,2000")
    a = parse(ap)
    render = os.path.join(a.bin, "gi-render")
    work = tempfile.mkdtemp(prefix="gis_triangles_")
    scenes = []
    for k in [int(s) for s in a.sizes.split(",")]:
        path = os.path.join(work, f"atrium-{k}k.glb")
        subprocess.run([render, "--scene", f"builtin:atrium-{k}k", "--export", path, "--quiet"], check=True)
        scenes.append((f"atrium-{k}k.glb", path))
    scenes += [("builtin:cornell-dense", "builtin:cornell-dense"), ("builtin:atrium", "builtin:atrium")]

    results = {}
    for _ in range(a.rounds):
        for label, scene in scenes:
            for technique in ("none", a.technique):
                stats = os.path.join(work, "stats.json")
                peak = run([render, "--scene", scene, "--technique", technique, "--size", a.size, "--frames",
                            str(a.frames), "--no-timer-queries", "--stats", stats, "--quiet"])
                s = json.load(open(stats))
                counts = s.get("counts", {})
                r = results.setdefault((label, technique), {"frame": [], "load": [], "peak": [], "stats": s})
                r["frame"].append(s["frame_ms"])
                r["load"].append(s["scene_load_ms"])
                r["peak"].append(peak)
                r["triangles"] = s["scene_triangles"]
                r["culled"] = counts.get("triangles_gbuffer_culled", 0)

    print(f"Frame: {a.size}, median of {a.frames} frames after a warm-up, {a.rounds} round(s); "
          f"load: read, decode and finish on the CPU; peak: maximum resident set of the process.\n")
    print(f"| scene | triangles | file MiB | load ms | peak MiB | none ms | {a.technique} ms | G-buffer culled |")
    print("|---|---|---|---|---|---|---|---|")
    for label, scene in scenes:
        n = results[(label, "none")]
        t = results[(label, a.technique)]
        size = os.path.getsize(scene) / 2**20 if os.path.exists(scene) else 0.0
        med = statistics.median
        print(f"| {label} | {n['triangles']:,} | {size:.1f} | {med(n['load']):.0f} | {max(n['peak'] + t['peak']):.0f} | "
              f"{med(n['frame']):.1f} | {med(t['frame']):.1f} | {100.0 * n['culled'] / max(n['triangles'], 1):.0f}% |")
    dense = results[("builtin:cornell-dense", a.technique)]
    atrium = results[("builtin:atrium", a.technique)]
    print(f"\nbuiltin:atrium / builtin:cornell-dense frame time ({a.technique}): "
          f"{statistics.median(atrium['frame']) / statistics.median(dense['frame']):.2f}")
    for label, _ in scenes:
        passes = {p["name"]: p.get("gpu_ms", 0.0) for p in results[(label, a.technique)]["stats"].get("passes", [])}
        top = sorted(passes.items(), key=lambda kv: -kv[1])[:4]
        print(f"  {label}: " + ", ".join(f"{k} {v:.0f} ms" for k, v in top))


if __name__ == "__main__":
    main()
