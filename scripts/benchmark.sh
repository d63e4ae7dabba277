#!/usr/bin/env bash
# Runs the Google Benchmark programs (Release build), writes their JSON to docs/benchmarks/ and
# regenerates docs/performance.md from it (scripts/gen_performance_page.py). Run it on a quiet
# machine: the page records the load average at the start of each run.
# Usage: scripts/benchmark.sh [repetitions]   (default 5; medians of the repetitions are shown)
#        VESSEL_BUILD_JOBS=1 scripts/benchmark.sh   builds with one job (default: the core count)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build"
repetitions="${1:-5}"
# program target, path under build/
benchmarks=(
  "spring_kernel_benchmark msm/spring_kernel_benchmark"
  "msm_bench tests/msm/msm_bench"
  "updates_bench tests/msm/updates_bench"
)
"$root/scripts/install_deps.sh"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
for entry in "${benchmarks[@]}"; do
  read -r target path <<<"$entry"
  cmake --build "$build" --target "$target" --parallel "${VESSEL_BUILD_JOBS:-$(nproc)}"
  echo "== $target =="
  "$build/$path" --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
    --benchmark_out="$root/docs/benchmarks/$target.json" --benchmark_out_format=json
done
/usr/bin/python3 "$root/scripts/gen_performance_page.py"
