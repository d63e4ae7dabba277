#!/usr/bin/env bash
# The rod tables of docs/rods.md from the rows the rod tests print: every model and closed-form
# case at N = 16, 32, 64 with the observed orders ("ROD-TABLE model case e16 e32 e64 order16-32
# order32-64"), and the rigid-wall cases ("ROD-WALL ..."). Usage:
#   msm/rods/benchmarks/rod_table.sh [build-dir]      (default: build)
set -euo pipefail
build=${1:-build}
exe="$build/tests/rods/rods_tests"
if [[ ! -x $exe ]]; then
  echo "rod_table.sh: $exe not found: build the rods_tests target first" >&2
  exit 1
fi
status=0
out=$("$exe" --gtest_filter='*RodClosedForm*:Greenhill*:Xpbd.ClosedForms*:*RigidWall*' 2>&1) || status=$?
echo "| model | case | N = 16 | N = 32 | N = 64 | order 16→32 | order 32→64 |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
grep '^ROD-TABLE' <<<"$out" | awk '{printf "| %s | %s | %s | %s | %s | %s | %s |\n", $2, $3, $4, $5, $6, $7, $8}'
echo
grep '^ROD-WALL' <<<"$out" || true
if [[ $status -ne 0 ]]; then
  echo "rod_table.sh: rods_tests reported failures (exit $status):" >&2
  grep -E '^\[  FAILED  \]|Failure' <<<"$out" >&2 || true
  exit "$status"
fi
