#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UBSan) under build-fuzz/ and runs
# each for a while on its corpus (tests/fuzz/corpus/<target>, never modified: new inputs go to a
# temporary directory). Exits non-zero on the first crash, leak or sanitizer report.
# Usage: scripts/fuzz.sh [seconds-per-target]   (default 30)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-30}"
build="$root/build-fuzz"

"$root/scripts/install_deps.sh" clang libclang-rt-14-dev libomp-dev  # libomp: clang's OpenMP (fast spring kernel)
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DVESSEL_FUZZ=ON
fi
cmake --build "$build" --parallel "$(nproc)" --target fuzz_msh fuzz_stl fuzz_scene
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for target in msh stl scene; do
  echo "== fuzz_$target for $seconds s =="
  mkdir -p "$work/$target"
  status=0
  "$build/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$work/$target-" -print_final_stats=1 \
    "$work/$target" "$root/tests/fuzz/corpus/$target" >"$work/$target.log" 2>&1 || status=$?
  tail -n 30 "$work/$target.log"
  if [ "$status" -ne 0 ] || ls "$work/$target-"* >/dev/null 2>&1; then
    mkdir -p "$root/build-fuzz/crashes"
    cp "$work/$target-"* "$root/build-fuzz/crashes/"
    echo "fuzz_$target found a failing input: see $root/build-fuzz/crashes/" >&2
    exit 1
  fi
done
echo "fuzzing finished: no crashes"
