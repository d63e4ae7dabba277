#include "reports/representative_load.hpp"

#include <algorithm>
#include <cmath>

namespace vessel {

double representative_load(const std::vector<double>& magnitudes,
                           double max_abs_strain_at_unit_load,
                           std::optional<double> budget_magnitude) {
  if (budget_magnitude) return *budget_magnitude;
  double best = -1.0;
  double smallest = HUGE_VAL;
  for (const double m : magnitudes) {
    smallest = std::min(smallest, m);
    if (max_abs_strain_at_unit_load * m <= kLinearRegimeStrain) best = std::max(best, m);
  }
  return best > 0.0 ? best : smallest;
}

}  // namespace vessel
