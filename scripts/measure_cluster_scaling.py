#!/usr/bin/python3
"""Times the straight tube's FEM reference serially and on 1 and 2 MPI ranks, with each run's peak
memory and the load average. Serially: CHOLMOD or UMFPACK, AMG-CG or FGMRES. Per run: DoFs, Krylov iterations, set-up / assembly / solve seconds, peak memory of the
largest rank, the peak memory of all ranks together per DoF, and the load average before and after
each run (the figures mean little on a busy machine: rerun it on an idle one).

Usage: /usr/bin/python3 scripts/measure_cluster_scaling.py [--program build/verification/vesselverify]
           [--levels 1] [--ranks 1,2] [--cases p2,th] [--no-serial] [--length 0.04] [--out table.md]
           [--distributed-solvers cg-amg,matrix-free] [--repeat 1] [--log-dir DIR]
Cases: p2 = P2 at nu = 0.45 (distributed: AMG-CG and the matrix-free p-multigrid CG); th =
Taylor-Hood at nu = 0.5 (serial: UMFPACK and FGMRES; distributed: FGMRES). --length gives a
longer tube (metres; `fem`'s default 0.04), labelled in the case column. --repeat runs the
distributed ones that many times, the rank counts alternating (one row each: the spread is the
machine's noise). Needs mpirun and /usr/bin/time (scripts/install_deps.sh)."""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
from measurement_host import load_average

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe", "--mca", "mpi_yield_when_idle", "1"]
CASES = {"p2": ["--degree", "2", "--nu", "0.45"], "th": ["--nu", "0.5"]}
SERIAL = {"p2": [("CHOLMOD", "direct"), ("AMG-CG", "cg-amg")],
          "th": [("UMFPACK", "direct"), ("FGMRES", "gmres-block")]}
DISTRIBUTED = {"p2": ["cg-amg", "matrix-free"], "th": ["gmres-block"]}


def run(command, json_path, peak_base, log):
    """Runs `command` (each process under /usr/bin/time, writing its peak to peak_base.RANK);
    returns (json, "peak MiB of each rank", the ranks' peaks together in bytes)."""
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for old in glob.glob(peak_base + ".*"):
        os.remove(old)
    p = subprocess.run(command, capture_output=True, text=True, env=env)
    if log:
        with open(log, "w") as f:
            f.write(" ".join(command) + "\n" + p.stdout + p.stderr)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(command)}\n{p.stdout}\n{p.stderr}")
    peaks = []
    for name in glob.glob(peak_base + ".*"):
        with open(name) as f:
            peaks += [int(k) for k in re.findall(r"peak_kb (\d+)", f.read())]
    with open(json_path) as f:
        return (json.load(f), "/".join(f"{k / 1024.0:.0f}" for k in sorted(peaks, reverse=True)),
                1024 * sum(peaks))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--program", default=os.path.join(ROOT, "build", "verification", "vesselverify"))
    ap.add_argument("--levels", default="1")
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--cases", default="p2,th")
    ap.add_argument("--no-serial", action="store_true", help="the distributed runs only")
    ap.add_argument("--length", default="", help="tube length in metres (default: fem's)")
    ap.add_argument("--out", default="")
    ap.add_argument("--distributed-solvers", default="",
                    help="the distributed runs' --solver values (default: the case's, above)")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--log-dir", default="", help="keep each run's command, stdout and stderr here "
                    "(with VESSELVERIFY_MEMORY=1 in the environment: each rank's memory by phase)")
    a = ap.parse_args()
    # Each rank's /usr/bin/time to its own file: on a shared stderr the ranks' lines interleave.
    peak_base = os.path.join(tempfile.gettempdir(), f"cluster_scaling_peak_{os.getpid()}")
    timed = ["sh", "-c", '/usr/bin/time -f "peak_kb %M" -o "$0.${OMPI_COMM_WORLD_RANK:-0}" "$@"',
             peak_base, a.program]
    rows = ["| case | level | solver | ranks | DoFs | iterations | setup s | assembly s | solve s | "
            "peak MiB per rank | kB per DoF (all ranks) | load avg before/after |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "fem.json")
        for case in a.cases.split(","):
            for level in a.levels.split(","):
                base = ["fem", "--level", level, "--load", "contact", "--json", out] + CASES[case]
                label = case
                if a.length:
                    base += ["--length", a.length]
                    label = f"{case} ({a.length} m)"
                runs = [] if a.no_serial else [(name, 1, timed + base + ["--solver", s])
                                               for name, s in SERIAL[case]]
                solvers = (a.distributed_solvers.split(",") if a.distributed_solvers
                           else DISTRIBUTED[case])
                runs += [("distributed", int(n), MPIRUN + ["-np", n] + timed + base +
                          ["--distributed", "--solver", s])
                         for s in solvers for _ in range(a.repeat) for n in a.ranks.split(",")]
                for k, (name, n, command) in enumerate(runs):
                    before = load_average()
                    log = (os.path.join(a.log_dir,
                                        f"{case}-l{level}-{k:02d}-{name.lower()}-np{n}.log")
                           if a.log_dir else "")
                    j, peak, total = run(command, out, peak_base, log)
                    t = j["timings_s"]
                    rows.append(f"| {label} | {level} | {name} ({j['solver']}) | {n} | {j['dofs']} | "
                                f"{j['cg_iterations']} | {t['setup']:.2f} | {t['assembly']:.2f} | "
                                f"{t['solve']:.2f} | {peak} | {total / 1e3 / j['dofs']:.2f} | "
                                f"{before}/{load_average()} |")
                    print(rows[-1], flush=True)
    table = "\n".join(rows) + "\n"
    if a.out:
        with open(a.out, "w") as f:
            f.write(table)
    else:
        print(table)


if __name__ == "__main__":
    main()
