#!/usr/bin/env python3
"""docs/performance.md, generated from the Google Benchmark runs in docs/benchmarks/*.json.

Usage: scripts/gen_performance_page.py            rewrite the page from the committed runs
       scripts/gen_performance_page.py --check    exit 1 (with a diff) if the page is stale
scripts/benchmark.sh runs the benchmarks (writing docs/benchmarks/) and then this script. Each
benchmark's description is the first comment of its source, found through the add_executable
line of the CMakeLists.txt that builds it, so moving a benchmark needs no change here.
"""
import argparse
import difflib
import glob
import json
import math
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNS = os.path.join("docs", "benchmarks")
OUTPUT = os.path.join("docs", "performance.md")
UNIT_SCALE = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def cmake_files():
    """Every CMakeLists.txt of the sources (build and hidden folders skipped)."""
    found = []
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith((".", "build")))
        if "CMakeLists.txt" in filenames:
            found.append(os.path.join(dirpath, "CMakeLists.txt"))
    return found


def first_sentence(text):
    """A comment's first sentence, without the issue it was written for."""
    text = re.sub(r"\s*\(issues? [^()]*\)", "", " ".join(text.split()))
    end = re.search(r"(?<!e\.g)(?<!i\.e)\.(\s|$)", text)
    text = text[:end.start()] if end else text
    if "issue" in text:  # a clause naming an issue: keep what comes before it
        text = text[:text.index("issue")].rsplit(", ", 1)[0]
    if len(text) > 200:
        cut = [m.start() for m in re.finditer(r"[:;] ", text) if m.start() >= 40]
        text = text[:cut[0]] if cut else text
    return text.strip().rstrip(",:;")


def source_description(executable):
    """The first sentence of the first comment of the source the executable is built from."""
    name = os.path.basename(executable)
    pattern = re.compile(r"add_executable\(\s*" + re.escape(name) + r"\s+([^\s)]+)")
    for cmake in cmake_files():
        m = pattern.search(open(cmake, encoding="utf-8").read())
        if not m:
            continue
        source = os.path.join(os.path.dirname(cmake), m.group(1))
        lines = []
        for line in open(source, encoding="utf-8").read().splitlines():
            if not line.startswith("//"):
                break
            lines.append(line.lstrip("/ ").strip())
        return os.path.relpath(source, ROOT), first_sentence(" ".join(lines))
    return None, ""


def seconds_text(value, unit):
    s = value * UNIT_SCALE.get(unit, 1.0)
    for scale, label in ((1.0, "s"), (1e-3, "ms"), (1e-6, "µs")):
        if s >= scale:
            return f"{s / scale:.3g} {label}"
    return f"{s / 1e-9:.3g} ns"


def number_text(value):
    if isinstance(value, float) and (math.isnan(value) or math.isinf(value)):
        return "–"
    if value == 0:
        return "0"
    if abs(value) >= 1e5 or abs(value) < 1e-3:
        return f"{value:.3e}"
    return f"{value:.4g}"


def rows(benchmarks):
    """One row per benchmark: its median aggregate if repeated, else its single run."""
    medians = [b for b in benchmarks if b.get("aggregate_name") == "median"]
    cvs = {b["run_name"]: b for b in benchmarks if b.get("aggregate_name") == "cv"}
    chosen = medians or [b for b in benchmarks if b.get("run_type", "iteration") == "iteration"]
    skip = {"name", "run_name", "run_type", "aggregate_name", "aggregate_unit", "family_index",
            "per_family_instance_index", "repetitions", "repetition_index", "threads",
            "iterations", "real_time", "cpu_time", "time_unit", "error_occurred", "error_message",
            "label"}
    out = []
    for b in chosen:
        name = b.get("run_name", b["name"])
        cv = cvs.get(name, {}).get("real_time")
        counters = ", ".join(f"{k} {number_text(v)}" for k, v in sorted(b.items())
                             if k not in skip and isinstance(v, (int, float)))
        label = f" ({b['label']})" if b.get("label") else ""
        out.append(f"| `{name}`{label} | {seconds_text(b['real_time'], b['time_unit'])} | "
                   f"{'' if cv is None else f'{100 * cv:.1f} %'} | {counters} |")
    return out


def section(path):
    run = json.load(open(os.path.join(ROOT, path), encoding="utf-8"))
    ctx = run.get("context", {})
    executable = ctx.get("executable", os.path.splitext(os.path.basename(path))[0])
    source, description = source_description(executable)
    out = [f"## `{os.path.basename(executable)}`", ""]
    if description:
        out += [f"{description} (`{source}`).", ""]
    reps = {b.get("repetitions", 1) for b in run.get("benchmarks", [])}
    load = ", ".join(f"{x:.1f}" for x in ctx.get("load_avg", []))
    out += [f"Run on `{ctx.get('host_name', '?')}`: {ctx.get('num_cpus', '?')}"
            f" CPUs at {ctx.get('mhz_per_cpu', '?')} MHz, load average {load or '?'} at the start; "
            f"{max(reps)} repetition(s), medians shown; raw run: `{path}`.", ""]
    standard = {"date", "host_name", "executable", "num_cpus", "mhz_per_cpu",
                "cpu_scaling_enabled", "caches", "load_avg", "library_build_type", "json_schema_version"}
    extra = [(k, v) for k, v in sorted(ctx.items()) if k not in standard and isinstance(v, str)]
    if extra:
        out += ["| context | value |", "| --- | --- |"]
        out += [f"| {k} | {v.replace('|', '/')} |" for k, v in extra]
        out.append("")
    out += ["| benchmark | time | CV | counters (per second of wall-clock time where rates) |",
            "| --- | ---: | ---: | --- |"]
    out += rows(run.get("benchmarks", []))
    out.append("")
    return out


def page():
    runs = sorted(glob.glob(os.path.join(ROOT, RUNS, "*.json")))
    if not runs:
        raise SystemExit(f"gen_performance_page.py: no benchmark runs in {RUNS}/")
    out = ["# Performance",
           "",
           "Generated by `scripts/gen_performance_page.py` from the benchmark runs committed in",
           "`docs/benchmarks/`; `scripts/benchmark.sh` runs the benchmarks again and regenerates this",
           "page, and the test `docs_performance_page` fails if the page does not match the runs.",
           "Figures are wall-clock times on the machine each run names: compare ratios within one",
           "run, not across runs or machines. How the suite times models as a simulator runs them",
           "(set-up apart, then the time per update): [running](user_guide/running.md).",
           ""]
    for path in runs:
        out += section(os.path.relpath(path, ROOT))
    return "\n".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="fail if the page is stale")
    args = parser.parse_args()
    text = page()
    path = os.path.join(ROOT, OUTPUT)
    current = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
    if current == text:
        return 0
    if args.check:
        sys.stdout.writelines(difflib.unified_diff(current.splitlines(True), text.splitlines(True),
                                                   OUTPUT, OUTPUT + " (generated)"))
        print(f"\n{OUTPUT} is stale; run scripts/gen_performance_page.py", file=sys.stderr)
        return 1
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"wrote {OUTPUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
