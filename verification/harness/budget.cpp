#include "verification/harness/budget.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "reports/representative_load.hpp"

namespace vessel {

double budget_magnitude(const Scene& s, double max_abs_strain_unit) {
  return representative_load(s.load.magnitudes, max_abs_strain_unit,
                             s.budget.magnitude > 0.0 ? std::optional(s.budget.magnitude)
                                                      : std::nullopt);
}

std::pair<double, long> time_per_update(double solve_seconds, long steps, double dt,
                                        double period) {
  if (period <= 0.0) return {0.0, 0};
  if (steps <= 0 || dt <= 0.0) return {solve_seconds, 0};
  // One update advances the simulation by the period: ⌈period/dt⌉ steps (a relative 1e-9 keeps
  // 1 ms / 1e-5 s at 100 steps despite round-off), at least one.
  const long per_update = std::max(1L, static_cast<long>(std::ceil(period / dt * (1.0 - 1e-9))));
  return {solve_seconds / static_cast<double>(steps) * static_cast<double>(per_update), per_update};
}

}  // namespace vessel
