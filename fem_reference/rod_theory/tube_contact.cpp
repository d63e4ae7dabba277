#include "fem_reference/rod_theory/tube_contact.hpp"

#include <Eigen/Dense>
#include <boost/math/special_functions/ellint_1.hpp>
#include <boost/math/special_functions/ellint_2.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fem_reference/rod_theory/elastica.hpp"

namespace vessel::rod_theory {

StraightTubeContact straight_tube_contact(double theta_in, double offset_over_z) {
  const double c = offset_over_z;
  // Unknowns u = (m0, L, F); the wall pushes the tip by (0, −F).
  const auto residual = [&](const Eigen::Vector3d& u) {
    const auto y = integrate_planar({0.0, 0.0, theta_in, u[0]}, 0.0, -u[2], u[1]);
    return Eigen::Vector3d(y[0] - 1.0, y[1] - c, y[3]);
  };
  Eigen::Vector3d u(0.0, 1.0, 3.0 * (theta_in - c));  // small-deflection start
  u[0] = -u[2];
  for (int it = 0; it < 50; ++it) {
    const Eigen::Vector3d r = residual(u);
    if (r.norm() < 1e-13) break;
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d up = u, um = u;
      const double h = 1e-6 * std::max(1.0, std::abs(u[k]));
      up[k] += h;
      um[k] -= h;
      J.col(k) = (residual(up) - residual(um)) / (2 * h);
    }
    u -= J.partialPivLu().solve(r);
  }
  const Eigen::Vector3d r = residual(u);
  if (!(r.norm() < 1e-10)) {
    throw std::runtime_error("straight_tube_contact: no convergence, residual " +
                             std::to_string(r.norm()));
  }
  const auto y = integrate_planar({0.0, 0.0, theta_in, u[0]}, 0.0, -u[2], u[1]);
  return {u[2], u[1], y[2], u[0]};
}

double straight_tube_contact_distance(double theta_in, double offset, double length) {
  const auto miss = [&](double z) {
    return straight_tube_contact(theta_in, offset / z).length * z - length;
  };
  double z0 = 0.98 * length, z1 = 0.99 * length;
  double m0 = miss(z0), m1 = miss(z1);
  for (int it = 0; it < 50 && std::abs(m1) > 1e-15 * length; ++it) {
    const double z2 = z1 - m1 * (z1 - z0) / (m1 - m0);
    z0 = z1;
    m0 = m1;
    z1 = z2;
    m1 = miss(z1);
  }
  if (!(std::abs(m1) <= 1e-12 * length)) {
    throw std::runtime_error("straight_tube_contact_distance: no convergence, length missed by " +
                             std::to_string(m1));
  }
  return z1;
}

ArchApexContact arch_apex_contact(double outer_over_bend_radius) {
  using boost::math::ellint_1;
  using boost::math::ellint_2;
  const auto ratio = [&](double k) {
    return (2.0 * ellint_2(k) - ellint_1(k)) / (2.0 * k) - outer_over_bend_radius;
  };
  boost::math::tools::eps_tolerance<double> tol(52);
  std::uintmax_t iterations = 200;
  // The ratio falls from +∞ (k → 0) to −∞ (k → 1).
  const auto bracket = boost::math::tools::toms748_solve(ratio, 1e-6, 1.0 - 1e-12, tol, iterations);
  const double k = 0.5 * (bracket.first + bracket.second);
  return {k, 4.0 * k * k, ellint_1(k) / (2.0 * k)};
}

}  // namespace vessel::rod_theory
