#!/usr/bin/env bash
# ctest slurm_reference_job: scripts/slurm_reference_job.sbatch submitted to a one-node Slurm
# cluster on this machine (scripts/slurm_localhost.sh) on 2 tasks: the reference job must solve
# the short tube's 4 references on 2 ranks and the serial run must then read all 4 from the cache.
# Usage: slurm_reference_job_test.sh VESSELVERIFY SOURCE_DIR
set -euo pipefail
vv=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work" || true' EXIT
export VESSELVERIFY="$vv" OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$src/scripts/slurm_localhost.sh" "$work/slurm" --nodes=1 --ntasks-per-node=2 \
  "$src/scripts/slurm_reference_job.sbatch" "$work/cache" "$work/out" \
  "$src/tests/fixtures/short_contact.toml" > "$work/log" 2>&1 || {
  cat "$work/log"
  echo "FAILED: the batch job failed"
  exit 1
}
fail=0
expect() {
  grep -qF "$1" "$work/log" || { echo "FAILED: the job's log lacks: $1"; fail=1; }
}
expect "reference job on 2 MPI rank(s)"
expect "references: 4 solved and stored, 0 already in the cache"
expect ": 4 hits, 0 misses"
[ -s "$work/out/results.json" ] || { echo "FAILED: no results.json"; fail=1; }
grep -v -E "^(slurmctld|slurmd|munged):" "$work/log"
exit "$fail"
