#include "fem_reference/convergence.hpp"

#include <cmath>
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

}  // namespace vessel::fem
