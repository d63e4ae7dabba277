#!/usr/bin/python3
"""Compares two results.json files figure by figure, ignoring what a rerun may change (timings,
memory, the command line and the machine): every other number must agree to --rtol (relative,
with --atol as the floor for values near zero), every string and count exactly.

Usage: /usr/bin/python3 scripts/compare_results.py BEFORE.json AFTER.json [--rtol 1e-8]
Exit 0 when they agree, 1 with a list of the differences otherwise."""
import argparse
import json
import math
import sys

# Keys whose values are measurements of the run, not results of the models: a key is one when one of
# its underscore-separated words is a volatile word (`setup_seconds`, `timing_source`,
# `peak_memory_mb_per_rank`) or it is one of the named keys; whole words only, so that `updates`
# and `steps_per_update` (results) are compared although they contain "date" and "update".
VOLATILE_WORDS = frozenset({"seconds", "second", "memory", "timing", "timings", "machine", "date",
                            "build", "command", "kernel"})
VOLATILE_KEYS = frozenset({"update_ms", "update_s", "timings_s", "real_time", "cpu_time"})


def volatile(key):
    return key in VOLATILE_KEYS or any(w in VOLATILE_WORDS for w in key.split("_"))


def walk(a, b, path, rtol, atol, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if volatile(k):
                continue
            if k not in a or k not in b:
                out.append(f"{path}/{k}: only in {'after' if k in b else 'before'}")
                continue
            walk(a[k], b[k], f"{path}/{k}", rtol, atol, out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items before, {len(b)} after")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            walk(x, y, f"{path}[{i}]", rtol, atol, out)
    elif isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or a is None:
        if a != b:
            out.append(f"{path}: {a!r} before, {b!r} after")
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isnan(a) and math.isnan(b):
            return
        if abs(a - b) > max(atol, rtol * max(abs(a), abs(b))):
            out.append(f"{path}: {a!r} before, {b!r} after")
    elif a != b:
        out.append(f"{path}: {a!r} before, {b!r} after")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("before")
    p.add_argument("after")
    p.add_argument("--rtol", type=float, default=1e-8)
    p.add_argument("--atol", type=float, default=1e-15)
    a = p.parse_args()
    with open(a.before) as f:
        before = json.load(f)
    with open(a.after) as f:
        after = json.load(f)
    out = []
    walk(before, after, "", a.rtol, a.atol, out)
    for line in out[:200]:
        print(line)
    print(f"{len(out)} difference(s) beyond rtol {a.rtol}")
    return 1 if out else 0


if __name__ == "__main__":
    sys.exit(main())
