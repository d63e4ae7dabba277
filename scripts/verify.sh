#!/usr/bin/env bash
# The main command: installs what is missing, builds in Release and runs the default verification,
# writing its results under the output directory.
# Usage: scripts/verify.sh [output-dir]   (default: results)
#
# At this stage of the project the default verification meshes the two default vessels (straight
# tube and 180° arch, level 0), checks them against their closed-form volumes and areas and writes
# the meshes (.msh, .vtu) and their statistics (JSON).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/results}"
build="$root/build"

"$root/scripts/build.sh" "$build"
vv="$build/verification/vesselverify"
mkdir -p "$out"
for vessel in straight arch; do
  echo "== default $vessel vessel =="
  "$vv" mesh --vessel "$vessel" --level 0 \
    -o "$out/${vessel}_vessel.msh" --vtu "$out/${vessel}_vessel.vtu" \
    --stats-json "$out/${vessel}_vessel_stats.json"
done
echo "results written to $out"
