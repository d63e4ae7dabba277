#!/usr/bin/env python3
"""CG iterations of `vesselverify fem --solver matrix-free` (P2, p-multigrid, ML-CG on P1)
per structured-tube level (on each thread count) and per Poisson's ratio, with wall time, solve
time, peak memory and the operator's application against the memory-bandwidth roofline (the
STREAM-like triad of build/msm/spring_kernel_benchmark, measured in the same run); writes
docs/measurements/matrix_free_multigrid.md.

Each run: `vesselverify fem --structured --level L --degree 2 --bc clamped --load pressure
--formulation displacement --nu NU --solver matrix-free --threads T`, timed by /usr/bin/time
(peak RSS).
The CLI's "solve" phase includes the solver's set-up (operators, transfer, P1 solver); the
page splits it with the CLI's "matrix-free set-up" and "matrix-free CG" lines.

Usage: /usr/bin/python3 scripts/measure_matrix_free_multigrid.py [--levels 0,1] [--threads 1,2]
           [--nus 0,0.3,0.45,0.49] [--nu-level 1] [--vesselverify build/verification/vesselverify]
           [--benchmark build/msm/spring_kernel_benchmark] [--out PAGE]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
from measurement_host import load_average

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# The P2 operator's compulsory traffic per application: per cell its 30 DoF indices (4 B) and
# its geometry (J⁻ᵀ and |det J|, 10 doubles), per DoF the source read, the destination zeroed
# and written once (3 × 8 B); any re-read of a vector entry evicted from the caches comes on top.
BYTES_PER_CELL = 30 * 4 + 10 * 8
BYTES_PER_DOF = 3 * 8


def triad_bandwidth(benchmark):
    """{threads: bytes/s} of the spring kernel benchmark's STREAM-like triad."""
    p = subprocess.run([benchmark, "--benchmark_filter=BM_Triad"], capture_output=True,
                       text=True)
    if p.returncode != 0:
        sys.exit(f"{benchmark} failed:\n{p.stdout}{p.stderr}")
    text = re.sub(r"\x1b\[[0-9;]*m", "", p.stdout)
    rates = {}
    for threads, rate, unit in re.findall(r"BM_Triad/(\d+)/real_time .* ([0-9.]+)([GM])/s\s*$",
                                          text, re.M):
        rates[int(threads)] = float(rate) * (1e9 if unit == "G" else 1e6)
    if not rates:
        sys.exit(f"{benchmark}: no BM_Triad rows in its output:\n{text}")
    return rates


def run(vv, level, nu, threads, env):
    cmd = [vv, "fem", "--structured", "--level", str(level), "--degree", "2", "--bc", "clamped",
           "--load", "pressure", "--formulation", "displacement", "--nu", repr(nu),
           "--solver", "matrix-free", "--threads", str(threads)]
    load = load_average()
    p = subprocess.run(["/usr/bin/time", "-f", "TIMED %e %M"] + cmd, env=env,
                       capture_output=True, text=True)
    out = p.stdout + p.stderr
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{out}")
    dofs = int(re.search(r"(\d+) DoFs", out).group(1))
    cells = int(re.search(r"(\d+) tets", out).group(1))
    iterations = int(re.search(r"(\d+) CG iterations", out).group(1))
    solve = float(re.search(r"solve ([0-9.]+)", out).group(1))
    setup_line = re.search(r"matrix-free set-up \(s\): (.*)", out).group(1)
    setup = sum(float(v) for v in re.findall(r"([0-9.]+)(?:,|$)", setup_line))
    cg = re.search(r"matrix-free CG \(s\): ([0-9.]+) in all; (\d+) operator applications "
                   r"([0-9.]+) \(([0-9.]+) ms each", out).groups()
    coarse = re.search(r"(\d+) P1 solves ([0-9.]+) \((\d+) inner CG iterations\)", out).groups()
    wall, kb = re.search(r"TIMED ([0-9.]+) (\d+)", out).groups()
    return dict(level=level, nu=nu, threads=threads, dofs=dofs, cells=cells,
                iterations=iterations, solve=solve, setup=setup,
                cg=float(cg[0]), applications=int(cg[1]), ms_per_application=float(cg[3]),
                coarse_method=re.search(r"P1 solver \(([^)]*)\)", out).group(1),
                coarse_seconds=float(coarse[1]),
                inner_per_solve=int(coarse[2]) / max(int(coarse[0]), 1),
                wall=float(wall), mb=int(kb) / 1024, bytes_per_dof=int(kb) * 1024 / dofs,
                load=load, cmd=" ".join(["vesselverify"] + cmd[1:]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--levels", default="0,1")
    ap.add_argument("--threads", default="1,2", help="thread counts of the per-level runs")
    ap.add_argument("--nus", default="0,0.3,0.45,0.49")
    ap.add_argument("--nu-level", type=int, default=1)
    ap.add_argument("--vesselverify", default=os.path.join(ROOT, "build", "verification",
                                                           "vesselverify"))
    ap.add_argument("--benchmark", default=os.path.join(ROOT, "build", "msm",
                                                        "spring_kernel_benchmark"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "measurements",
                                                  "matrix_free_multigrid.md"))
    args = ap.parse_args()
    if not os.access(args.vesselverify, os.X_OK):
        sys.exit(f"{args.vesselverify}: not an executable (build first: scripts/build.sh)")
    env = dict(os.environ, VESSELVERIFY_CACHE_DIR=os.environ.get(
        "VESSELVERIFY_CACHE_DIR", os.path.join(tempfile.gettempdir(), "vesselverify-mg-cache")))
    thread_counts = [int(t) for t in args.threads.split(",") if t]
    triad = triad_bandwidth(args.benchmark)
    levels = [run(args.vesselverify, int(v), 0.3, t, env)
              for v in args.levels.split(",") if v for t in thread_counts]
    nus = [run(args.vesselverify, args.nu_level, float(v), max(thread_counts), env)
           for v in args.nus.split(",") if v]
    header = ("| level | threads | ν | DoFs | CG iterations | solve incl. set-up (s) | set-up (s) | CG (s) | "
              "operator applications | ms per application | P1 solver | P1 solves (s) | "
              "inner iterations per P1 solve | wall (s) | peak MB | bytes per DoF | "
              "load (1 min) |\n" + "| --- " * 17 + "|\n")

    def rows(rs):
        return "".join(f"| {r['level']} | {r['threads']} | {r['nu']} | {r['dofs']} | "
                       f"{r['iterations']} | "
                       f"{r['solve']:.1f} | {r['setup']:.1f} | {r['cg']:.1f} | "
                       f"{r['applications']} | {r['ms_per_application']:.1f} | "
                       f"{r['coarse_method']} | {r['coarse_seconds']:.1f} | "
                       f"{r['inner_per_solve']:.1f} | {r['wall']:.1f} | "
                       f"{r['mb']:.0f} | {r['bytes_per_dof']:.0f} | {r['load']} |\n" for r in rs)

    def roofline(rs):
        out = ("| level | threads | cells | DoFs | compulsory MB per application | "
               "bytes per DoF | triad (GB/s) | at the triad (ms) | measured (ms) | "
               "fraction of the roofline |\n" + "| --- " * 10 + "|\n")
        for r in rs:
            bytes_ = r["cells"] * BYTES_PER_CELL + r["dofs"] * BYTES_PER_DOF
            bw = triad.get(r["threads"])
            bound = bytes_ / bw * 1e3 if bw else float("nan")
            out += (f"| {r['level']} | {r['threads']} | {r['cells']} | {r['dofs']} | "
                    f"{bytes_ / 1e6:.1f} | {bytes_ / r['dofs']:.0f} | "
                    f"{bw / 1e9 if bw else float('nan'):.1f} | {bound:.2f} | "
                    f"{r['ms_per_application']:.2f} | {bound / r['ms_per_application']:.2f} |\n")
        return out

    its = [r["iterations"] for r in levels]
    page = ("# Matrix-free P2 elasticity: p-multigrid iterations per level and per ν\n\n"
            "CG to ‖r‖ ≤ 1e-10 ‖b‖ (the default tolerance) on the matrix-free P2 operator, "
            "preconditioned by one two-level V-cycle: Chebyshev (degree 4, range 20) on the "
            "operator's diagonal at P2, the P1 level of the same mesh solved by CG preconditioned "
            "by ML (plain aggregation, drop threshold 0.02, the six rigid-body modes as near-null "
            "space) to a relative "
            "residual of 0.1, the outer CG then the flexible variant. The P2 "
            "operator integrates at Witherden–Vincent's 4-point rule of degree 2 (exact on these "
            "straight-sided tets) in the project's own cell kernel, eight cells at a time in "
            "AVX-512 registers (two AVX2 or four SSE2 registers on a CPU without it, chosen at "
            "run time; Debian's deal.II itself is built with vectorisation width 0), the cells "
            "cut into one contiguous part per thread (`--threads`), on geometry and DoF indices "
            "read from MatrixFree's one-point data at set-up; the P1 level's ML runs on one "
            "thread (over MPI ranks it is distributed: cluster_scaling.md). "
            "The P2 → P1 transfer is the nodal "
            "interpolation (P1 ⊂ P2) and its transpose. Set-up: the sum of the CLI's set-up parts (operators, "
            "transfer, diagonal, eigenvalue estimate, P1 matrix and ML hierarchy). "
            "Structured straight tube (a = 3 mm, t = 1 mm, L = 40 mm), internal pressure 10 Pa, "
            "both ends clamped, E = 14240 Pa. One run each on the 2-core machine, shared: the "
            "load column is the 1-minute load average before the run.\n\n"
            "Regenerate: `/usr/bin/python3 scripts/measure_matrix_free_multigrid.py "
            f"--levels {args.levels} --threads {args.threads} --nus {args.nus} "
            f"--nu-level {args.nu_level}`\n\n"
            "## Per level (ν = 0.3)\n\n" + header + rows(levels) +
            (f"\nLargest / smallest iteration count: {max(its) / min(its):.2f}.\n" if its else "") +
            f"\n## Per ν (level {args.nu_level}, displacement formulation)\n\n" + header +
            rows(nus) +
            "\n## The operator against the memory-bandwidth roofline\n\n"
            "One application's compulsory traffic: per cell its 30 DoF indices (4 B) and its "
            f"geometry (10 doubles), {BYTES_PER_CELL} B, and per DoF {BYTES_PER_DOF} B (the "
            "source read, the destination zeroed and written once); at the triad bandwidth "
            "(a = b + s·c, 24 B per element, `spring_kernel_benchmark --benchmark_filter=BM_Triad`, "
            "run first in this same run) on as many threads that traffic takes the time "
            "*at the triad*; the fraction is that time over the measured one (1: "
            "bandwidth-bound).\n\n" + roofline(levels))
    with open(args.out, "w") as f:
        f.write(page)
    print(page)


if __name__ == "__main__":
    main()
