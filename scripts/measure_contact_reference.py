#!/usr/bin/python3
"""The guidewire scenes' contact reference (`vesselverify contact`) at every EI of their sweep,
beside the patch-based coupling's forces, into docs/measurements/contact_reference.md.

Runs `vesselverify contact SCENE` (its defaults: three levels, the scene's stiffness_sweep) on
guidewire_straight.toml and guidewire_arch.toml side by side, and
writes the page with the machine and the load average before and after each run: figures from a
loaded machine are upper bounds on time.

With --outputs DIR the runs are not made here: each scene's output is read from DIR/SCENE.md (the
command's stdout) and DIR/SCENE.meta (its command line, "load before L start T" and "exit C load
after L end T" lines), as written by a run by hand; runs made one after the other (say one per
stiffness) append to both files, a "command" line each; a stiffness of the scene's sweep missing
from an output is listed as not measured.

The finite-strain wall's page: --out docs/measurements/contact_reference_neo_hookean.md -- --wall
neo-hookean (the page then describes that wall).

Usage: /usr/bin/python3 scripts/measure_contact_reference.py [--program build/verification/vesselverify]
       [--scenes guidewire_straight,guidewire_arch] [--out PAGE] [--outputs DIR]
       [-- extra vesselverify contact flags]"""
import argparse
import datetime
import os
import re
import subprocess
import sys
import time
from measurement_host import load_average, machine

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The patch-based series-spring coupling's reference force on guidewire_straight (level 0, P2,
# ν = 0.45) at patch radius 1, 0.5 and 0.25 mm, measured with `vesselverify run` changing only
# load.patch_radius (issue 40's table): mN per EI.
PATCH_FORCES = {
    "guidewire_straight": {
        4e-7: (0.4406, 0.4377, 0.4354),
        4e-6: (2.786, 2.675, 2.588),
        4e-5: (5.859, 5.381, 5.037),
    },
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--program", default=os.path.join(ROOT, "build/verification/vesselverify"))
    ap.add_argument("--scenes", default="guidewire_straight,guidewire_arch")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/measurements/contact_reference.md"))
    ap.add_argument("--outputs", help="read the runs' outputs from this folder instead of running")
    ap.add_argument("extra", nargs="*", help="further `vesselverify contact` flags (after --)")
    args = ap.parse_args()
    if not os.path.exists(args.program):
        sys.exit(f"measure_contact_reference.py: no program at {args.program} (build vesselverify)")
    if args.outputs:
        sections = [saved_section(args.outputs, scene) for scene in args.scenes.split(",")]
        write_page(args, sections)
        return
    runs = []
    for scene in args.scenes.split(","):
        path = os.path.join("verification/scenes", scene + ".toml")
        # the scenes run side by side: one core each unless the extra flags say otherwise
        threads = [] if any(a.startswith("--threads") for a in args.extra) else ["--threads", "1"]
        cmd = [args.program, "contact", path] + threads + args.extra
        runs.append((scene, cmd, load_average(), time.monotonic(),
                     subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True)))
    sections = []
    for scene, cmd, before, t0, proc in runs:  # the scenes run side by side
        stdout, stderr = proc.communicate()
        seconds = time.monotonic() - t0
        if proc.returncode != 0:
            sys.exit(f"measure_contact_reference.py: `{' '.join(cmd)}` exited {proc.returncode}:\n"
                     f"{stderr}")
        shown = "vesselverify " + " ".join(cmd[1:])
        sections.append(f"## {scene}\n\n`{shown}`: {seconds:.0f} s (the scenes side by side), load "
                        f"average {before} before, {load_average()} after.\n\n" +
                        stdout.replace("### ", "#### "))
    write_page(args, sections)


def saved_section(folder, scene):
    """A scene's section from a run made by hand (its stdout and its .meta lines)."""
    with open(os.path.join(folder, scene + ".md")) as f:
        stdout = f.read()
    meta = {}
    with open(os.path.join(folder, scene + ".meta")) as f:
        text = f.read()
    for key, pattern in (("before", r"load before (\S+)"), ("after", r"load after (\S+)"),
                         ("exit", r"exit (\S+)")):
        found = re.findall(pattern, text, re.M)
        if found:  # several runs (one per stiffness): the first load before, the last after and exit
            meta[key] = found[0] if key == "before" else found[-1]
    # Runs made one after the other, maybe days apart: the time is the sum of each run's own.
    starts = [float(t) for t in re.findall(r"start (\S+)", text)]
    ends = [float(t) for t in re.findall(r"end (\S+)", text)]
    seconds = sum(end - start for start, end in zip(starts, ends))
    commands = re.findall(r"^command (.+)$", text, re.M) or ["vesselverify contact"]
    head = f"## {scene}\n\n" + ", then ".join(f"`{c}`" for c in commands)
    finished = meta.get("exit") == "0" and len(ends) == len(starts)
    if finished:
        head += (f": {seconds:.0f} s in all (the runs side by side with others), "
                 f"load average {meta['before']} before, {meta['after']} after.")
    else:
        ran = f" after {seconds:.0f} s" if ends else ""
        head += (f": stopped before it finished{ran} (the scenes side by side, load average "
                 f"{meta.get('before', '?')} at the start); the stiffnesses it did not reach are "
                 "not measured.")
    sweep = []
    with open(os.path.join(ROOT, "verification/scenes", scene + ".toml")) as f:
        for line in f:
            if line.startswith("stiffness_sweep"):
                sweep = [float(v) for v in line.split("[")[1].split("]")[0].split(",")]
    missing = [ei for ei in sweep if f"EI = {ei:g} N" not in stdout]
    tail = "".join(f"\n#### {scene}, EI = {ei:g} N·m²\n\nNot finished (the run was stopped at or "
                   "before this stiffness; its progress, if any, is in the lines below).\n"
                   for ei in missing)
    log = os.path.join(folder, scene + ".log")
    if not finished and os.path.exists(log):
        with open(log) as f:
            progress = f.read().strip()
        tail += ("\nThe stopped run's progress lines (stderr), one per solve; the first solve of "
                 "each stiffness is the scout:\n\n```\n" + progress + "\n```\n")
    return head + "\n\n" + stdout.replace("### ", "#### ") + tail


def wall_description(args, sections):
    """What the page's rows are: the linear wall's (the default) or the neo-Hookean wall's."""
    neo = "neo-hookean" in " ".join(args.extra) or any("--wall neo-hookean" in s for s in sections)
    common = ("Each scene's wire (DER at the scene's segments, E scaled to each EI) and its wall "
              "({wall}, the scene's E, ν and supports) solved together, the contact between the "
              "wire's surface and the wall's found by the solve ({how}, "
              "[contact.md](../physics/contact.md)), the wall's mesh refined level by level around "
              "the contact zone (`vesselverify contact`, verification/harness/contact_reference.hpp). "
              "F is the wire's net force on the wall, |Σ λ_j n_j|. ")
    if neo:
        return (common.format(wall="compressible neo-Hookean FEM at finite strain",
                              how="the wire and the wall as one potential, frictionless contact by "
                                  "an augmented Lagrangian") +
                "A row is a reference if every level converged, the zone stayed inside the "
                "refined patch and no level's dent is wider than the lumen (then the wall does not "
                "hold the wire, and the verdict says so); its uncertainty is the GCI. The largest "
                "strain is Green–Lagrange's. "
                "The wall is P1 unless the command says `--degree 2`, and the GCI is the contact "
                "zone's mesh at that degree: at ν = 0.45 linear tets are stiffer than the "
                "continuum at every size, an error the levels do not see (the P1 and P2 forces "
                "side by side are in [contact.md](../physics/contact.md)).")
    return (common.format(wall="linear FEM", how="Signorini's conditions") +
            "A row is a reference only if every level converged and the wall's largest strain "
            "stays within the linear wall's validity (0.1); otherwise its verdict says why, and its "
            "numbers are those of a linear wall beyond its range, not a reference.")


def write_page(args, sections):
    lines = [
        "# The guidewire scenes' contact reference",
        "",
        "Generated by `scripts/measure_contact_reference.py` on "
        f"{datetime.date.today().isoformat()} ({machine()}); do not edit by hand.",
        "",
        wall_description(args, sections),
        "",
        "## The patch-based coupling's forces (for comparison)",
        "",
        "The series-spring coupling with the wall's compliance read under a disc patch, "
        "guidewire_straight, level 0, P2, ν = 0.45 (measured with `vesselverify run`, changing only "
        "`load.patch_radius`; not regenerated by this script):",
        "",
        "| EI N·m² | patch 1 mm | 0.5 mm | 0.25 mm |",
        "| --- | --- | --- | --- |",
    ]
    for ei, forces in PATCH_FORCES["guidewire_straight"].items():
        lines.append(f"| {ei:g} | " + " | ".join(f"{f} mN" for f in forces) + " |")
    lines.append("")
    page = "\n".join(lines) + "\n" + "\n".join(sections)
    tmp = args.out + ".tmp"
    with open(tmp, "w") as f:
        f.write(page)
    os.replace(tmp, args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
