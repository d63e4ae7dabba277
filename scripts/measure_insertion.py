#!/usr/bin/python3
"""A guidewire scene's insertion (`vesselverify insertion`) into docs/measurements/insertion_SCENE.md,
with its figure (the forces against the insertion length) beside it as insertion_SCENE.svg.

Runs `vesselverify insertion verification/scenes/SCENE.toml --threads 1 [flags]` and writes the page
with the machine, the command, its time and the load average before and after: figures from a
loaded machine are upper bounds on time.

With --outputs DIR the run is not made here: its stdout, figure and metadata are read from
DIR/SCENE.md, DIR/SCENE.svg and DIR/SCENE.meta (a "command ..." line, then "load before L start T"
and "exit C load after L end T" lines, T in seconds since the epoch), as written by a run by hand.

Usage: /usr/bin/python3 scripts/measure_insertion.py [--program build/verification/vesselverify]
       [--scene guidewire_arch] [--page STEM] [--outputs DIR] [-- further vesselverify insertion
       flags]
--page names the page and its figure (STEM.md, STEM.svg; default insertion_SCENE), for a second
insertion of one scene (another EI).
Example (the arch from the wire's first contact to the apex, ~2 h on one core):
  /usr/bin/python3 scripts/measure_insertion.py --scene guidewire_arch -- --ei 4e-7 \\
      --from 10e-3 --to 24.633e-3 --steps 59"""
import argparse
import datetime
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from measurement_host import load_average, machine

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_DIR = os.path.join(ROOT, "docs/measurements")


def shown(text, program):
    """The command's own lines with the program and the checkout's paths as a user types them."""
    return text.replace(program, "vesselverify").replace(ROOT + "/", "")


def run_here(args, svg):
    scene = os.path.join(ROOT, "verification/scenes", args.scene + ".toml")
    threads = [] if any(a.startswith("--threads") for a in args.extra) else ["--threads", "1"]
    cmd = [args.program, "insertion", scene] + threads + args.extra + ["--svg", svg]
    before, t0 = load_average(), time.monotonic()
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    seconds = time.monotonic() - t0
    if proc.returncode != 0:
        sys.exit(f"measure_insertion.py: `{' '.join(cmd)}` exited {proc.returncode}:\n"
                 f"{proc.stderr}")
    # The figure's temporary folder is no part of what a reader would type.
    here = os.path.dirname(svg) + "/"
    head = (f"`{shown(' '.join(cmd), args.program).replace(here, '')}`: {seconds:.0f} s, load "
            f"average {before} before, {load_average()} after.")
    return head, shown(proc.stdout, args.program).replace(here, "")


def saved_run(args, svg):
    folder = args.outputs
    with open(os.path.join(folder, args.scene + ".md")) as f:
        stdout = f.read()
    with open(os.path.join(folder, args.scene + ".meta")) as f:
        meta = f.read()
    shutil.copyfile(os.path.join(folder, args.scene + ".svg"), svg)
    found = {key: re.search(pattern, meta, re.M) for key, pattern in (
        ("command", r"^command (.+)$"), ("before", r"load before (\S+)"),
        ("after", r"load after (\S+)"), ("start", r"start (\S+)"), ("end", r"end (\S+)"),
        ("exit", r"exit (\S+)"))}
    value = {k: (m.group(1) if m else None) for k, m in found.items()}
    if value["exit"] != "0":
        sys.exit(f"measure_insertion.py: {folder}/{args.scene}.meta has no `exit 0`: the run did "
                 "not finish")
    seconds = float(value["end"]) - float(value["start"])
    head = (f"`{value['command'] or 'vesselverify insertion'}`: {seconds:.0f} s (a run by hand, "
            f"beside other work), load average {value['before'] or 'not recorded'} before, "
            f"{value['after'] or 'not recorded'} after.")
    # The run's own figure path is no part of what a reader would type either.
    return head, shown(stdout, args.program).replace(os.path.abspath(folder) + "/", "")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--program", default=os.path.join(ROOT, "build/verification/vesselverify"))
    ap.add_argument("--scene", default="guidewire_arch")
    ap.add_argument("--page", help="the page's and the figure's name without the extension "
                    "(default insertion_SCENE)")
    ap.add_argument("--outputs", help="read the run's outputs from this folder instead of running")
    ap.add_argument("extra", nargs="*", help="further `vesselverify insertion` flags (after --)")
    args = ap.parse_args()
    if not args.outputs and not os.path.exists(args.program):
        sys.exit(f"measure_insertion.py: no program at {args.program} (build vesselverify)")
    stem = args.page or f"insertion_{args.scene}"
    page = os.path.join(OUT_DIR, stem + ".md")
    figure = stem + ".svg"
    with tempfile.TemporaryDirectory() as tmp:
        svg = os.path.join(tmp, figure)
        head, stdout = (saved_run if args.outputs else run_here)(args, svg)
        # The command's own "document:" and "figure:" lines name files of the run, not the page's.
        stdout = re.sub(r"^(document|figure): .*\n?", "", stdout, flags=re.M).rstrip() + "\n"
        ei = re.search(r"--ei (\S+)", head)
        text = "\n".join([
            f"# The guidewire pushed into {args.scene}"
            + (f" at EI {ei.group(1)} N·m²" if ei else ""),
            "",
            "Generated by `scripts/measure_insertion.py` on "
            f"{datetime.date.today().isoformat()} ({machine()}); do not edit by hand. What is "
            "computed: [the contact page](../physics/contact.md#the-insertion-vesselverify-insertion-verificationharnesscontact_insertionhpp).",
            "",
            head,
            "",
            f"![The contact force and the hub's forces against the insertion length]({figure})",
            "",
            stdout.replace("## The guidewire pushed in\n", "").replace("### ", "## ").strip(),
            "",
        ])
        shutil.copyfile(svg, os.path.join(OUT_DIR, figure))
    with open(page + ".tmp", "w") as f:
        f.write(text)
    os.replace(page + ".tmp", page)
    print(f"wrote {page} and {os.path.join(OUT_DIR, figure)}")


if __name__ == "__main__":
    main()
