#pragma once
/// The reference checked against a closed form and against itself: the relative L2 error of a
/// solve against Lamé's thick-walled cylinder, and the Richardson estimate of a displacement at
/// one point from the same problem solved one level coarser. Free of deal.II. SI units.
#include "fem_reference/convergence.hpp"
#include "fem_reference/elasticity.hpp"
#include "fem_reference/lame.hpp"

namespace vessel::fem {

/// Relative L2 error ‖u_h − u_Lamé‖ / ‖u_Lamé‖ of a solved straight-tube problem (roller ends,
/// internal pressure alone: plane strain, where Lamé's solution is exact).
double lame_relative_l2_error(const ElasticitySolver& solved, const LameCylinder& lame);

/// The displacement along `direction` at `point` on two levels and its Richardson estimate.
struct PointRichardson {
  double u_coarse = 0.0;  ///< m
  double u_fine = 0.0;    ///< m
  double order = 2.0;     ///< assumed, not observed (two levels)
  RichardsonEstimate estimate;
};

/// Richardson extrapolation (refinement ratio 2, assumed order `order`, Roache's safety factor 3
/// for an assumed order) of u·direction at `point` from two solved problems, the second one level
/// finer. The point may lie on a curved wall: the chord's sagitta is allowed for (barycentric
/// tolerance 0.25).
PointRichardson richardson_at_point(const ElasticitySolver& coarse, const ElasticitySolver& fine,
                                    const Vec3& point, const Vec3& direction, double order);

}  // namespace vessel::fem
