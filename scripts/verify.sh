#!/usr/bin/env bash
# The main command: installs what is missing, builds in Release and runs the default verification
# of the shipped scenes, then writes the report.
#   1. the default vessels' mesh statistics;
#   2. `vesselverify run`: every model of every shipped scene (contact on the straight tube and
#      on the arch, Lamé pressure, gravity sag, the dynamic step contact, the region-of-interest
#      radii, the guidewire pushing the straight tube and the arch) against the FEM reference →
#      results.json, results.csv, summary.md, fields/; the straight tube's guidewire also presses
#      each model's wall and the FEM P2 wall in a wire–wall contact solve (coupling = "contact";
#      --quick at the wire's own EI alone);
#   3. `vesselverify validity` on the contact scenes and gravity: where the linear reference stops
#      being valid, and the seed models against the finite-strain reference up to 70 mN and 1 g
#      → validity.json;
#   4. `vesselverify stability`: predicted vs found critical time steps and the hard cases →
#      stability.json, stability.md;
#   5. `vesselverify recommend` on the two contact scenes at 30 Hz (visual) and 1 kHz (haptic):
#      the cheapest model meeting each scene's [budget] → recommend/<scene>/<rate>hz/;
#   6. `vesselverify insertion` (not in --quick): the straight scene's floppy guidewire pushed in
#      in steps against the finite-strain wall and each of the scene's models' walls →
#      insertion.json, insertion.md;
#   7. `vesselverify report` → report.md, report.html (self-contained) and figures/, with the
#      stability, recommendation, validity and insertion sections drawn from stability.json, each
#      recommend.json, validity.json and insertion.json.
#
# Usage: scripts/verify.sh [--quick | --full] [--retime] [output-dir]   (default: results/)
#   default  the scenes' own levels, loads and sweeps (contact up to 1 mN, where the linear
#            reference holds; seed 000's range is the validity study's, against the
#            finite-strain reference, to 70 mN); the stability table at levels 0-1 with a
#            2·10^5-step long run; level-0 recommendation candidates (times, from an
#            empty cache and cached: docs/measurements/verify_times.md)
#   --quick  models and the P2 reference on level 0 (the models' own mesh, so no estimate of
#            the reference's uncertainty), smallest and largest load, the validity study at 0.1,
#            1 and 10 mN, the quick stability study, recommendations against P2 on level 0
#            (docs/measurements/verify_times.md)
#   --full   the default plus the stability table at level 2, the 10^6-step long run, the
#            level-1 recommendation candidates and the validity study at the scenes' reference
#            level on the dense ladder (not measured: P2 level 1 costs ~10 s per Newton
#            iteration, so expect well over an hour on 2 cores)
#   --retime measure every model, recommendation candidate and stability item again instead of
#            reading the outcomes a run of the same executable on this machine kept in the cache
#            (VESSELVERIFY_CACHE_DIR, else ~/.cache/vesselverify: model-outcomes/, next to the FEM
#            references in fem-solutions/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode=()
full=false
retime=()
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) mode=(--quick); shift ;;
    --full) full=true; shift ;;
    --retime) retime=(--retime); shift ;;
    -*) echo "verify.sh: unknown option '$1' (expected --quick, --full or --retime)" >&2; exit 2 ;;
    *) break ;;
  esac
done
out="${1:-$root/results}"
build="$root/build"

"$root/scripts/build.sh" "$build"
vv="$build/verification/vesselverify"
mkdir -p "$out"
start=$SECONDS
phase_start=$SECONDS
phase() {  # prints the time the previous phase took, then the next one's name
  echo "== [$((SECONDS - start)) s, previous phase $((SECONDS - phase_start)) s] $1 =="
  phase_start=$SECONDS
}
for vessel in straight arch; do
  echo "== default $vessel vessel =="
  "$vv" mesh --vessel "$vessel" --level 0 --stats-json "$out/${vessel}_vessel_stats.json"
done
scenes="$root/verification/scenes"
phase "run: the shipped scenes"
# --quick judges the level-0 models against P2 on level 0 (their own mesh): the level-1
# references are most of a quick run's cost; the report then gives no reference uncertainty.
reference=()
if [ ${#mode[@]} -gt 0 ]; then reference=(--reference-level 0); fi
"$vv" run "${mode[@]}" "${reference[@]}" "${retime[@]}" --output-dir "$out" "$scenes/contact_straight.toml" \
  "$scenes/pressure_lame.toml" "$scenes/contact_arch.toml" "$scenes/gravity_sag.toml" \
  "$scenes/dynamic_contact.toml" "$scenes/contact_roi.toml" "$scenes/guidewire_straight.toml" \
  "$scenes/guidewire_arch.toml"
phase "validity: the linear reference's limit, the seed models at finite strain"
# P2 on level 0 and the ladder to 70 mN (--quick: 0.1, 1 and 10 mN; `vesselverify validity
# --full` for the scenes' reference level, the full ladder to 140 mN and every static model).
validity_options=()
if $full; then validity_options=(--full); elif [ ${#mode[@]} -gt 0 ]; then validity_options=(--quick); fi
"$vv" validity "${validity_options[@]}" --output-dir "$out" "$scenes/contact_straight.toml" \
  "$scenes/contact_arch.toml" "$scenes/gravity_sag.toml"
phase "stability"
# Default: the step table at levels 0-1 and every hard case, the long run at 2·10^5 steps (the
# 10^6 steps of --full take ~40 s more); --full adds level 2 to the table (~13 minutes).
if $full; then
  stability_options=()
elif [ ${#mode[@]} -eq 0 ]; then
  stability_options=(--max-level 1 --long-run-steps 200000)
else
  stability_options=(--max-level 1)
fi
"$vv" stability "${mode[@]}" "${retime[@]}" "${stability_options[@]}" --output-dir "$out"
recommendations=()
for scene in contact_straight contact_arch; do
  phase "recommend $scene at 30 and 1000 Hz"
  dir="$out/recommend/$scene"
  # Level-0 candidates and ROI radii 4 and 8 mm (~1 minute); --full adds the level-1 candidates
  # (5-10 minutes each). The candidates run once and are judged at both rates (their time per
  # update does not depend on the rate).
  candidates=(--quick)
  if $full; then candidates=(); fi
  "$vv" recommend "${candidates[@]}" "${reference[@]}" "${retime[@]}" --rate 30,1000 --output-dir "$dir" "$scenes/$scene.toml"
  recommendations+=(--recommend "$dir/30hz/recommend.json" --recommend "$dir/1000hz/recommend.json")
done
insertion=()
if [ ${#mode[@]} -eq 0 ]; then
  phase "insertion: the floppy wire pushed into the straight tube"
  # guidewire_straight's wire (EI 4e-7 N·m²) on its neo-Hookean wall and on each model's own,
  # pushed its last 0.5 mm in two steps (a longer insertion, or the stiffer wires: `vesselverify
  # insertion`, minutes a millimetre); not in --quick.
  "$vv" insertion "$scenes/guidewire_straight.toml" --ei 4e-7 --from 19.75e-3 --to 20.25e-3 \
    --steps 2 --models all --json "$out/insertion.json" > "$out/insertion.md"
  insertion=(--insertion "$out/insertion.json")
fi
phase "report"
"$vv" report "$out/results.json" --stability "$out/stability.json" "${recommendations[@]}" \
  --validity "$out/validity.json" "${insertion[@]}" --output-dir "$out"
# The guidewire scenes' figures: the wire's shape and each model's coupled force over the EI sweep.
/usr/bin/python3 "$root/scripts/guidewire_figures.py" "$out/results.json" "$out/figures"
phase "done"
echo "verification finished in $((SECONDS - start)) s; report: $out/report.html (and report.md)"
