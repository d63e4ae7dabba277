#pragma once
/// The spring kernels' one threading scaffold (FastSprings, NodeSprings): the work is cut into
/// `parts` parts, one per thread of an OpenMP team, and their energies summed in part order (so
/// the sum does not depend on which thread ran which part). Include it only from a file compiled
/// with OpenMP (msm/CMakeLists.txt).
#include <omp.h>

#include <atomic>
#include <cstddef>
#include <vector>

namespace vessel::msm {

/// Σ_t part(t) for t = 0 … parts − 1, the parts run by a team of `parts` threads; a smaller team
/// than asked (OMP_THREAD_LIMIT, nesting) still covers every part. `last_team` gets the team's
/// size.
template <class Part>
double sum_over_thread_parts(int parts, std::atomic<int>& last_team, const Part& part) {
  std::vector<double> partial(static_cast<std::size_t>(parts), 0.0);
  // set_solver_threads(1) sets max-active-levels to 0 on this thread so that CHOLMOD's regions run
  // serially; that would serialise this region too, so it is lifted here and restored after.
  const int saved_levels = omp_get_max_active_levels();
  if (saved_levels < 1) omp_set_max_active_levels(1);
#pragma omp parallel num_threads(parts)
  {
    const int team = omp_get_num_threads();
    if (omp_get_thread_num() == 0) last_team.store(team, std::memory_order_relaxed);
    for (int t = omp_get_thread_num(); t < parts; t += team) {
      partial[static_cast<std::size_t>(t)] = part(t);
    }
  }
  if (saved_levels < 1) omp_set_max_active_levels(saved_levels);
  double e = 0.0;
  for (double p : partial) e += p;
  return e;
}

}  // namespace vessel::msm
