#!/usr/bin/python3
"""An external model for vesselverify in Python with numpy only (Debian's python3-numpy).

It reads one exchange case (manifest.json and problem.vtu, see verification/exchange.schema.json),
builds a linear spring network on the tetrahedra's edges with Van Gelder's stiffness
k = E * sum(V_tet) / L^2 (sum over the tets sharing the edge), solves K u = f at rest by
Jacobi-preconditioned conjugate gradients with the fixed components held at zero, and writes
displacements.vtu (point data 'displacement', m) and timing.json beside the manifest.

Usage: /usr/bin/python3 python_model.py CASE_DIR/manifest.json
       (vesselverify appends the manifest's path; VESSELVERIFY_MANIFEST holds it too)

Static problems on tetra cells only: anything else is refused with exit code 2 and the reason.
"""
import json
import os
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np


def read_arrays(vtu_path):
    """Points, connectivity and point data of an ASCII .vtu as numpy arrays."""
    root = ET.parse(vtu_path).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    n_points = int(piece.get("NumberOfPoints"))

    def values(array, dtype=float):
        if array.get("format", "ascii") != "ascii":
            sys.exit(f"{vtu_path}: expected format=\"ascii\" DataArrays")
        return np.array(array.text.split(), dtype=dtype)

    points = values(piece.find("Points/DataArray")).reshape(n_points, 3)
    cells = {a.get("Name"): a for a in piece.find("Cells").findall("DataArray")}
    connectivity = values(cells["connectivity"], np.int64)
    types = values(cells["types"], np.int64)
    point_data = {}
    for a in piece.find("PointData").findall("DataArray"):
        k = int(a.get("NumberOfComponents", "1"))
        v = values(a)
        point_data[a.get("Name")] = v.reshape(n_points, k) if k > 1 else v
    return points, connectivity, types, point_data


def van_gelder_springs(points, tets, youngs_modulus):
    """Edges (a, b) and k = E * sum of the volumes of the tets sharing the edge / L^2."""
    x = points[tets]  # (T, 4, 3)
    volume = np.abs(np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]),
                              x[:, 3] - x[:, 0])) / 6.0
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    a = np.concatenate([tets[:, i] for i, _ in pairs])
    b = np.concatenate([tets[:, j] for _, j in pairs])
    v = np.tile(volume, len(pairs))
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    edges, inverse = np.unique(np.stack([lo, hi], axis=1), axis=0, return_inverse=True)
    summed = np.bincount(inverse.ravel(), weights=v, minlength=len(edges))
    length2 = np.sum((points[edges[:, 1]] - points[edges[:, 0]]) ** 2, axis=1)
    return edges, youngs_modulus * summed / length2


def solve(points, edges, k, load, fixed, tolerance=1e-10):
    """K u = f for the springs linearised at rest (K = sum k n n^T), fixed components zero."""
    n = len(points)
    d = points[edges[:, 1]] - points[edges[:, 0]]
    unit = d / np.linalg.norm(d, axis=1)[:, None]
    free = (fixed == 0).astype(float)

    def scatter(f):  # sum the per-edge vectors f onto both ends (+ at b, - at a)
        out = np.empty((n, 3))
        for c in range(3):
            out[:, c] = (np.bincount(edges[:, 1], f[:, c], n) -
                         np.bincount(edges[:, 0], f[:, c], n))
        return out

    def apply(u):
        s = k * np.einsum("ij,ij->i", unit, u[edges[:, 1]] - u[edges[:, 0]])
        return scatter(s[:, None] * unit) * free

    diagonal = np.empty((n, 3))
    for c in range(3):
        w = k * unit[:, c] ** 2
        diagonal[:, c] = np.bincount(edges[:, 0], w, n) + np.bincount(edges[:, 1], w, n)
    inverse_diagonal = np.where(free > 0, 1.0 / np.maximum(diagonal, 1e-300), 0.0)

    f = load * free
    u = np.zeros((n, 3))
    r = f.copy()
    z = r * inverse_diagonal
    p = z.copy()
    rz = np.sum(r * z)
    norm_f = np.linalg.norm(f)
    if norm_f == 0.0:
        return u, 0
    for iteration in range(1, 20 * 3 * n):
        q = apply(p)
        alpha = rz / np.sum(p * q)
        u += alpha * p
        r -= alpha * q
        if np.linalg.norm(r) <= tolerance * norm_f:
            return u, iteration
        z = r * inverse_diagonal
        rz_new = np.sum(r * z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    sys.exit(f"conjugate gradients did not converge in {iteration} iterations")


def write_vtu(path, points, displacement):
    """displacements.vtu: the problem's points in order, point data 'displacement' (m)."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">',
             '  <UnstructuredGrid>',
             f'    <Piece NumberOfPoints="{len(points)}" NumberOfCells="0">',
             '      <PointData>',
             '        <DataArray type="Float64" Name="displacement" NumberOfComponents="3" '
             'format="ascii">']
    lines += [" ".join(repr(float(v)) for v in row) for row in displacement]
    lines += ['        </DataArray>', '      </PointData>', '      <Points>',
              '        <DataArray type="Float64" NumberOfComponents="3" format="ascii">']
    lines += [" ".join(repr(float(v)) for v in row) for row in points]
    lines += ['        </DataArray>', '      </Points>', '      <Cells>',
              '        <DataArray type="Int64" Name="connectivity" format="ascii"></DataArray>',
              '        <DataArray type="Int64" Name="offsets" format="ascii"></DataArray>',
              '        <DataArray type="UInt8" Name="types" format="ascii"></DataArray>',
              '      </Cells>', '    </Piece>', '  </UnstructuredGrid>', '</VTKFile>']
    temporary = path + ".tmp"
    with open(temporary, "w") as out:
        out.write("\n".join(lines) + "\n")
    os.replace(temporary, path)  # never a half-written answer


def main():
    manifest_path = sys.argv[1] if len(sys.argv) > 1 else os.environ["VESSELVERIFY_MANIFEST"]
    case_dir = os.path.dirname(os.path.abspath(manifest_path))
    with open(manifest_path) as f:
        manifest = json.load(f)
    if manifest["schema"] != "vesselverify.exchange" or manifest["schema_version"] != 1:
        print("expected a vesselverify.exchange manifest, version 1", file=sys.stderr)
        return 2
    if manifest["analysis"]["type"] != "static":
        print("this example answers static problems only", file=sys.stderr)
        return 2
    if manifest["problem"]["cell_type"] != "tetra":
        print("this example needs tetra cells (nodes = \"volume\")", file=sys.stderr)
        return 2
    start = time.perf_counter()
    points, connectivity, types, data = read_arrays(
        os.path.join(case_dir, manifest["problem"]["file"]))
    tets = connectivity.reshape(-1, 4)
    edges, k = van_gelder_springs(points, tets, manifest["material"]["youngs_modulus_pa"])
    set_up = time.perf_counter()
    u, iterations = solve(points, edges, k, data["load_N"], data["fixed"])
    solved = time.perf_counter()
    write_vtu(os.path.join(case_dir, "displacements.vtu"), points, u)
    with open(os.path.join(case_dir, "timing.json"), "w") as f:
        json.dump({"setup_seconds": set_up - start, "solve_seconds": solved - set_up}, f)
    print(f"{len(points)} nodes, {len(edges)} springs, CG {iterations} iterations, "
          f"max |u| = {np.max(np.linalg.norm(u, axis=1)) * 1e3:.4g} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
