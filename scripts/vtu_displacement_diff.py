#!/usr/bin/python3
"""Largest nodal difference of the `displacement` point field of two VTU files written by
vesselverify (same mesh, ASCII): max_i |u_a,i - u_b,i| / max_i |u_b,i|. Standard library only.
Usage: scripts/vtu_displacement_diff.py a.vtu b.vtu"""
import math
import re
import sys


def displacement(path):
    text = open(path, encoding="utf-8").read()
    m = re.search(r'<DataArray[^>]*Name="displacement"[^>]*>(.*?)</DataArray>', text, re.S)
    if not m:
        sys.exit(f"{path}: no 'displacement' point field (expected a vesselverify fem --vtu file)")
    v = [float(x) for x in m.group(1).split()]
    return [v[i:i + 3] for i in range(0, len(v), 3)]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = displacement(sys.argv[1]), displacement(sys.argv[2])
    if len(a) != len(b):
        sys.exit(f"different node counts: {len(a)} vs {len(b)} (expected the same mesh)")
    diff = max(math.dist(x, y) for x, y in zip(a, b))
    scale = max(math.hypot(*y) for y in b)
    print(f"nodes {len(a)}  max|u_b| {scale * 1e3:.6g} mm  max|u_a - u_b| {diff * 1e3:.3g} mm  "
          f"relative {diff / scale:.3g}")


if __name__ == "__main__":
    main()
