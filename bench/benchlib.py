"""Helpers the Python benchmarks share (bench/triangles/run.py, bench/scenes/instancing.py)."""
import os
import sys
import subprocess


def run(cmd):
    """Runs cmd; returns its peak resident set in MiB (the child's own, by wait4). Exits on failure."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    err = proc.stderr.read().decode()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{err}")
    return usage.ru_maxrss / 1024.0


def render_arguments(doc, rounds):
    """An argument parser with the options every gi-render benchmark takes: --bin, --size, --frames,
    --rounds (default `rounds`) and --technique (default: the service's, filled in by parse())."""
    import argparse
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="build/ci/bin")
    ap.add_argument("--size", default="512x512")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=rounds)
    ap.add_argument("--technique", default=None,
                    help="the GI technique (default: the service's, presets/presets.json default_technique)")
    return ap


def parse(ap):
    """ap's arguments, with --technique defaulted to the service's."""
    a = ap.parse_args()
    if a.technique is None:
        a.technique = default_technique()
    return a


def default_technique(fallback="rsm_gather"):
    """The service's default technique (presets/presets.json, or $GI_PRESETS)."""
    import json
    try:
        with open(os.environ.get("GI_PRESETS", "presets/presets.json")) as f:
            return json.load(f)["default_technique"]["name"]
    except (OSError, KeyError, ValueError):
        return fallback
