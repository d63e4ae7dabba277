#!/usr/bin/python3
"""ctest cache.user_cache_untouched: the suite never writes the user's cache.

Every ctest entry that is not a GoogleTest case (those set the variable in tests/test_main.cpp)
must carry VESSELVERIFY_CACHE_DIR in its ENVIRONMENT (set for all of them at the end of
tests/CMakeLists.txt); and `vesselverify mesh`, run with the environment ctest gives those entries
under a HOME that is an empty folder (no XDG_CACHE_HOME, no VESSELVERIFY_CACHE_DIR of the caller),
must create no .cache/vesselverify in it.

Usage: check_user_cache_untouched.py CTEST BUILD_DIR VESSELVERIFY"""
import json
import os
import subprocess
import sys
import tempfile


def environment_of(test):
    for p in test.get("properties", []):
        if p["name"] == "ENVIRONMENT":
            return dict(e.split("=", 1) for e in p["value"])
    return {}


def main():
    ctest, build, vesselverify = sys.argv[1:4]
    listing = subprocess.run([ctest, "--test-dir", build, "--show-only=json-v1"],
                             capture_output=True, text=True, check=True)
    tests = json.loads(listing.stdout)["tests"]
    # GoogleTest cases carry --gtest_filter; *_NOT_BUILT are ctest's stand-ins for unbuilt programs.
    scripts = [t for t in tests if not t["name"].endswith("_NOT_BUILT")
               and not any(a.startswith("--gtest_filter") for a in t.get("command", []))]
    failures = [f"ctest entry {t['name']}: no VESSELVERIFY_CACHE_DIR in its ENVIRONMENT"
                for t in scripts if "VESSELVERIFY_CACHE_DIR" not in environment_of(t)]
    if not scripts:
        failures.append("ctest lists no entry that is not a GoogleTest case")

    me = next((t for t in tests if t["name"] == "cache.user_cache_untouched"), None)
    given = environment_of(me) if me else {}
    with tempfile.TemporaryDirectory() as home:
        env = {k: v for k, v in os.environ.items()
               if k not in ("VESSELVERIFY_CACHE_DIR", "XDG_CACHE_HOME")}
        env["HOME"] = home
        env.update(given)
        with tempfile.TemporaryDirectory() as cwd:
            r = subprocess.run([vesselverify, "mesh"], cwd=cwd, env=env, capture_output=True,
                               text=True)
        if r.returncode != 0:
            failures.append(f"vesselverify mesh failed ({r.returncode}): {r.stderr.strip()}")
        # Only the cache is judged: gmsh's FLTK writes its own ~/.fltk preferences.
        user_cache = os.path.join(home, ".cache", "vesselverify")
        left = sorted(os.path.relpath(os.path.join(d, f), home)
                      for d, _, fs in os.walk(user_cache) for f in fs)
        if os.path.exists(user_cache):
            failures.append(f"vesselverify mesh under the tests' environment wrote into HOME: "
                            f"{', '.join(left[:5]) or user_cache}")
    for f in failures:
        print("FAILED:", f)
    print(f"{len(scripts)} script entries checked; HOME left "
          f"{'untouched' if not any('HOME' in f for f in failures) else 'written'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
