#!/usr/bin/env python3
"""Corotational P1 and XPBD FEM beside the contact scenes' spring networks and linear P1, judged
against the finite-strain reference at 1, 10 and 70 mN and timed per update.

All models on the scene's level-0 mesh; writes docs/measurements/fem_models_vs_springs.md.

Each scene (verification/scenes/contact_straight.toml, contact_arch.toml) is copied to a
temporary folder with a corotational_fem and an xpbd_fem model added at their defaults where it
has none of the kind, and its calibration paths made absolute, then run by

    vesselverify validity SCENE --ladder 0.001,0.01,0.07 --models ... --time-updates --fields none

which judges every model against the finite-strain (neo-Hookean) reference, P2 on level 0, along
the ladder and times each model's update as `vesselverify run` does (set-up apart: a ramp of
warm-started updates to the load; XPBD FEM from rest to its steady state, its time per update the
per-step cost × the steps one update period holds).

Usage: /usr/bin/python3 scripts/measure_fem_models_vs_springs.py [--scenes contact_straight,contact_arch]
           [--loads 0.001,0.01,0.07] [--vesselverify build/verification/vesselverify] [--out PAGE]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES_DIR = os.path.join(ROOT, "verification", "scenes")
# Added to a scene that lacks a model of the kind (at the kind's defaults).
ADDED_MODELS = {
    "corotational_fem": ("fem/corotational-p1", "corotational P1"),
    "xpbd_fem": ("fem/xpbd-neo-hookean", "XPBD FEM"),
}
RATES = [(30.0, "update_seconds_30hz"), (1000.0, "update_seconds_1khz")]


def load_average():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def models_of(scene_text):
    """The scene's models the study judges: linear P1, the whole-vessel static spring models,
    corotational P1 and XPBD FEM."""
    scene = tomllib.loads(scene_text)
    out = []
    for m in scene.get("models", []):
        kind = m.get("kind")
        if kind == "fem" and m.get("degree", 2) == 1:
            out.append((m["name"], "linear P1"))
        elif kind in ("surface_msm", "volume_msm") and m.get("solver") in ("static", "linear") \
                and "roi_radius" not in m:
            # The edge pairs are P1's StVK tetrahedron written on the edges, not a spring network.
            out.append((m["name"], "edge pairs" if m.get("edge_pairs") else "springs"))
        elif kind in ADDED_MODELS:
            out.append((m["name"], ADDED_MODELS[kind][1]))
    return out


def study(vv, scene, loads, tmp, env):
    with open(os.path.join(SCENES_DIR, scene + ".toml")) as f:
        text = f.read()
    # Relative calibration files resolve against the scene's folder: name them absolutely.
    text = re.sub(r'^(calibration\s*=\s*")([^"/][^"]*)"',
                  lambda m: m.group(1) + os.path.join(SCENES_DIR, m.group(2)) + '"', text,
                  flags=re.M)
    present = {m.get("kind") for m in tomllib.loads(text).get("models", [])}
    for kind, (name, label) in ADDED_MODELS.items():
        if kind not in present:
            text += f'\n[[models]]\nname = "{name}"\nkind = "{kind}"\n'
    kinds = models_of(text)
    path = os.path.join(tmp, scene + ".toml")
    with open(path, "w") as f:
        f.write(text)
    out_dir = os.path.join(tmp, scene)
    cmd = [vv, "validity", path, "--ladder", ",".join(loads), "--models",
           ",".join(name for name, _ in kinds), "--time-updates", "--fields", "none",
           "--output-dir", out_dir]
    before = load_average()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    after = load_average()
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stdout}{p.stderr}")
    with open(os.path.join(out_dir, "validity.json")) as f:
        v = json.load(f)["scenes"][0]
    shown = " ".join(["vesselverify"] + [os.path.basename(c) if c == path else c
                                        for c in cmd[1:-2]])
    return dict(scene=scene, kinds=dict(kinds), order=[n for n, _ in kinds], v=v,
                load_before=before, load_after=after, command=shown)


def fmt(x, digits=3):
    return "—" if x is None else f"{x:.{digits}g}"


def ms(seconds):
    return "—" if seconds is None else f"{seconds * 1e3:.3g}"


def front(points):
    """The models no other beats in both time and error (time, error, name), by time."""
    pts = sorted(points)
    out, best = [], float("inf")
    for t, e, name in pts:
        if e < best:
            out.append(name)
            best = e
    return out


def scene_section(r):
    v, kinds = r["v"], r["kinds"]
    lines = [f"## {r['scene']}\n",
             f"`{r['command']}` (plus `--output-dir DIR`), the scene being "
             f"verification/scenes/{r['scene']}.toml with the two P1 tet models added; load average (1, 5, 15 min) "
             f"{r['load_before']} before, {r['load_after']} after.\n",
             f"Finite-strain reference: {v['element']} on level {v['reference_level']} "
             f"({v['dofs']} DoFs); models on level {v['model_level']}; contact point "
             f"({', '.join(f'{c:.3g}' for c in v['qoi_point_mm'])}) mm. "
             + ("The continuation reached every load." if v["continuation"]["completed"] else
                f"The continuation stopped at {v['continuation']['largest_load'] * 1e3:.3g} mN: "
                f"{v['continuation']['stop_reason']}.") + "\n"]
    verdicts = []
    for row in v["rows"]:
        load_mn = row["magnitude"] * 1e3
        by = {e["model"]: e for e in row["models"]}
        p1 = next((by[n] for n in r["order"] if kinds[n] == "linear P1" and by[n]["ok"]), None)
        lines.append(f"### {r['scene']} at {load_mn:.3g} mN\n")
        lines.append(f"Contact point moves {row['finite_qoi_mm']:.3g} mm in the finite-strain "
                     f"reference; the linear reference parts from it by "
                     f"{row['qoi_difference'] * 100:.3g} % there.\n")
        lines.append("| model | what | contact-point error (mm) | × P1 | largest nodal error (mm) "
                     "| × P1 | set-up (ms) | update (ms) | per update at 30 Hz (ms) | "
                     "per update at 1 kHz (ms) |")
        lines.append("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for name in r["order"]:
            e = by[name]
            if not e["ok"]:
                lines.append(f"| {name} | {kinds[name]} | failed: {e['failure']} |"
                             " | | | | | | |")
                continue
            t = e["timing"]
            steps = f" ({t['steps']} steps)" if t["steps"] else ""
            lines.append(
                f"| {name} | {kinds[name]} | {fmt(e['qoi_error_mm'])} | "
                f"{fmt(e['qoi_error_mm'] / p1['qoi_error_mm']) if p1 else '—'} | "
                f"{fmt(e['max_error_mm'])} | "
                f"{fmt(e['max_error_mm'] / p1['max_error_mm']) if p1 else '—'} | "
                f"{ms(t['setup_seconds'])} | {ms(t['update_seconds'])}{steps} | "
                f"{ms(t['update_seconds_30hz'])} | {ms(t['update_seconds_1khz'])} |")
        lines.append("")
        ok = [n for n in r["order"] if by[n]["ok"]]
        for rate, key in RATES:
            pts = [(by[n]["timing"][key], by[n]["qoi_error_mm"], n) for n in ok]
            lines.append(f"Speed–error front at {rate:g} Hz (contact-point error against time per "
                         f"update; fastest first): {', '.join(front(pts))}.")
        lines.append("")
        verdicts.append(verdict(r["scene"], load_mn, by, kinds, r["order"]))
    return "\n".join(lines) + "\n", verdicts


def verdict(scene, load_mn, by, kinds, order):
    springs = [n for n in order if kinds[n] == "springs" and by[n]["ok"]]
    if not springs:
        return f"- **{scene}, {load_mn:.3g} mN**: no spring network gave an answer."
    best = min(springs, key=lambda n: by[n]["qoi_error_mm"])
    best_err = by[best]["qoi_error_mm"]
    parts = []
    for fem in (n for n in order if kinds[n] in ("corotational P1", "XPBD FEM")):
        e = by[fem]
        if not e["ok"]:
            parts.append(f"{kinds[fem]} gave no answer ({e['failure']})")
            continue
        beats = e["qoi_error_mm"] < best_err
        budgets = []
        for rate, key in RATES:
            fits = e["timing"][key] <= 1.0 / rate
            budgets.append(f"{'within' if fits else 'over'} the {rate:g} Hz budget "
                           f"({ms(e['timing'][key])} ms per update)")
        parts.append(
            f"{kinds[fem]} ({fmt(e['qoi_error_mm'])} mm) "
            f"{'beats every spring network' if beats else 'does not beat every spring network'}"
            f" (the best, {best}, {fmt(best_err)} mm; {ms(by[best]['timing']['update_seconds'])}"
            f" ms per update), {budgets[0]} and {budgets[1]}")
    return f"- **{scene}, {load_mn:.3g} mN**: " + "; ".join(parts) + "."


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="contact_straight,contact_arch")
    ap.add_argument("--loads", default="0.001,0.01,0.07", help="contact loads, N")
    ap.add_argument("--vesselverify", default=os.path.join(ROOT, "build", "verification",
                                                           "vesselverify"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "measurements",
                                                  "fem_models_vs_springs.md"))
    args = ap.parse_args()
    if not os.access(args.vesselverify, os.X_OK):
        sys.exit(f"{args.vesselverify}: not an executable (build first: scripts/build.sh)")
    env = dict(os.environ, VESSELVERIFY_CACHE_DIR=os.environ.get(
        "VESSELVERIFY_CACHE_DIR", os.path.join(tempfile.gettempdir(), "vesselverify-fem-front")))
    loads = [x for x in args.loads.split(",") if x]
    sections, verdicts = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for scene in [s for s in args.scenes.split(",") if s]:
            text, v = scene_section(study(args.vesselverify, scene, loads, tmp, env))
            sections.append(text)
            verdicts += v
    page = (
        "# Corotational and XPBD FEM beside the springs, against the finite-strain reference\n\n"
        "Each model of the contact scenes on the same level-0 mesh: the scene's spring networks "
        "(and the edge pairs, P1's StVK tetrahedron on the edges, shown but not counted as a "
        "spring network), linear P1 FEM, corotational P1 (Müller & Gross 2004; static Newton "
        "with the consistent tangent) and XPBD FEM (Macklin & Müller 2021's stable neo-Hookean "
        "constraints, multipliers carried, stepped to its steady state at its defaults), judged "
        "against the finite-strain (neo-Hookean) reference, P2 on level 0, by "
        "`vesselverify validity --time-updates`. Errors: at the contact point (the budget's "
        "quantity) and the largest over the model's nodes, in mm and × linear P1's. Update: the "
        "median warm-started update of a ramp of 8 to the load, set-up apart (linear P1: a solve "
        "or superposition with the factor made at set-up; XPBD FEM: its run from rest to steady "
        "state, whose step count is shown). A simulator pays XPBD FEM's per-step cost × the "
        "steps one period holds (334 at 30 Hz, 10 at 1 kHz, at dt = 0.1 ms), so its time per "
        "update at a rate is that, while the other models pay their update. One run each on the "
        "2-core machine shared with other jobs: the load averages are beside each scene.\n\n"
        "Regenerate: `/usr/bin/python3 scripts/measure_fem_models_vs_springs.py "
        f"--scenes {args.scenes} --loads {args.loads}`\n\n"
        "## Where a corotational or position-based FEM beats every spring network\n\n"
        "Beats: a smaller contact-point error than every spring network's at that load; the "
        "budget: time per update within the period (33.3 ms at 30 Hz, 1 ms at 1 kHz).\n\n"
        + "\n".join(verdicts) + "\n\n" + "\n".join(sections))
    with open(args.out, "w") as f:
        f.write(page)
    print(page)


if __name__ == "__main__":
    main()
