// Item 3: the wire against a rigid lumen (frictionless, one-sided), against the continuum
// references of fem_reference/rod_theory: the straight tube (shooting) and the arch apex
// (quarter-wave elastica), on every rod model (XPBD: its steady state with the wall's multipliers
// carried between steps). Rows printed as "ROD-WALL model case N F/F_ref-1 L/L_ref-1".
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "fem_reference/rod_theory/tube_contact.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rigid_wall.hpp"
#include "msm/rods/xpbd_rod.hpp"

namespace vessel::msm::rods::test {
namespace {

// A 0.356 mm (0.014") solid nitinol core in a 3 mm lumen.
const RodMaterial kNitinol{48e9, 48e9 / 2.66, 6450.0};
constexpr double kWire = 0.356e-3;
constexpr double kOffset = 3e-3 - 0.178e-3;  // lumen radius less the wire's

double wire_EI() { return solid_section(kNitinol, kWire).EI; }

struct WallRun {
  ContactSolution contact;
  Eigen::Vector3d tip;
  double length = 0.0;
};

enum class Model { der, corde, xpbd };
const char* name(Model m) { return m == Model::der ? "DER" : m == Model::corde ? "CORDE" : "XPBD"; }

/// The start state of `start_shape` (a state of the same model and N, of length start_length)
/// scaled about the clamp to length L: positions scaled, the other dofs (DER's twists, the
/// quaternions) kept; or `rest` if there is none.
VectorXd scaled_start(const VectorXd& rest, int nodes, const Eigen::Vector3d& origin, double length,
                      const VectorXd& start_shape, double start_length) {
  if (start_shape.size() == 0) return rest;
  VectorXd x = start_shape;
  for (int i = 0; i < nodes; ++i) {
    x.segment<3>(3 * i) =
        origin + (length / start_length) * (start_shape.segment<3>(3 * i) - origin);
  }
  return x;
}

// XPBD relaxes as a damped dynamic run: the wire's first period is ~1 ms.
constexpr double kXpbdStep = 1e-4, kXpbdDamping = 0.3;

/// XPBD's steady state inside the lumen (direct solver, warm-started multipliers).
ContactSolution xpbd_in_lumen(const RodLayout& layout, const VectorXd& start,
                              const RigidLumen& lumen) {
  XpbdOptions options;
  options.solver = XpbdSolver::direct;
  options.iterations = 2;
  options.damping = kXpbdDamping;
  XpbdRod rod(layout, 0.0, options);
  rod.set_state(start);
  const int tip = rod.tip_node();
  rod.set_wall(&lumen, 2, tip);
  rod.relax(kXpbdStep, VectorXd::Zero(start.size()), 1e-14, 200000);
  ContactSolution s;
  s.x = rod.state();
  const std::vector<double> f = rod.wall_forces();
  s.min_gap = std::numeric_limits<double>::infinity();
  for (int i = 2; i <= tip; ++i) {
    if (f[i] > 0.0) {
      s.nodes.push_back(i);
      s.forces.push_back(f[i]);
    }
    s.min_gap = std::min(s.min_gap, lumen.gap(s.x.segment<3>(3 * i), nullptr, nullptr));
  }
  return s;
}

/// The wire (model m) of length L from the clamp (origin, direction) inside `lumen`, started from
/// `start_shape` (see scaled_start) or from the straight rest state.
WallRun wire_in_lumen(Model m, double length, int segments, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& direction, const RigidLumen& lumen,
                      const VectorXd& start_shape = {}, double start_length = 0.0) {
  RodSpec spec = uniform_rod(kNitinol, length, kWire, segments);
  spec.origin = origin;
  spec.direction = direction;
  const RodLayout layout = make_layout(spec);
  ConstrainedOptions options;
  options.force_scale = wire_EI() / (length * length);
  WallRun run;
  const int tip = layout.tip_node;
  if (m == Model::der) {
    DerRod rod(layout);
    const VectorXd x =
        scaled_start(rod.rest_state(), rod.num_nodes(), origin, length, start_shape, start_length);
    rod.update_reference(x);
    run.contact = solve_wall_contact(rod, nullptr, rod.clamp_fixed(), x, lumen, 2, tip, options);
  } else if (m == Model::corde) {
    // KKT Newton takes full steps (the alignment penalty is stiff) and does not converge from
    // a far start in the arch: it starts from XPBD's steady state on the same layout (CORDE's
    // energy less inextensibility, a strain ~1e-6 away) and its contacts.
    const CordeRod rod(layout);
    const VectorXd x0 =
        scaled_start(rod.rest_state(), rod.num_nodes(), origin, length, start_shape, start_length);
    const ContactSolution start = xpbd_in_lumen(layout, x0, lumen);
    run.contact = solve_wall_contact(
        rod, &rod, rod.clamp_fixed(), start.x, lumen, 2, tip, options, 40,
        [&rod](VectorXd& y) { rod.normalise_quaternions(y); }, start.nodes);
  } else {
    const CordeRod rod(layout, 0.0, false);
    const VectorXd x =
        scaled_start(rod.rest_state(), rod.num_nodes(), origin, length, start_shape, start_length);
    run.contact = xpbd_in_lumen(layout, x, lumen);
  }
  run.tip = run.contact.x.segment<3>(3 * tip);
  run.length = length;
  return run;
}

double total_force(const ContactSolution& c) {
  double f = 0.0;
  for (double v : c.forces) f += v;
  return f;
}

/// Secant on the length so that target(run) = 0, each solve warm-started from the last.
template <class Target>
WallRun secant_length(Model m, double L0, double L1, int segments, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& direction, const RigidLumen& lumen, WallRun previous,
                      const Target& target) {
  WallRun a =
      wire_in_lumen(m, L0, segments, origin, direction, lumen, previous.contact.x, previous.length);
  WallRun b = wire_in_lumen(m, L1, segments, origin, direction, lumen, a.contact.x, a.length);
  for (int it = 0; it < 30 && std::abs(target(b)) > 1e-12; ++it) {
    const double L = b.length - target(b) * (b.length - a.length) / (target(b) - target(a));
    a = b;
    b = wire_in_lumen(m, L, segments, origin, direction, lumen, a.contact.x, a.length);
  }
  return b;
}

/// The relative errors each model reached against the continuum reference at N = 16, 32, 64
/// (force F/F_ref − 1 and length L/L_ref − 1, magnitudes), and the least observed order of the
/// force error between successive N (log2 of the ratio). Measured with this test's ROD-WALL rows.
struct Reached {
  std::array<double, 3> force, length;
  double force_order;
};

/// Straight tube: DER converges at order 2.0; CORDE and XPBD at 1.7 from 16 to 32, 1.2 from 32 to
/// 64. Their lengths reach 2e-5 or better at every N, not monotonically (XPBD's changes sign).
Reached straight_tube_reached(Model m) {
  switch (m) {
    case Model::der:
      return {{1.71e-3, 4.26e-4, 1.08e-4}, {2.06e-5, 4.18e-6, 6.98e-8}, 1.98};
    case Model::corde:
      return {{2.11e-3, 6.56e-4, 2.90e-4}, {2.30e-5, 6.40e-6, 2.24e-6}, 1.18};
    case Model::xpbd:
      return {{2.12e-3, 6.61e-4, 2.96e-4}, {1.91e-5, 2.57e-6, 1.59e-6}, 1.16};
  }
  return {};
}

/// Arch apex: DER at order 2.0 then 2.2; CORDE 1.8 then 1.4; XPBD 1.6 then 1.1. The lengths reach
/// 3e-4 or better, not monotonically (DER's stalls at 1.7e-5, XPBD's grows to 6.1e-5 at N = 64).
Reached arch_apex_reached(Model m) {
  switch (m) {
    case Model::der:
      return {{2.24e-3, 5.57e-4, 1.18e-4}, {1.63e-4, 1.74e-5, 1.61e-5}, 2.01};
    case Model::corde:
      return {{1.88e-3, 5.52e-4, 2.10e-4}, {2.65e-4, 6.88e-5, 1.83e-5}, 1.39};
    case Model::xpbd:
      return {{1.98e-3, 6.46e-4, 3.04e-4}, {1.86e-4, 1.02e-5, 6.07e-5}, 1.09};
  }
  return {};
}

/// Each N's force and length errors within 1.5 times what was reached (lengths floored at 1e-6:
/// below that the secant on the length and the solvers' tolerances decide the digits), and the
/// force error's order between successive N at least the reached one less 0.25.
void expect_reached(const Reached& r, const std::array<double, 3>& force,
                    const std::array<double, 3>& length, const char* what) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::abs(force[i]), 1.5 * r.force[i]) << what << " N = " << (16 << i);
    EXPECT_LE(std::abs(length[i]), std::max(1.5 * r.length[i], 1e-6))
        << what << " N = " << (16 << i);
  }
  for (int i = 0; i < 2; ++i) {
    const double order = std::log2(std::abs(force[i] / force[i + 1]));
    std::printf("ROD-WALL %s force order N = %d to %d: %.2f\n", what, 16 << i, 32 << i, order);
    EXPECT_GE(order, r.force_order - 0.25) << what << " N = " << (16 << i) << " to " << (32 << i);
  }
}

class RigidWall : public ::testing::TestWithParam<Model> {};

TEST_P(RigidWall, StraightTubeTipContactMatchesShooting) {
  const Model m = GetParam();
  const double z = 20e-3, theta = 0.3;
  const rod_theory::StraightTubeContact ref = rod_theory::straight_tube_contact(theta, kOffset / z);
  const StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), kOffset);
  const Eigen::Vector3d dir(std::cos(theta), std::sin(theta), 0.0);
  std::array<double, 3> force{}, length{};
  for (int i = 0; i < 3; ++i) {
    const int n = 16 << i;
    const WallRun start = wire_in_lumen(m, ref.length * z, n, Eigen::Vector3d::Zero(), dir, tube);
    const WallRun run =
        secant_length(m, ref.length * z, 1.001 * ref.length * z, n, Eigen::Vector3d::Zero(), dir,
                      tube, start, [&](const WallRun& r) { return r.tip.x() - z; });
    const double F = total_force(run.contact) * z * z / wire_EI();
    const double L = run.length / z;
    std::printf("ROD-WALL %s straight_tube %d F %.6f (ref %.6f, %+.2e) L %.6f (ref %.6f, %+.2e)\n",
                name(m), n, F, ref.force, F / ref.force - 1, L, ref.length, L / ref.length - 1);
    ASSERT_EQ(run.contact.nodes.size(), 1u);  // a tip contact only
    EXPECT_GE(run.contact.min_gap, -1e-12);
    force[i] = F / ref.force - 1;
    length[i] = L / ref.length - 1;
  }
  expect_reached(straight_tube_reached(m), force, length, name(m));
}

TEST_P(RigidWall, NoForceAtZeroGapAndNeverPulling) {
  const Model m = GetParam();
  const double theta = 0.3;
  const StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), kOffset);
  const Eigen::Vector3d dir(std::cos(theta), std::sin(theta), 0.0);
  const double touch = kOffset / std::sin(theta);  // the straight wire's tip on the wall
  const WallRun at = wire_in_lumen(m, touch * (1.0 - 1e-9), 32, Eigen::Vector3d::Zero(), dir, tube);
  EXPECT_TRUE(at.contact.nodes.empty());
  // Just beyond: a small force, the linear cantilever's 3EI·Δy/(L³ cos²θ), pushing (never pulling).
  const double L = touch * (1.0 + 1e-5);
  const WallRun beyond = wire_in_lumen(m, L, 32, Eigen::Vector3d::Zero(), dir, tube);
  ASSERT_EQ(beyond.contact.forces.size(), 1u);
  const double dy = L * std::sin(theta) - kOffset;
  const double linear = 3.0 * wire_EI() * dy / (std::pow(L, 3) * std::cos(theta) * std::cos(theta));
  EXPECT_GT(beyond.contact.forces[0], 0.0);
  EXPECT_NEAR(beyond.contact.forces[0] / linear, 1.0, 5e-3);  // the discretisation's 1/(2N²)
}

TEST_P(RigidWall, ArchApexQuarterWaveElastica) {
  const Model m = GetParam();
  const double R = 15e-3;
  const double Ro = R + kOffset;
  const rod_theory::ArchApexContact ref = rod_theory::arch_apex_contact(Ro / R);
  const TorusBend bend(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), R, kOffset);
  const Eigen::Vector3d clamp(R, 0.0, 0.0), dir = Eigen::Vector3d::UnitY();
  std::array<double, 3> force{}, length{};
  for (int i = 0; i < 3; ++i) {
    const int n = 16 << i;
    // Insert the wire in steps (each solve from the last shape), then find the length whose tip
    // bears at the apex (polar angle π/2).
    WallRun run = wire_in_lumen(m, 0.6 * R, n, clamp, dir, bend);
    for (double L = 0.7 * R; L < 1.5 * R; L += 0.1 * R) {
      run = wire_in_lumen(m, L, n, clamp, dir, bend, run.contact.x, run.length);
    }
    const auto angle = [](const WallRun& r) {
      return std::atan2(r.tip.y(), r.tip.x()) - std::numbers::pi / 2;
    };
    run = secant_length(m, 1.55 * R, 1.6 * R, n, clamp, dir, bend, run, angle);
    const double F = total_force(run.contact) * R * R / wire_EI();
    const double L = run.length / R;
    std::printf("ROD-WALL %s arch_apex %d F %.6f (ref %.6f, %+.2e) L %.6f (ref %.6f, %+.2e)\n",
                name(m), n, F, ref.force, F / ref.force - 1, L, ref.length, L / ref.length - 1);
    ASSERT_EQ(run.contact.nodes.size(), 1u);  // no second contact
    EXPECT_GE(run.contact.min_gap, -1e-12);
    force[i] = F / ref.force - 1;
    length[i] = L / ref.length - 1;
  }
  expect_reached(arch_apex_reached(m), force, length, name(m));
}

// The stepwise insertion of verification/scenes/guidewire_straight.toml (a floppy wire, EI =
// 4e-7 N·m², N = 32, tilted 0.3 rad in a 3 mm tube): from the steady state at 7/14 of the
// insertion scaled to 8/14, XPBD must settle at a 0.1 ms step as at 1 ms, to the same force (the
// steady state does not depend on the step). Contacts projected after the last direct iteration
// instead of before each one make it fail (the frames spin; 20 000 steps, no settling).
TEST(RigidWallXpbd, InsertionStepSettlesAtATenthOfAMillisecondAsAtOne) {
  const RodMaterial floppy{5.073e8, 5.073e8 / (2.0 * 1.33), 6450.0};
  const double tilt = 0.3, insertion = 20.25e-3;
  const Eigen::Vector3d dir(std::sin(tilt), 0.0, std::cos(tilt));
  const StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), kOffset);
  XpbdOptions options;  // direct, 2 iterations, warm-started multipliers
  options.damping = 0.3;
  const auto settle = [&](double L, const VectorXd& start, double start_length, double h,
                          int& steps, double& force, double& min_gap) {
    RodSpec spec = uniform_rod(floppy, L, kWire, 32);
    spec.direction = dir;
    XpbdRod rod(make_layout(spec), 0.0, options);
    const int nodes = rod.energy_model().num_nodes(), tip = rod.tip_node();
    if (start.size() > 0) {
      const Eigen::Vector3d clamp = Eigen::Vector3d::Zero();
      rod.set_state(scaled_start(rod.state(), nodes, clamp, L, start, start_length));
    }
    rod.set_wall(&tube, 2, tip);
    steps = rod.relax(h, VectorXd::Zero(rod.state().size()), 1e-14, 20000);
    force = 0.0;
    for (double f : rod.wall_forces()) force += f;
    min_gap = std::numeric_limits<double>::infinity();
    for (int i = 2; i <= tip; ++i) {
      min_gap = std::min(min_gap, tube.gap(rod.state().segment<3>(3 * i), nullptr, nullptr));
    }
    return rod.state();
  };
  int steps = 0;
  double force = 0.0, gap = 0.0;
  const double L7 = insertion * 7 / 14, L8 = insertion * 8 / 14;
  const VectorXd seven = settle(L7, VectorXd(), 0.0, 1e-3, steps, force, gap);
  ASSERT_LT(steps, 20000);
  double force_1ms = 0.0;
  settle(L8, seven, L7, 1e-3, steps, force_1ms, gap);
  ASSERT_LT(steps, 20000);
  settle(L8, seven, L7, 1e-4, steps, force, gap);
  std::printf(
      "ROD-WALL XPBD insertion 8/14 at 0.1 ms: %d steps, F %.7e N (1 ms: %.7e N), "
      "min gap %.2e m\n",
      steps, force, force_1ms, gap);
  EXPECT_LT(steps, 20000);
  EXPECT_GT(force_1ms, 0.0);
  EXPECT_NEAR(force / force_1ms, 1.0, 1e-6);
  EXPECT_GE(gap, -1e-12);
}

INSTANTIATE_TEST_SUITE_P(Models, RigidWall,
                         ::testing::Values(Model::der, Model::corde, Model::xpbd),
                         [](const auto& info) { return std::string(name(info.param)); });

}  // namespace
}  // namespace vessel::msm::rods::test
