#!/usr/bin/env python3
"""Figures of the guidewire scenes of a results.json (scenes whose load is a guidewire):

- <scene>_guidewire_shape.png: the wire's centreline against the rigid lumen at each EI, in the
  plane of its contact (mm);
- <scene>_guidewire_forces.png: each model's coupled contact force over the reference's and over
  the rigid wire's, against EI (compliant coupling). F/F_rigid near 1 is force control (the wire
  is the soft spring), falling with EI is displacement control (the wall is). A hollow marker is a
  row whose springs dent the reference's wall deeper than it is thick (reference_within_wall
  false): the springs' arithmetic, not a state of the vessel.

Usage: /usr/bin/python3 scripts/guidewire_figures.py results.json output-dir
"""
import json
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def shape_figure(scene, out):
    g = scene["guidewire"]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    for r in g["rigid"]:
        line = r["centreline_mm"]
        n = r["normal"]
        # Plot in the plane spanned by the vessel's axis and the contact normal.
        if "arch" in scene["vessel"]:
            xs, ys = [p[0] for p in line], [p[1] for p in line]
            ax.set_xlabel("x (mm)")
            ax.set_ylabel("y (mm)")
        else:
            xs = [p[2] for p in line]
            ys = [p[0] * n[0] + p[1] * n[1] for p in line]
            ax.set_xlabel("z along the axis (mm)")
            ax.set_ylabel("towards the contact (mm)")
        ax.plot(xs, ys, marker=".", ms=3,
                label="EI = %.0e N·m², F = %.3g mN" % (r["bending_stiffness_Nm2"],
                                                        r["contact_force_N"] * 1e3))
    w = g["rigid"][0]["wall_point_mm"]
    ax.plot([w[2] if "arch" not in scene["vessel"] else w[0]],
            [w[0] if "arch" not in scene["vessel"] else w[1]], "kx", label="patch centre")
    ax.set_aspect("equal")
    ax.set_title(scene["name"] + ": the wire against the rigid lumen")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / (scene["name"] + "_guidewire_shape.png"), dpi=120)
    plt.close(fig)


def force_figure(scene, out):
    g = scene["guidewire"]
    rows = [r for r in g["coupling_rows"] if r["ok"]]
    if not rows:
        return
    rigid = {r["bending_stiffness_Nm2"]: r["contact_force_N"] * 1e3 for r in g["rigid"]}
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.5))
    models = sorted({r["model"] for r in rows})
    for m in models:
        mine = sorted((r for r in rows if r["model"] == m), key=lambda r: r["bending_stiffness_Nm2"])
        ei = [r["bending_stiffness_Nm2"] for r in mine]
        held = [r.get("reference_within_wall", True) for r in mine]
        for a, y in ((a1, [r["force_mN"] / rigid[r["bending_stiffness_Nm2"]] for r in mine]),
                     (a2, [r["force_mN"] / r["reference_force_mN"] for r in mine])):
            (line,) = a.plot(ei, y, "-", label=m)
            for x, v, h in zip(ei, y, held):
                a.plot([x], [v], "o", color=line.get_color(), mfc=line.get_color() if h else "none")
    ref = sorted((r for r in rows if r["model"] == models[0]), key=lambda r: r["bending_stiffness_Nm2"])
    a1.plot([r["bending_stiffness_Nm2"] for r in ref],
            [r["reference_force_mN"] / rigid[r["bending_stiffness_Nm2"]] for r in ref], "k--",
            label="reference")
    for a in (a1, a2):
        a.set_xscale("log")
        a.set_xlabel("wire EI (N·m²)")
        a.grid(True, which="both", alpha=0.3)
    a1.set_ylabel("F / F_rigid")
    a1.set_title("force control (≈1) to displacement control")
    a2.set_ylabel("F_model / F_reference")
    a2.set_title("contact-force error")
    a1.legend(fontsize=7)
    beyond = any(not r.get("reference_within_wall", True) for r in rows)
    fig.suptitle(scene["name"] + ": coupled contact force (linear walls)"
                 + ("; hollow: the wall dented deeper than it is thick" if beyond else ""))
    fig.tight_layout()
    fig.savefig(out / (scene["name"] + "_guidewire_forces.png"), dpi=120)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    results = json.loads(pathlib.Path(sys.argv[1]).read_text())
    out = pathlib.Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    for scene in results["scenes"]:
        if "guidewire" not in scene:
            continue
        shape_figure(scene, out)
        force_figure(scene, out)
        print("wrote", out / (scene["name"] + "_guidewire_{shape,forces}.png"))


if __name__ == "__main__":
    main()
