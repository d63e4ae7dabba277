#include "fem_reference/convergence.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace vessel::fem {

double observed_order(double e_coarse, double e_fine, double ratio) {
  if (!(e_coarse > 0.0) || !(e_fine > 0.0) || !(ratio > 1.0)) {
    throw std::invalid_argument("observed_order: errors must be > 0 and the ratio > 1");
  }
  return std::log(e_coarse / e_fine) / std::log(ratio);
}

double observed_order_three(double f3, double f2, double f1, double ratio) {
  const double d32 = f3 - f2;
  const double d21 = f2 - f1;
  if (d32 == 0.0 || d21 == 0.0 || (d32 > 0.0) != (d21 > 0.0)) {
    throw std::domain_error("observed_order_three: differences are zero or change sign");
  }
  // Roache (1998) eq. 5.10.6.1 for a constant refinement ratio.
  return std::log(d32 / d21) / std::log(ratio);
}

RichardsonEstimate richardson(double f2, double f1, double p, double r, double fs) {
  if (!(r > 1.0) || !(p > 0.0))
    throw std::invalid_argument("richardson: need ratio > 1, order > 0");
  const double rp1 = std::pow(r, p) - 1.0;
  RichardsonEstimate e;
  e.extrapolated = f1 + (f1 - f2) / rp1;  // Richardson extrapolation
  e.error_fine = std::abs(e.extrapolated - f1);
  // Roache's GCI for the fine grid: Fs |ε| / (r^p − 1), ε = (f2 − f1)/f1.
  e.gci_fine = f1 != 0.0 ? fs * std::abs((f2 - f1) / f1) / rp1 : 0.0;
  return e;
}

GciOrder gci_order(const std::optional<std::vector<double>>& three, double assumed, double ratio,
                   double min_order, double max_order) {
  if (!(min_order > 0.0) || !(min_order <= assumed) || !(assumed <= max_order)) {
    throw std::invalid_argument("gci_order: need 0 < min_order <= assumed <= max_order");
  }
  GciOrder g;
  g.order = assumed;
  g.source = "assumed";
  g.safety_factor = 3.0;
  std::ostringstream note;
  if (!three) {
    note << "assumed order " << assumed << " (fewer than three levels)";
    g.note = note.str();
    return g;
  }
  if (three->size() != 3) throw std::invalid_argument("gci_order: expected three values");
  try {
    const double p = observed_order_three((*three)[0], (*three)[1], (*three)[2], ratio);
    g.order = std::clamp(p, min_order, max_order);
    g.source = "observed";
    g.safety_factor = 1.25;
    note << "observed order " << p << " from three levels";
    if (g.order != p) note << ", clamped to " << g.order;
  } catch (const std::domain_error&) {
    note << "assumed order " << assumed << " (the three levels converge oscillatorily)";
  }
  g.note = note.str();
  return g;
}

FieldUncertainty richardson_field(const std::vector<Vec3>& medium, const std::vector<Vec3>& fine,
                                  double order, double ratio) {
  if (medium.size() != fine.size()) {
    throw std::invalid_argument("richardson_field: the two levels have different point counts");
  }
  if (!(ratio > 1.0) || !(order > 0.0)) {
    throw std::invalid_argument("richardson_field: need ratio > 1, order > 0");
  }
  const double rp1 = std::pow(ratio, order) - 1.0;
  FieldUncertainty u;
  double e2 = 0.0, f2 = 0.0;
  for (std::size_t i = 0; i < fine.size(); ++i) {
    const double e = (fine[i] - medium[i]).norm() / rp1;  // |u_ext − u_fine|, Richardson
    u.error_fine.push_back(e);
    u.max_error = std::max(u.max_error, e);
    e2 += e * e;
    f2 += fine[i].squaredNorm();
  }
  if (!fine.empty()) u.rms_error = std::sqrt(e2 / static_cast<double>(fine.size()));
  u.relative_l2 = f2 > 0.0 ? std::sqrt(e2 / f2) : 0.0;
  return u;
}

}  // namespace vessel::fem
