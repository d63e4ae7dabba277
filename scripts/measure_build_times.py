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

--fresh-clone measures what CI pays instead: a commit (HEAD unless --commit) cloned into a folder outside the
source tree and built through ccache (filling the cache), then cloned into a second folder and
built again, timed, with ccache's log listing the compilations that missed the cache (any
absolute path in a compile command, other than one ccache's base_dir rewrites, makes one).
--compare-checkouts lists those objects without building: the compile commands (from
`ninja -t compdb`) that differ between two configured checkouts once base_dir's rewriting is done.

Usage: /usr/bin/python3 scripts/measure_build_times.py [--jobs 2] [--work build-times]
           [--headers msm/form/form.hpp,verification/harness/harness.hpp] [--no-ccache-runs]
           [--cmake-args="-DVESSEL_PCH=OFF -DVESSEL_FAST_LINKER=OFF"] [--out table.md]
       /usr/bin/python3 scripts/measure_build_times.py --fresh-clone [--commit HEAD] [--jobs 2]
           [--out table.md]
       /usr/bin/python3 scripts/measure_build_times.py --compare-checkouts ROOT_A ROOT_B"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from measurement_host import load_average

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_HEADERS = ["verification/harness/harness.hpp", "msm/form/form.hpp", "meshes/tet_mesh.hpp"]


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


def timed_build(build, jobs, label, env=None):
    """Runs ninja; returns a table row: label, wall s, objects compiled, compile s, load before/after."""
    before_rows = len(log_entries(build)) if os.path.exists(os.path.join(build, ".ninja_log")) else 0
    load_before = load_average()
    t0 = time.monotonic()
    p = subprocess.run(["ninja", "-C", build, "-j", str(jobs)], capture_output=True, text=True,
                       env=env)
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


def table(rows):
    """The rows as a Markdown table, with the machine (cores) and its load."""
    lines = [f"{os.cpu_count()} cores, `-j` as given; the load average is the machine's before and "
             "after each build.", "",
             "| build | wall s | objects compiled | compile s (sum) | load before / after |",
             "|---|---|---|---|---|"]
    lines += [f"| {r[0]} | {r[1]:.0f} | {r[2]} | {r[3]:.0f} | {r[4]} / {r[5]} |" for r in rows]
    return "\n".join(lines) + "\n"


def ccache_misses(logfile):
    """The source files whose compilation missed the cache, from a ccache log (one process per pid)."""
    source, misses = {}, []
    with open(logfile, errors="replace") as f:
        for line in f:
            head, _, text = line.partition("] ")
            pid = head.rsplit(" ", 1)[-1]
            if text.startswith("Source file: "):
                source[pid] = text[len("Source file: "):].strip()
            elif text.strip() == "Result: cache_miss":  # (direct_cache_miss may still hit)
                misses.append(source.get(pid, "?"))
    return sorted(set(misses))


def compile_commands(build, root):
    """Each object's compile command as ccache's base_dir sees it: the checkout's root taken out of
    the path arguments (-I, -include, the source, -o), not out of -D values, which it keeps."""
    out = subprocess.run(["ninja", "-C", build, "-t", "compdb"], check=True, capture_output=True,
                         text=True).stdout
    return {e["output"]: " ".join(t if t.startswith("-D") else t.replace(root, "ROOT")
                                  for t in e["command"].split())
            for e in json.loads(out) if e["output"].endswith((".o", ".gch"))}


def differing_commands(root_a, root_b):
    """The objects whose compile command differs between two configured checkouts (each with its
    build tree in build/): every one of them misses ccache in the second checkout."""
    a = compile_commands(os.path.join(root_a, "build"), root_a)
    b = compile_commands(os.path.join(root_b, "build"), root_b)
    return len(a), sorted(k for k in a if k in b and a[k] != b[k])


def fresh_clone(args, extra):
    """Two clones of HEAD in folders outside the source tree, built one after the other; the second
    timed, with the list of its ccache misses. Returns (table rows, misses)."""
    head = subprocess.run(["git", "-C", ROOT, "rev-parse", args.commit], check=True,
                          capture_output=True, text=True).stdout.strip()
    work = tempfile.mkdtemp(prefix="vesselverify-clones-")
    rows = []
    misses = []
    try:
        for k, label in enumerate(("first clone (fills the cache)", "second clone, another folder")):
            clone = os.path.join(work, f"clone{k + 1}")
            subprocess.run(["git", "clone", "--quiet", "--no-checkout", ROOT, clone], check=True)
            subprocess.run(["git", "-C", clone, "checkout", "--quiet", head], check=True)
            build = os.path.join(clone, "build")  # as scripts/build.sh configures it
            subprocess.run(["cmake", "-S", clone, "-B", build, "-G", "Ninja",
                            "-DCMAKE_BUILD_TYPE=Release", "-DVESSEL_CCACHE=ON"] + extra,
                           check=True, stdout=subprocess.DEVNULL)
            env = dict(os.environ)
            logfile = os.path.join(work, f"ccache{k + 1}.log")
            env["CCACHE_LOGFILE"] = logfile
            rows.append(timed_build(build, args.jobs, label, env))
            misses = ccache_misses(logfile)
            print(f"{label}: {len(misses)} ccache misses", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return rows, misses


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
    ap.add_argument("--fresh-clone", action="store_true",
                    help="only CI's case: two clones of --commit in other folders, the second timed")
    ap.add_argument("--commit", default="HEAD", help="what --fresh-clone checks out (default HEAD)")
    ap.add_argument("--compare-checkouts", nargs=2, metavar=("ROOT_A", "ROOT_B"),
                    help="only list the compile commands that differ between two configured "
                         "checkouts of one commit (what misses ccache in the second)")
    args = ap.parse_args()
    extra = args.cmake_args.split()
    if args.compare_checkouts:
        total, diff = differing_commands(*[os.path.abspath(r) for r in args.compare_checkouts])
        print(f"{len(diff)} of {total} compile commands differ:")
        print("\n".join("  " + d for d in diff))
        return
    if args.fresh_clone:
        rows, misses = fresh_clone(args, extra)
        text = f"Commit {args.commit}. " + table(rows) + "\nccache misses of the second clone: " + (
            ", ".join(f"`{m}`" for m in misses) if misses else "none") + "\n"
        print(text)
        if args.out:
            with open(args.out, "w") as f:
                f.write(text)
        return
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

    text = table(rows)
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
