#!/usr/bin/python3
"""A user's own guidewire model for vesselverify, in Python with numpy only.

It reads one wire case (manifest.json, schema vesselverify.exchange with a "wire" object, see
verification/exchange.schema.json): a wire clamped at a point on the straight lumen's axis,
tilted from it, inserted `length_m`, inside a lumen whose centreline offset (the lumen's radius
less the wire's) it must not exceed. It solves the wire as a continuous inextensible Kirchhoff rod
in the plane of the axis and the clamp's tilt, its tip on the wall under a force normal to the
axis (shooting: EI theta' = -F (z_tip - z), x' = sin theta, z' = cos theta, RK4 on 40 steps per
segment, Newton on F and z_tip so that x(L) = offset), and writes the centreline at the manifest's
segment nodes (centreline.csv: node,x,y,z in m, node 0 the clamp) and the wall's force on the tip
(contact.json: {"force_N": F, "node": N}) beside the manifest.

Usage: /usr/bin/python3 wire_model.py CASE_DIR/manifest.json
       (vesselverify appends the manifest's path; VESSELVERIFY_MANIFEST holds it too)

A wire that does not reach the wall is answered with force 0 (a straight wire). Other lumens, or
a clamp off the axis, are refused with exit code 2 and the reason.
"""
import json
import os
import sys

import numpy as np


def shoot(theta0, ei, length, force, z_tip, steps):
    """RK4 on (theta, x, z) over s in [0, L]; the states at every step."""
    def rhs(y):
        theta, _, z = y
        return np.array([-force * (z_tip - z) / ei, np.sin(theta), np.cos(theta)])

    h = length / steps
    y = np.array([theta0, 0.0, 0.0])
    out = [y]
    for _ in range(steps):
        k1 = rhs(y)
        k2 = rhs(y + 0.5 * h * k1)
        k3 = rhs(y + 0.5 * h * k2)
        k4 = rhs(y + h * k3)
        y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(y)
    return np.array(out)


def solve(theta0, ei, length, offset, steps):
    """F and the states: the tip at x = offset with zero moment there."""
    free = shoot(theta0, ei, length, 0.0, 0.0, steps)
    if free[-1, 1] <= offset:
        return 0.0, free  # the straight wire does not reach the wall
    # Unknowns: F (scaled by EI/L^2) and z_tip (scaled by L).
    u = np.array([0.5, free[-1, 2] / length])

    def residual(u):
        y = shoot(theta0, ei, length, u[0] * ei / length ** 2, u[1] * length, steps)
        return np.array([(y[-1, 1] - offset) / length, y[-1, 2] / length - u[1]])

    for _ in range(50):
        r = residual(u)
        if np.linalg.norm(r) < 1e-13:
            break
        jac = np.empty((2, 2))
        for k in range(2):
            du = np.zeros(2)
            du[k] = 1e-7
            jac[:, k] = (residual(u + du) - residual(u - du)) / 2e-7
        u = u - np.linalg.solve(jac, r)
    else:
        sys.exit("wire_model: the shooting did not converge")
    force = u[0] * ei / length ** 2
    return force, shoot(theta0, ei, length, force, u[1] * length, steps)


def main():
    manifest_path = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("VESSELVERIFY_MANIFEST")
    if not manifest_path:
        sys.exit("usage: wire_model.py CASE_DIR/manifest.json")
    with open(manifest_path) as f:
        manifest = json.load(f)
    wire = manifest.get("wire")
    if wire is None:
        print("wire_model: this case has no wire (a vessel case?)", file=sys.stderr)
        sys.exit(2)
    lumen = wire["lumen"]
    if lumen["kind"] != "straight":
        print("wire_model: only straight lumens, found " + lumen["kind"], file=sys.stderr)
        sys.exit(2)
    axis = np.array(lumen["axis_direction"], dtype=float)
    origin = np.array(lumen["axis_origin_m"], dtype=float)
    clamp = np.array(wire["clamp"]["point_m"], dtype=float)
    direction = np.array(wire["clamp"]["direction"], dtype=float)
    off_axis = (clamp - origin) - np.dot(clamp - origin, axis) * axis
    if np.linalg.norm(off_axis) > 1e-12:
        print("wire_model: the clamp must be on the lumen's axis", file=sys.stderr)
        sys.exit(2)
    across = direction - np.dot(direction, axis) * axis
    if np.linalg.norm(across) < 1e-12:
        print("wire_model: the clamp must tilt from the axis", file=sys.stderr)
        sys.exit(2)
    across /= np.linalg.norm(across)
    theta0 = np.arctan2(np.dot(direction, across), np.dot(direction, axis))
    n = int(wire["segments"])
    steps_per_segment = 40
    force, states = solve(theta0, wire["bending_stiffness_Nm2"], wire["length_m"],
                          lumen["centreline_offset_m"], n * steps_per_segment)
    nodes = states[::steps_per_segment]
    case_dir = os.path.dirname(os.path.abspath(manifest_path))
    with open(os.path.join(case_dir, manifest["output"]["centreline"]), "w") as f:
        f.write("node,x,y,z\n")
        for i, (_, x, z) in enumerate(nodes):
            p = clamp + z * axis + x * across
            f.write("%d,%.17g,%.17g,%.17g\n" % (i, p[0], p[1], p[2]))
    with open(os.path.join(case_dir, manifest["output"]["contact"]), "w") as f:
        json.dump({"force_N": force, "node": n}, f)


if __name__ == "__main__":
    main()
