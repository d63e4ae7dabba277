#!/usr/bin/env python3
"""Checks that the project's imports run one way: no folder includes a folder that includes it
back (directly or through others), and no library folder includes a floor above it.

Folders are the directories holding sources (meshes/foundation, msm/kernels, verification/harness,
...); an include "a/b/c.hpp" is an import of the folder "a/b". Floors, lowest first, are given
below; a folder may import its own floor and those below. Prints each violation and exits 1 if
there is any. Usage: scripts/check_layers.py [repo-root]
"""
import pathlib
import re
import sys

# Lowest first. A folder belongs to the longest prefix listed.
FLOORS = [
    "meshes/foundation",
    "meshes",
    "msm/form",
    "msm/linalg",
    "msm/topology",
    "msm/kernels",
    "msm/stiffness",
    "msm/mass",
    "msm/terms",
    "msm/fem",
    "msm/model",
    "msm/formats",
    "msm/pbd",
    "msm/solvers",
    "msm/stability",
    "msm/dynamics",
    "msm/calibration",
    "msm/rods",
    "msm/benchmarks",
    "fem_reference",
    "verification/contact",
    "verification/guidewire",
    "reports",
    "verification/scene",
    "verification/contact_models",
    "verification/harness",
    "verification/studies",
    "verification/cli",
]
SOURCE_ROOTS = ["meshes", "msm", "fem_reference", "reports", "verification", "examples"]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def floor_of(folder):
    best = None
    for i, f in enumerate(FLOORS):
        if folder == f or folder.startswith(f + "/"):
            if best is None or len(f) > len(FLOORS[best]):
                best = i
    return best


def own_folder(folder):
    """verification/ itself holds the scene layer (the scene, its problems, calibration files);
    a detail/ folder is the private half of its parent's target."""
    if folder == "verification":
        return "verification/scene"
    return folder[: -len("/detail")] if folder.endswith("/detail") else folder


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    edges = {}  # folder -> {imported folder: example file}
    for top in SOURCE_ROOTS:
        for path in (root / top).rglob("*"):
            if path.suffix not in (".cpp", ".hpp"):
                continue
            folder = own_folder(str(path.parent.relative_to(root)))
            for inc in INCLUDE.findall(path.read_text(errors="replace")):
                target = own_folder(str(pathlib.PurePosixPath(inc).parent))
                if not (root / inc).exists() or target == folder:
                    continue
                edges.setdefault(folder, {}).setdefault(target, str(path.relative_to(root)))
    problems = []
    # 1. Floors: a library folder never imports a floor above its own (examples/ stand outside).
    for src, targets in sorted(edges.items()):
        fs = floor_of(own_folder(src))
        if fs is None:
            continue
        for dst, example in sorted(targets.items()):
            fd = floor_of(own_folder(dst))
            if fd is not None and fd > fs:
                problems.append(f"{example}: {src} (floor {FLOORS[fs]}) imports {dst}, a floor above "
                                f"({FLOORS[fd]})")
    # 2. Cycles between folders (Tarjan's strongly connected components).
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                sccs.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    for comp in sccs:
        links = [f"{a} -> {b} ({edges[a][b]})" for a in comp for b in edges.get(a, {}) if b in comp]
        problems.append("folders importing each other: " + "; ".join(links))
    for p in problems:
        print(p)
    folders = len(edges)
    imports = sum(len(t) for t in edges.values())
    print(f"check_layers: {folders} folders, {imports} folder imports, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
