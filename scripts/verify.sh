#!/usr/bin/env bash
# The main command: installs what is missing, builds in Release and runs the default verification:
# the shipped static scenes (contact on the straight tube and on the arch, Lamé pressure, gravity
# sag) with every model against the FEM reference, and the default vessels' mesh statistics.
# Writes results.json (schema verification/results.schema.json), results.csv, summary.md and the
# meshes' statistics under the output directory.
#
# Usage: scripts/verify.sh [--full] [output-dir]   (default: results)
#   default  the --quick variant: models at level 0, reference at level 1 (0 for scenes with
#            ν ≥ 0.49), smallest and largest load; a few minutes on 2 cores
#   --full   the scenes' own levels and every load: much longer (Taylor–Hood references at level
#            ≥ 1 go to a direct solver and need many minutes and gigabytes)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode=(--quick)
if [ "${1:-}" = "--full" ]; then
  mode=()
  shift
fi
out="${1:-$root/results}"
build="$root/build"

"$root/scripts/build.sh" "$build"
vv="$build/verification/vesselverify"
mkdir -p "$out"
for vessel in straight arch; do
  echo "== default $vessel vessel =="
  "$vv" mesh --vessel "$vessel" --level 0 --stats-json "$out/${vessel}_vessel_stats.json"
done
scenes="$root/verification/scenes"
"$vv" run "${mode[@]}" --output-dir "$out" "$scenes/contact_straight.toml" \
  "$scenes/pressure_lame.toml" "$scenes/contact_arch.toml" "$scenes/gravity_sag.toml"
echo "results written to $out (summary: $out/summary.md)"
