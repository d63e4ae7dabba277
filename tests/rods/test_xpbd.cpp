// The XPBD Cosserat rod's steady state against Newton on the same energy (CordeRod without
// inextensibility): measured, not hidden. XPBD restarts its multipliers every step, so with a
// finite number of sweeps its statics depend on the sweep count and the step; rows printed as
// "XPBD h sweeps steps gap".
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "msm/rods/xpbd_rod.hpp"
#include "rod_cases.hpp"

namespace vessel::msm::rods::test {
namespace {

constexpr int kN = 16;

RodLayout cantilever() { return make_layout(uniform_rod(test_material(), kLength, kDiameter, kN)); }

VectorXd tip_force(int num_dofs, int tip) {
  VectorXd f = VectorXd::Zero(num_dofs);
  f[3 * tip + 1] = test_EI() / (kLength * kLength);  // α = 1
  return f;
}

Eigen::Vector3d newton_tip() {
  const CordeRod energy(cantilever(), 0.0, false);
  CordeStaticLoad load;
  load.force = tip_force(energy.num_dofs(), energy.layout().tip_node);
  const ConstrainedResult r = solve_corde_static(energy, load);
  return r.x.segment<3>(3 * energy.layout().tip_node);
}

double steady_gap(double h, int sweeps, const Eigen::Vector3d& newton) {
  XpbdOptions options;
  options.iterations = sweeps;
  options.damping = 0.05;
  XpbdRod rod(cantilever(), 0.0, options);
  const int steps = rod.relax(h, tip_force(rod.state().size(), rod.tip_node()), 1e-13, 6000);
  const double gap = (rod.state().segment<3>(3 * rod.tip_node()) - newton).norm() / kLength;
  std::printf("XPBD h %.0e sweeps %d: %d steps, |tip - Newton| = %.3e L\n", h, sweeps, steps, gap);
  return gap;
}

TEST(Xpbd, StaticsDependOnTheSweepCount) {
  const Eigen::Vector3d newton = newton_tip();
  const double two = steady_gap(1e-2, 2, newton);
  const double eight = steady_gap(1e-2, 8, newton);
  // The target (independent of the sweeps, within 1e-6 L of Newton) is not met: the
  // steady state is far softer than the energy's equilibrium (0.91 L and 0.57 L off at h = 10 ms).
  EXPECT_GT(two, eight);
  EXPECT_GT(eight, 1e-6);
  EXPECT_TRUE(std::isfinite(two));
}

}  // namespace
}  // namespace vessel::msm::rods::test
