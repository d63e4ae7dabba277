#!/usr/bin/python3
"""What a change costs to build: a fresh build of every target, then one header changed at a time.

In a new build directory (Release, Ninja, as scripts/build.sh configures it) the script times
  1. a fresh build with ccache off (what a machine with an empty cache pays),
  2. for each header given: the header's mtime bumped, then `ninja` again (the objects that
     depend on it are recompiled and relinked; ccache stays off, so this is a real content change),
  3. a fresh build with ccache on, twice: the first fills the cache, the second is what a fresh
     clone pays when the cache is warm (CI on this machine after a session has built the same code).
Per run: wall seconds, objects compiled, the sum of compile seconds (CPU-ish: from .ninja_log),
and the load average before and after (the figures mean little on a busy machine).

Usage: /usr/bin/python3 scripts/measure_build_times.py [--jobs 2] [--work build-times]
           [--headers msm/form/form.hpp,verification/harness/harness.hpp] [--no-ccache-runs]
           [--cmake-args="-DVESSEL_PCH=OFF -DVESSEL_FAST_LINKER=OFF"] [--out table.md]"""
import argparse
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_HEADERS = ["verification/harness/harness.hpp", "msm/form/form.hpp", "meshes/tet_mesh.hpp"]


def load_average():
    with open("/proc/loadavg") as f:
        return f.read().split()[0]


def configure(build, ccache, extra):
    shutil.rmtree(build, ignore_errors=True)
    subprocess.run(["cmake", "-S", ROOT, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                    f"-DVESSEL_CCACHE={'ON' if ccache else 'OFF'}"] + extra,
                   check=True, stdout=subprocess.DEVNULL)


def log_entries(build):
    """The .ninja_log rows as (start ms, end ms, output)."""
    rows = []
    with open(os.path.join(build, ".ninja_log")) as f:
        for line in f:
            if line.startswith("#"):
                continue
            start, end, _, output, _ = line.rstrip("\n").split("\t")
            rows.append((int(start), int(end), output))
    return rows


def timed_build(build, jobs, label):
    """Runs ninja; returns a table row: label, wall s, objects compiled, compile s, load before/after."""
    before_rows = len(log_entries(build)) if os.path.exists(os.path.join(build, ".ninja_log")) else 0
    load_before = load_average()
    t0 = time.monotonic()
    p = subprocess.run(["ninja", "-C", build, "-j", str(jobs)], capture_output=True, text=True)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        sys.exit(f"build failed ({label}):\n{p.stdout[-4000:]}\n{p.stderr[-2000:]}")
    new = log_entries(build)[before_rows:]
    objects = [r for r in new if r[2].endswith(".o")]
    compile_s = sum(end - start for start, end, _ in objects) / 1000.0
    row = (label, wall, len(objects), compile_s, load_before, load_average())
    print(f"{label}: {wall:.0f} s wall, {len(objects)} objects, {compile_s:.0f} s compiling "
          f"(load {row[4]} -> {row[5]})", flush=True)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=os.cpu_count())
    ap.add_argument("--work", default=os.path.join(ROOT, "build-times"),
                    help="scratch folder, removed afterwards; inside the source tree, as CI's build is, "
                         "so that ccache's base_dir applies")
    ap.add_argument("--headers", default=",".join(DEFAULT_HEADERS))
    ap.add_argument("--no-ccache-runs", action="store_true", help="skip step 3")
    ap.add_argument("--cmake-args", default="", help="extra CMake arguments, e.g. -DVESSEL_PCH=OFF")
    ap.add_argument("--out", help="also write the table (Markdown) here")
    args = ap.parse_args()
    extra = args.cmake_args.split()
    headers = [h for h in args.headers.split(",") if h]
    for header in headers:
        if not os.path.isfile(os.path.join(ROOT, header)):
            sys.exit(f"--headers: no such file in the source tree: {header}")

    build = args.work
    rows = []
    configure(build, False, extra)
    rows.append(timed_build(build, args.jobs, "fresh build, ccache off"))
    for header in headers:
        os.utime(os.path.join(ROOT, header))
        rows.append(timed_build(build, args.jobs, f"`{header}` changed"))
    if not args.no_ccache_runs:
        for label in ("fresh build, ccache on (first)", "fresh build, ccache warm (second)"):
            configure(build, True, extra)
            rows.append(timed_build(build, args.jobs, label))
    shutil.rmtree(args.work, ignore_errors=True)

    table = ["| build | wall s | objects compiled | compile s (sum) | load before / after |",
             "|---|---|---|---|---|"]
    table += [f"| {r[0]} | {r[1]:.0f} | {r[2]} | {r[3]:.0f} | {r[4]} / {r[5]} |" for r in rows]
    text = "\n".join(table) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
