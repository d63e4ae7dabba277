#include "fem_reference/reference_checks.hpp"

namespace vessel::fem {

double lame_relative_l2_error(const ElasticitySolver& solved, const LameCylinder& lame) {
  return solved.relative_l2_error([&](const Vec3& x) { return lame.displacement(x); });
}

PointRichardson richardson_at_point(const ElasticitySolver& coarse, const ElasticitySolver& fine,
                                    const Vec3& point, const Vec3& direction, double order) {
  // A point on the exact inner cylinder lies outside the straight-sided tets by up to ℓ²/(8r).
  constexpr double kOutsideTolerance = 0.25;
  PointRichardson r;
  r.order = order;
  r.u_fine = fine.displacement_at({point}, kOutsideTolerance)[0].dot(direction);
  r.u_coarse = coarse.displacement_at({point}, kOutsideTolerance)[0].dot(direction);
  r.estimate = richardson(r.u_coarse, r.u_fine, order, 2.0, 3.0);  // assumed order: Fs = 3
  return r;
}

}  // namespace vessel::fem
