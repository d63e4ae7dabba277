#include "fem_reference/lame.hpp"

#include <cmath>

namespace vessel::fem {

double LameCylinder::radial_displacement(double r) const {
  const double a = inner_radius;
  const double b = outer_radius;
  const double nu = poisson_ratio;
  // Timoshenko & Goodier §28, plane strain: u_r = p a²/(E(b²−a²)) ((1+ν)(1−2ν) r + (1+ν) b²/r).
  return pressure * a * a / (youngs_modulus * (b * b - a * a)) *
         ((1.0 + nu) * (1.0 - 2.0 * nu) * r + (1.0 + nu) * b * b / r);
}

Vec3 LameCylinder::displacement(const Vec3& x) const {
  const double r = std::hypot(x.x(), x.y());
  const double ur = radial_displacement(r);
  return {ur * x.x() / r, ur * x.y() / r, 0.0};
}

}  // namespace vessel::fem
