#!/usr/bin/python3
"""The FEM reference side by side with CalculiX (ccx) on the same mesh, load and supports.

Per level: `vesselverify mesh` writes the structured straight tube; the script writes the same
mesh as a CalculiX deck (C3D10: the P2 tets with straight sides, midside nodes at the edges'
midpoints), clamped ends (both end faces' nodes held), internal pressure on inner_wall (*DLOAD
P faces), then runs `vesselverify fem --degree 2 --bc clamped` and `ccx` alternately (--repeats
times each, the fastest kept), compares the displacement at the mesh's vertices (largest
difference relative to the largest displacement), and reports wall time and peak memory
(/usr/bin/time) of each whole run, mesh reading and set-up included. Both solve on every core.

Usage: /usr/bin/python3 scripts/calculix_side_by_side.py [--levels 0,1] [--nu 0.3]
           [--pressure 10] [--repeats 2] [--solver direct] [--vesselverify build/verification/vesselverify]
           [--out table.md] [--keep DIR]
Exit status 1 if a field differs by more than --tolerance (default 1e-6: CalculiX prints
seven significant digits)."""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from measurement_host import load_average

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# C3D10's midside nodes 5..10 sit on the corner pairs (1,2), (2,3), (3,1), (1,4), (2,4), (3,4);
# its faces 1..4 are (1,2,3), (1,4,2), (2,4,3), (3,4,1) (CalculiX manual, element C3D10).
MIDSIDE = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


def read_msh22(path):
    """Nodes {id: (x, y, z)}, tets [(n1..n4)], and per physical name its triangles."""
    text = open(path, encoding="utf-8").read()
    names = {}
    block = re.search(r"\$PhysicalNames\n(.*?)\$EndPhysicalNames", text, re.S)
    for line in block.group(1).splitlines()[1:]:
        dim, tag, name = line.split(maxsplit=2)
        names[int(tag)] = name.strip('"')
    nodes = {}
    for line in re.search(r"\$Nodes\n(.*?)\$EndNodes", text, re.S).group(1).splitlines()[1:]:
        i, x, y, z = line.split()
        nodes[int(i)] = (float(x), float(y), float(z))
    tets, groups = [], {}
    for line in re.search(r"\$Elements\n(.*?)\$EndElements", text, re.S).group(1).splitlines()[1:]:
        f = [int(v) for v in line.split()]
        kind, ntags = f[1], f[2]
        conn = f[3 + ntags:]
        if kind == 4:
            tets.append(tuple(conn))
        elif kind == 2:
            groups.setdefault(names[f[3]], []).append(tuple(conn))
    for required in ("inlet", "outlet", "inner_wall"):
        if required not in groups:
            sys.exit(f"{path}: no surface group '{required}' (expected a vesselverify vessel mesh)")
    return nodes, tets, groups


def write_deck(path, nodes, tets, groups, E, nu, pressure):
    """The CalculiX input deck; returns the vertex node ids (the ones both codes report)."""
    next_id = max(nodes) + 1
    midside = {}
    elements = []
    for t in tets:
        mids = []
        for a, b in MIDSIDE:
            key = (min(t[a], t[b]), max(t[a], t[b]))
            if key not in midside:
                midside[key] = next_id
                next_id += 1
            mids.append(midside[key])
        elements.append(tuple(t) + tuple(mids))
    face_of = {}  # sorted corner triple -> (element, face number)
    for e, t in enumerate(elements, start=1):
        for k, face in enumerate(FACES, start=1):
            face_of[tuple(sorted(t[i] for i in face))] = (e, k)
    held = set()
    for g in ("inlet", "outlet"):
        for tri in groups[g]:
            held.update(tri)
            for a, b in ((0, 1), (1, 2), (2, 0)):
                held.add(midside[(min(tri[a], tri[b]), max(tri[a], tri[b]))])
    with open(path, "w", encoding="utf-8") as f:
        f.write("*NODE, NSET=NALL\n")
        for i, x in nodes.items():
            f.write(f"{i}, {x[0]:.13e}, {x[1]:.13e}, {x[2]:.13e}\n")
        for (a, b), i in midside.items():
            x = [(nodes[a][c] + nodes[b][c]) / 2 for c in range(3)]
            f.write(f"{i}, {x[0]:.13e}, {x[1]:.13e}, {x[2]:.13e}\n")
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        for e, t in enumerate(elements, start=1):
            f.write(f"{e}, " + ", ".join(map(str, t[:8])) + ",\n" + ", ".join(map(str, t[8:])) + "\n")
        f.write("*NSET, NSET=HELD\n")
        ids = sorted(held)
        for k in range(0, len(ids), 8):
            f.write(", ".join(map(str, ids[k:k + 8])) + ",\n")
        f.write(f"*MATERIAL, NAME=WALL\n*ELASTIC\n{E:.13e}, {nu:.13e}\n")
        f.write("*SOLID SECTION, ELSET=EALL, MATERIAL=WALL\n")
        f.write("*STEP\n*STATIC\n*BOUNDARY\nHELD, 1, 3, 0.\n*DLOAD\n")
        for tri in groups["inner_wall"]:
            e, k = face_of[tuple(sorted(tri))]
            f.write(f"{e}, P{k}, {pressure:.13e}\n")
        f.write("*NODE PRINT, NSET=NALL\nU\n*END STEP\n")
    return sorted(nodes)


def read_dat_displacements(path):
    """{node id: (ux, uy, uz)} from ccx's .dat (*NODE PRINT U)."""
    u = {}
    number = r"[-+]?\d\.\d+E[-+]\d+"
    for m in re.finditer(rf"^\s*(\d+)\s+({number})\s+({number})\s+({number})\s*$",
                         open(path, encoding="utf-8").read(), re.M):
        u[int(m.group(1))] = tuple(float(m.group(k)) for k in (2, 3, 4))
    return u


def read_vtu(path):
    """Points and the displacement field of a vesselverify fem --vtu file (ASCII)."""
    text = open(path, encoding="utf-8").read()

    def array(pattern):
        m = re.search(pattern + r"[^>]*>(.*?)</DataArray>", text, re.S)
        v = [float(x) for x in m.group(1).split()]
        return [tuple(v[i:i + 3]) for i in range(0, len(v), 3)]
    points = array(r'<Points>\s*<DataArray')
    return points, array(r'<DataArray[^>]*Name="displacement"')


def timed(cmd, cwd, env):
    """Runs cmd under /usr/bin/time; returns (wall s, peak RSS MB, stdout)."""
    p = subprocess.run(["/usr/bin/time", "-f", "TIMED %e %M"] + cmd, cwd=cwd, env=env,
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    wall, rss = re.findall(r"TIMED ([\d.]+) (\d+)", p.stderr)[-1]
    return float(wall), int(rss) / 1024, p.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", default="0,1")
    ap.add_argument("--nu", type=float, default=0.3)
    ap.add_argument("--E", type=float, default=14.24e3)
    ap.add_argument("--pressure", type=float, default=10.0)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--solver", default="direct", choices=["direct", "cg-amg", "matrix-free"],
                    help="vesselverify fem --solver")
    ap.add_argument("--tolerance", type=float, default=1e-6)
    ap.add_argument("--vesselverify", default=os.path.join(ROOT, "build", "verification",
                                                           "vesselverify"))
    ap.add_argument("--out", help="also write the table (Markdown) here")
    ap.add_argument("--keep", help="keep the meshes, decks and outputs in this folder")
    args = ap.parse_args()
    if shutil.which("ccx") is None:
        sys.exit("ccx not found: scripts/install_deps.sh installs calculix-ccx")
    if not os.access(args.vesselverify, os.X_OK):
        sys.exit(f"{args.vesselverify}: not an executable (build first: scripts/build.sh)")
    work = args.keep or tempfile.mkdtemp(prefix="vesselverify-calculix-")
    os.makedirs(work, exist_ok=True)
    threads = str(os.cpu_count())
    env = dict(os.environ, OMP_NUM_THREADS=threads, CCX_NPROC_EQUATION_SOLVER=threads,
               VESSELVERIFY_CACHE_DIR=os.path.join(work, "cache"))
    rows, worst = [], 0.0
    try:
        for level in [int(v) for v in args.levels.split(",") if v]:
            msh = os.path.join(work, f"tube_L{level}.msh")
            subprocess.run([args.vesselverify, "mesh", "--structured", "--level", str(level),
                            "--no-cache", "-o", msh, "--msh-version", "2.2"], check=True,
                           env=env, stdout=subprocess.DEVNULL)
            nodes, tets, groups = read_msh22(msh)
            job = os.path.join(work, f"ccx_L{level}")
            vertices = write_deck(job + ".inp", nodes, tets, groups, args.E, args.nu, args.pressure)
            vtu = os.path.join(work, f"vv_L{level}.vtu")
            vv_cmd = [args.vesselverify, "fem", "--input", msh, "--degree", "2", "--bc", "clamped",
                      "--load", "pressure", "--pressure", repr(args.pressure), "--E", repr(args.E),
                      "--nu", repr(args.nu), "--solver", args.solver, "--vtu", vtu]
            vv_runs, ccx_runs = [], []
            load_before = load_average()
            for _ in range(args.repeats):  # alternately, so both see the same machine
                vv_runs.append(timed(vv_cmd, work, env))
                ccx_runs.append(timed(["ccx", "-i", os.path.basename(job)], work, env))
            load_after = load_average()
            dofs = re.search(r"(\d+) DoFs", vv_runs[0][2])
            points, u_vv = read_vtu(vtu)
            u_ccx = read_dat_displacements(job + ".dat")
            # The VTU's points are the mesh's nodes in the file's order (ids 1..n, as gmsh wrote).
            diff = scale = 0.0
            for k, node in enumerate(vertices):
                x, a, b = nodes[node], u_vv[k], u_ccx[node]
                if max(abs(x[c] - points[k][c]) for c in range(3)) > 1e-9:
                    sys.exit(f"node {node}: the VTU's point {points[k]} is not the mesh's {x}")
                diff = max(diff, sum((a[c] - b[c]) ** 2 for c in range(3)) ** 0.5)
                scale = max(scale, sum(b[c] ** 2 for c in range(3)) ** 0.5)
            rel = diff / scale
            worst = max(worst, rel)
            vv_best, ccx_best = min(vv_runs), min(ccx_runs)
            rows.append((level, dofs.group(1) if dofs else "?", vv_best, ccx_best, rel,
                         load_before, load_after))
            print(f"level {level}: vesselverify {vv_best[0]:.1f} s, {vv_best[1]:.0f} MB; ccx "
                  f"{ccx_best[0]:.1f} s, {ccx_best[1]:.0f} MB; ratio {ccx_best[0] / vv_best[0]:.2f}; "
                  f"fields differ by {rel:.2e} of max|u|", flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    lines = [f"Structured straight tube, P2 (C3D10), clamped ends, {args.pressure:g} Pa inside, "
             f"E {args.E:g} Pa, ν {args.nu:g}; {os.cpu_count()} cores, the fastest of "
             f"{args.repeats} alternate runs each (whole program: mesh reading, set-up, solve, "
             f"output); vesselverify's solver: {args.solver}. `/usr/bin/python3 "
             f"scripts/calculix_side_by_side.py --levels {args.levels} --solver {args.solver}`.", "",
             "| level | DoFs | vesselverify s | MB | CalculiX 2.20 s | MB | CalculiX / vesselverify "
             "| max\\|Δu\\| / max\\|u\\| | load before / after |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    lines += [f"| {r[0]} | {r[1]} | {r[2][0]:.1f} | {r[2][1]:.0f} | {r[3][0]:.1f} | {r[3][1]:.0f} | "
              f"{r[3][0] / r[2][0]:.2f} | {r[4]:.1e} | {r[5]} / {r[6]} |" for r in rows]
    table = "\n".join(lines) + "\n"
    print(table)
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            f.write(table)
    if worst > args.tolerance:
        sys.exit(f"the fields differ by {worst:.2e} of max|u| (tolerance {args.tolerance:g})")


if __name__ == "__main__":
    main()
