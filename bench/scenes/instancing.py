#!/usr/bin/env python3
"""Instanced against flattened: one mesh placed many times (docs/scenes.md, "Instances").

Writes two .glb files with the same geometry and the same image: in `shared.glb` every node names
one mesh (the loader keeps it once, with a matrix per node); in `copies.glb` every node names a mesh
of its own (the same accessors, so the file is no bigger, but the loader flattens each one to world
space, as it did for every file before instancing). Renders each with `none` and the default
technique at SIZE, FRAMES timed frames after a warm-up, ROUNDS rounds interleaved, and reports
medians, the peak resident set, and the ratios shared / copies measured in this one run.

usage: bench/scenes/instancing.py [--bin build/ci/bin] [--size 512x512] [--frames 3] [--rounds 2]
                                  [--count 100] [--segments 100] [--technique NAME]
"""
import json
import math
import os
import statistics
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from benchlib import parse, render_arguments, run  # noqa: E402


def sphere(segments):
    """A UV sphere of radius 0.4: positions, normals and indices (2 * segments^2 triangles, about)."""
    pos, nrm, idx = [], [], []
    rings = segments // 2
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2.0 * math.pi * s / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            nrm.append(n)
            pos.append(tuple(0.4 * c for c in n))
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            idx += [a, a + 1, b, a + 1, b + 1, b]
    return pos, nrm, idx


def write_glb(path, count, segments, shared):
    pos, nrm, idx = sphere(segments)
    floor_pos = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]
    floor_idx = [0, 2, 1, 0, 3, 2]
    blobs, views, accessors = [], [], []

    def add(data, fmt, target, acc):
        offset = sum(len(b) for b in blobs)
        blob = b"".join(struct.pack(fmt, *v) if isinstance(v, tuple) else struct.pack(fmt, v) for v in data)
        blob += b"\0" * (-len(blob) % 4)
        blobs.append(blob)
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob), "target": target})
        acc["bufferView"] = len(views) - 1
        acc["count"] = len(data)
        accessors.append(acc)
        return len(accessors) - 1

    def vec3(values):
        lo = [min(v[k] for v in values) for k in range(3)]
        hi = [max(v[k] for v in values) for k in range(3)]
        return add(values, "<3f", 34962, {"componentType": 5126, "type": "VEC3", "min": lo, "max": hi})

    sphere_prim = {"attributes": {"POSITION": vec3(pos), "NORMAL": vec3(nrm)},
                   "indices": add(idx, "<I", 34963, {"componentType": 5125, "type": "SCALAR"}), "material": 0}
    floor_prim = {"attributes": {"POSITION": vec3(floor_pos)},
                  "indices": add(floor_idx, "<I", 34963, {"componentType": 5125, "type": "SCALAR"}), "material": 1}
    side = math.ceil(math.sqrt(count))
    meshes = [{"name": "floor", "primitives": [floor_prim]}]
    nodes = [{"mesh": 0, "scale": [side, 1, side]}]
    for i in range(count):
        if shared and len(meshes) == 1:
            meshes.append({"name": "ball", "primitives": [sphere_prim]})
        elif not shared:
            meshes.append({"name": f"ball{i}", "primitives": [sphere_prim]})
        x, z = i % side, i // side
        nodes.append({"mesh": 1 if shared else len(meshes) - 1,
                      "translation": [2.0 * x - side + 1.0, 0.4, 2.0 * z - side + 1.0],
                      "rotation": [0.0, math.sin(0.1 * i), 0.0, math.cos(0.1 * i)]})
    doc = {"asset": {"version": "2.0", "generator": "bench/scenes/instancing.py"},
           "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
           "materials": [{"name": "ball", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1], "metallicFactor": 0}},
                         {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1], "metallicFactor": 0}}],
           "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": sum(len(b) for b in blobs)}]}
    body = json.dumps(doc).encode()
    body += b" " * (-len(body) % 4)
    binary = b"".join(blobs)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(body) + 8 + len(binary)))
        f.write(struct.pack("<II", len(body), 0x4E4F534A) + body)
        f.write(struct.pack("<II", len(binary), 0x004E4942) + binary)




def main():
    ap = render_arguments(__doc__, rounds=2)
    ap.add_argument("--count", type=int, default=100, help="placements of the sphere")
    ap.add_argument("--segments", type=int, default=100, help="the sphere's segments (2 x segments^2 / 2 triangles)")
    a = parse(ap)
    render = os.path.join(a.bin, "gi-render")
    work = tempfile.mkdtemp(prefix="gis_instancing_")
    files = {}
    for label, shared in (("shared", True), ("copies", False)):
        files[label] = os.path.join(work, f"{label}.glb")
        write_glb(files[label], a.count, a.segments, shared)

    results = {}
    for _ in range(a.rounds):
        for label, path in files.items():
            for technique in ("none", a.technique):
                stats = os.path.join(work, "stats.json")
                peak = run([render, "--scene", path, "--technique", technique, "--size", a.size, "--frames",
                            str(a.frames), "--no-timer-queries", "--stats", stats, "--out",
                            os.path.join(work, f"{label}-{technique}.exr"), "--quiet"])
                s = json.load(open(stats))
                r = results.setdefault((label, technique), {"frame": [], "load": [], "peak": [], "stats": s})
                r["frame"].append(s["frame_ms"])
                r["load"].append(s["scene_load_ms"])
                r["peak"].append(peak)

    med = statistics.median
    print(f"{a.count} spheres of {a.segments} segments at {a.size}; median of {a.frames} frames after a warm-up, "
          f"{a.rounds} round(s) interleaved; peak: maximum resident set of the process.\n")
    print(f"| file | triangles drawn | stored | instances | file KiB | load ms | peak MiB | none ms | {a.technique} ms |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, path in files.items():
        n, t = results[(label, "none")], results[(label, a.technique)]
        c = n["stats"].get("counts", {})
        print(f"| {label}.glb | {n['stats']['scene_triangles']:,} | {c.get('triangles_stored', n['stats']['scene_triangles']):,} | "
              f"{c.get('instances', 0)} | {os.path.getsize(path) / 1024:.0f} | {med(n['load']):.0f} | "
              f"{max(n['peak'] + t['peak']):.0f} | {med(n['frame']):.1f} | {med(t['frame']):.1f} |")
    s, c = "shared", "copies"
    print(f"\nshared / copies: load {med(results[(s, 'none')]['load']) / med(results[(c, 'none')]['load']):.2f}, "
          f"peak {max(results[(s, 'none')]['peak']) / max(results[(c, 'none')]['peak']):.2f}, "
          f"none frame {med(results[(s, 'none')]['frame']) / med(results[(c, 'none')]['frame']):.2f}, "
          f"{a.technique} frame {med(results[(s, a.technique)]['frame']) / med(results[(c, a.technique)]['frame']):.2f}")
    # The two files must give the same image (the test of Pipeline.InstancedMeshesDrawLikeTheirFlattenedCopies).
    print(f"images: {work}/{{shared,copies}}-{{none,{a.technique}}}.exr")


if __name__ == "__main__":
    main()
