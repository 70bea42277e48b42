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


def default_technique(fallback="rsm_gather"):
    """The service's default technique (presets/presets.json, or $GI_PRESETS)."""
    import json
    try:
        with open(os.environ.get("GI_PRESETS", "presets/presets.json")) as f:
            return json.load(f)["default_technique"]["name"]
    except (OSError, KeyError, ValueError):
        return fallback
