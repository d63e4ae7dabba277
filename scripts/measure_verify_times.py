#!/usr/bin/python3
"""How long the main job (scripts/verify.sh) takes: from an empty cache, then cached, per mode.

For each mode asked (default: the default run and --quick) the script builds once (verify.sh's
own build step, not timed), then runs `scripts/verify.sh [mode]` into a scratch folder with
VESSELVERIFY_CACHE_DIR pointed at a new empty folder (meshes, FEM references and model outcomes
all computed), and again with the cache that run filled. The time is verify.sh's own ("finished
in N s": from the first mesh to the report, the build excluded). It writes
docs/measurements/verify_times.md with the machine (CPU, cores, memory) and the load average
before and after each run: figures from a loaded machine are upper bounds. The rows of a mode not
asked for are kept from the page as it was.

Usage: /usr/bin/python3 scripts/measure_verify_times.py [--modes default,quick] [--out PAGE]"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from measurement_host import load_average, machine

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = {"default": [], "quick": ["--quick"]}


def run_verify(mode, cache, out):
    """verify.sh in `mode` with its cache in `cache`; returns (seconds, load before, load after)."""
    env = dict(os.environ, VESSELVERIFY_CACHE_DIR=cache)
    before = load_average()
    p = subprocess.run([os.path.join(ROOT, "scripts", "verify.sh")] + MODES[mode] + [out],
                       env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"verify.sh {' '.join(MODES[mode])} failed:\n{p.stdout[-4000:]}\n{p.stderr[-2000:]}")
    m = re.search(r"verification finished in (\d+) s", p.stdout)
    if not m:
        sys.exit("verify.sh printed no 'verification finished in N s' line")
    return int(m.group(1)), before, load_average()


def kept_rows(page, measured_modes):
    """The page's rows of the modes not measured this time (so `--modes default` keeps --quick's)."""
    if not os.path.exists(page):
        return []
    labels = {"default": "| default |", "quick": "| `--quick` |"}
    keep = [labels[m] for m in MODES if m not in measured_modes]
    with open(page) as f:
        return [line.rstrip("\n") for line in f if any(line.startswith(k) for k in keep)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--modes", default="default,quick", help="comma-separated: default, quick")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "measurements", "verify_times.md"))
    args = ap.parse_args()
    modes = [m for m in args.modes.split(",") if m]
    for m in modes:
        if m not in MODES:
            sys.exit(f"--modes: unknown mode '{m}' (expected default or quick)")
    subprocess.run([os.path.join(ROOT, "scripts", "build.sh")], check=True, stdout=subprocess.DEVNULL)
    rows = []
    work = tempfile.mkdtemp(prefix="vesselverify-verify-times-")
    try:
        for mode in modes:
            cache = os.path.join(work, f"cache-{mode}")
            os.makedirs(cache)
            for state in ("empty cache", "cached"):
                seconds, before, after = run_verify(mode, cache, os.path.join(work, f"out-{mode}"))
                rows.append((mode, state, seconds, before, after))
                print(f"{mode}, {state}: {seconds} s (load {before} -> {after})", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    lines = ["# How long the main job takes", "",
             f"`scripts/verify.sh` on {machine()}. Regenerate with "
             "`/usr/bin/python3 scripts/measure_verify_times.py`. The time is verify.sh's own, "
             "from the first mesh to the report (the build excluded); \"empty cache\" is "
             "`VESSELVERIFY_CACHE_DIR` pointed at an empty folder (meshes, FEM references and model "
             "outcomes all computed), \"cached\" the same run again on the cache it filled. The load "
             "average is the machine's before and after the run: on a loaded machine the times are "
             "upper bounds.", "",
             "| mode | cache | seconds | load before / after |", "| --- | --- | --- | --- |"]
    measured = [f"| {'`--quick`' if r[0] == 'quick' else 'default'} | {r[1]} | {r[2]} | {r[3]} / {r[4]} |"
                for r in rows]
    lines += measured + kept_rows(args.out, modes)
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
