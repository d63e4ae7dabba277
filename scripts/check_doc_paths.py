#!/usr/bin/env python3
"""Every file or folder of the repository that the README and docs/ name in backticks exists.

Usage: scripts/check_doc_paths.py   exit 1 listing each page and the paths it names that are gone
The ctest docs_paths runs it, so moving a file without updating the prose that points at it
fails the suite. The dated logs in docs/measurements/ are left out: they describe the code as it
was when they were measured.
"""
import glob
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PATH = re.compile(r"`([A-Za-z_][\w.-]*/[\w/.-]*)`")


def top_folders():
    outputs = {"results", "gate-results"}  # written by runs: the docs name their files as examples
    return {d for d in os.listdir(ROOT) if os.path.isdir(os.path.join(ROOT, d))
            and not d.startswith((".", "build")) and d not in outputs}


def pages():
    found = [os.path.join(ROOT, "README.md")]
    found += glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True)
    return sorted(p for p in found if os.sep + "measurements" + os.sep not in p)


def main():
    tops = top_folders()
    missing = {}
    for page in pages():
        text = open(page, encoding="utf-8").read()
        for m in PATH.finditer(text):
            path = m.group(1).rstrip("/.")
            if path.split("/")[0] not in tops:
                continue  # not a path of this repository (e.g. a URL part or an output folder)
            if not os.path.exists(os.path.join(ROOT, path)):
                missing.setdefault(os.path.relpath(page, ROOT), set()).add(path)
    for page, paths in sorted(missing.items()):
        print(f"{page}: names {', '.join(sorted(paths))}, which do not exist", file=sys.stderr)
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
