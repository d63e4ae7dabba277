#!/usr/bin/env python3
"""Where `auto` should switch from CHOLMOD to the matrix-free P2 solve: `vesselverify fem` with
--solver direct and --solver matrix-free on the same meshes, alternately, per mesh size; writes
docs/measurements/solver_switch.md.

Each run: `vesselverify fem --structured --level L --length LEN --degree 2 --bc clamped --load
pressure --formulation displacement --nu 0.3 --solver S`. The time compared is what the user pays
for the linear system: the CLI's set-up (DoFs, constraints, the pattern the direct solve needs),
assembly (the matrix, or the load alone for matrix-free) and solve (factorisation or multigrid
set-up, then the solve). The crossover is interpolated in log(DoFs) between the two sizes where
the ratio crosses 1; the product's default (SolverOptions::matrix_free_min_dofs) is set from it.

Usage: /usr/bin/python3 scripts/measure_solver_switch.py [--repeats 2]
           [--vesselverify build/verification/vesselverify] [--out PAGE]
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
import measurement_host

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# (structured level, tube length m): P2 DoFs from about 4 thousand to 230 thousand
CASES = [(0, 0.005), (0, 0.01), (0, 0.015), (0, 0.02), (0, 0.04), (1, 0.01), (1, 0.04)]


def run(vv, level, length, solver, env):
    cmd = [vv, "fem", "--structured", "--level", str(level), "--length", repr(length),
           "--degree", "2", "--bc", "clamped", "--load", "pressure", "--formulation",
           "displacement", "--nu", "0.3", "--solver", solver]
    p = subprocess.run(["/usr/bin/time", "-f", "TIMED %e %M"] + cmd, env=env,
                       capture_output=True, text=True)
    out = p.stdout + p.stderr
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{out}")
    dofs = int(re.search(r"(\d+) DoFs", out).group(1))
    parts = {k: float(re.search(k + r" ([0-9.]+)", out).group(1))
             for k in ("setup", "assembly", "solve")}
    wall, kb = re.search(r"TIMED ([0-9.]+) (\d+)", out).groups()
    return dict(dofs=dofs, paid=sum(parts.values()), wall=float(wall), mb=int(kb) / 1024)


def crossover(rows):
    """DoFs where CHOLMOD's time / matrix-free's crosses 1 (log-log interpolation), or None."""
    for a, b in zip(rows, rows[1:]):
        if a["ratio"] < 1.0 <= b["ratio"]:
            t = math.log(a["ratio"]) / (math.log(a["ratio"]) - math.log(b["ratio"]))
            return math.exp(math.log(a["dofs"]) + t * (math.log(b["dofs"]) - math.log(a["dofs"])))
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=2, help="pairs of runs per size (the faster "
                    "of each solver's runs is kept)")
    ap.add_argument("--vesselverify", default=os.path.join(ROOT, "build", "verification",
                                                           "vesselverify"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "measurements",
                                                  "solver_switch.md"))
    args = ap.parse_args()
    if not os.access(args.vesselverify, os.X_OK):
        sys.exit(f"{args.vesselverify}: not an executable (build first: scripts/build.sh)")
    env = dict(os.environ, VESSELVERIFY_CACHE_DIR=os.environ.get(
        "VESSELVERIFY_CACHE_DIR", os.path.join(tempfile.gettempdir(), "vesselverify-switch")))
    rows, loads = [], []
    for level, length in CASES:
        best = {}
        for k in range(args.repeats):
            order = ("direct", "matrix-free") if k % 2 == 0 else ("matrix-free", "direct")
            for solver in order:
                loads.append(float(measurement_host.load_average()))
                r = run(args.vesselverify, level, length, solver, env)
                if solver not in best or r["paid"] < best[solver]["paid"]:
                    best[solver] = r
        d, m = best["direct"], best["matrix-free"]
        rows.append(dict(level=level, length=length, dofs=d["dofs"], direct=d, mf=m,
                         ratio=d["paid"] / m["paid"]))
        print(f"level {level}, L {length} m, {d['dofs']} DoFs: CHOLMOD {d['paid']:.2f} s, "
              f"matrix-free {m['paid']:.2f} s, ratio {d['paid'] / m['paid']:.2f}", flush=True)
    rows.sort(key=lambda r: r["dofs"])
    cross = crossover(rows)
    table = ("| level | length (mm) | P2 DoFs | CHOLMOD (s) | matrix-free (s) | CHOLMOD / "
             "matrix-free | CHOLMOD peak MB | matrix-free peak MB |\n" + "| --- " * 8 + "|\n")
    table += "".join(
        f"| {r['level']} | {r['length'] * 1e3:g} | {r['dofs']} | {r['direct']['paid']:.2f} | "
        f"{r['mf']['paid']:.2f} | {r['ratio']:.2f} | {r['direct']['mb']:.0f} | "
        f"{r['mf']['mb']:.0f} |\n" for r in rows)
    page = ("# When `auto` solves P2 without a matrix: CHOLMOD against the matrix-free "
            "p-multigrid\n\n"
            "`vesselverify fem --structured --level L --length LEN --degree 2 --bc clamped "
            "--load pressure --formulation displacement --nu 0.3 --solver S`, S = direct "
            "(CHOLMOD) and matrix-free (CG to 1e-10 with the P2 → P1 p-multigrid), alternately, "
            f"{args.repeats} runs each per size, the faster kept. Time: the CLI's set-up + "
            "assembly + solve, what a user pays for the linear system (mesh generation and "
            "output apart). Structured straight tube, a = 3 mm, t = 1 mm, both ends clamped, "
            "internal pressure 10 Pa, E = 14240 Pa. The 1-minute load average before the runs: "
            f"{min(loads):.1f}–{max(loads):.1f} on this 2-core machine.\n\n"
            "Regenerate: `/usr/bin/python3 scripts/measure_solver_switch.py "
            f"--repeats {args.repeats}`\n\n" + table +
            (f"\nThe ratio crosses 1 at about {cross:.0f} P2 DoFs (log-log interpolation); "
             "`auto` takes the matrix-free solve from `SolverOptions::matrix_free_min_dofs` "
             "(`--matrix-free-min-dofs`) for one linear P2 solve on straight-sided tets. A "
             "reference solved for several loads on one factor (`keep_factor`), a curved wall "
             "and P1 keep CHOLMOD.\n" if cross else
             "\nThe ratio does not cross 1 within these sizes.\n"))
    with open(args.out, "w") as f:
        f.write(page)
    print(page)


if __name__ == "__main__":
    main()
