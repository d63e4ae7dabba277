// Item 3: the wire against a rigid lumen (frictionless, one-sided), against the continuum
// references of fem_reference/rod_theory: the straight tube (shooting) and the arch apex
// (quarter-wave elastica). Rows printed as "ROD-WALL model case N F/F_ref-1 L/L_ref-1".
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "fem_reference/rod_theory/tube_contact.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rigid_wall.hpp"

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

/// The DER wire of length L from the clamp (origin, direction) inside `lumen`, started from
/// `start_shape` (node positions of a rod of the same N, scaled about the clamp by L/its length)
/// or from the straight rest state.
WallRun der_in_lumen(double length, int segments, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& direction, const RigidLumen& lumen,
                     const VectorXd& start_shape = {}, double start_length = 0.0) {
  RodSpec spec = uniform_rod(kNitinol, length, kWire, segments);
  spec.origin = origin;
  spec.direction = direction;
  DerRod rod(make_layout(spec));
  VectorXd x = rod.rest_state();
  if (start_shape.size() > 0) {
    for (int i = 0; i < rod.num_nodes(); ++i) {
      x.segment<3>(3 * i) = origin + (length / start_length) * (start_shape.segment<3>(3 * i) - origin);
    }
    rod.update_reference(x);
  }
  ConstrainedOptions options;
  options.force_scale = wire_EI() / (length * length);
  WallRun run;
  run.contact = solve_wall_contact(rod, nullptr, rod.clamp_fixed(), x, lumen, 2,
                                   rod.layout().tip_node, options);
  run.tip = run.contact.x.segment<3>(3 * rod.layout().tip_node);
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
WallRun secant_length(double L0, double L1, int segments, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& direction, const RigidLumen& lumen, WallRun previous,
                      const Target& target) {
  WallRun a = der_in_lumen(L0, segments, origin, direction, lumen, previous.contact.x, previous.length);
  WallRun b = der_in_lumen(L1, segments, origin, direction, lumen, a.contact.x, a.length);
  for (int it = 0; it < 30 && std::abs(target(b)) > 1e-12; ++it) {
    const double L = b.length - target(b) * (b.length - a.length) / (target(b) - target(a));
    a = b;
    b = der_in_lumen(L, segments, origin, direction, lumen, a.contact.x, a.length);
  }
  return b;
}

TEST(RigidWall, StraightTubeTipContactMatchesShooting) {
  const double z = 20e-3, theta = 0.3;
  const rod_theory::StraightTubeContact ref = rod_theory::straight_tube_contact(theta, kOffset / z);
  const StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), kOffset);
  const Eigen::Vector3d dir(std::cos(theta), std::sin(theta), 0.0);
  for (int n : {16, 32, 64}) {
    const WallRun start = der_in_lumen(ref.length * z, n, Eigen::Vector3d::Zero(), dir, tube);
    const WallRun run = secant_length(ref.length * z, 1.001 * ref.length * z, n,
                                      Eigen::Vector3d::Zero(), dir, tube, start,
                                      [&](const WallRun& r) { return r.tip.x() - z; });
    const double F = total_force(run.contact) * z * z / wire_EI();
    const double L = run.length / z;
    std::printf("ROD-WALL DER straight_tube %d F %.6f (ref %.6f, %+.2e) L %.6f (ref %.6f, %+.2e)\n",
                n, F, ref.force, F / ref.force - 1, L, ref.length, L / ref.length - 1);
    ASSERT_EQ(run.contact.nodes.size(), 1u);  // a tip contact only
    EXPECT_GE(run.contact.min_gap, -1e-12);
    if (n == 32) {
      EXPECT_NEAR(F / ref.force, 1.0, 1e-2);
      EXPECT_NEAR(L / ref.length, 1.0, 1e-2);
    }
  }
}

TEST(RigidWall, NoForceAtZeroGapAndNeverPulling) {
  const double theta = 0.3;
  const StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), kOffset);
  const Eigen::Vector3d dir(std::cos(theta), std::sin(theta), 0.0);
  const double touch = kOffset / std::sin(theta);  // the straight wire's tip on the wall
  const WallRun at = der_in_lumen(touch * (1.0 - 1e-9), 32, Eigen::Vector3d::Zero(), dir, tube);
  EXPECT_TRUE(at.contact.nodes.empty());
  // Just beyond: a small force, the linear cantilever's 3EI·Δy/(L³ cos²θ), pushing (never pulling).
  const double L = touch * (1.0 + 1e-5);
  const WallRun beyond = der_in_lumen(L, 32, Eigen::Vector3d::Zero(), dir, tube);
  ASSERT_EQ(beyond.contact.forces.size(), 1u);
  const double dy = L * std::sin(theta) - kOffset;
  const double linear = 3.0 * wire_EI() * dy / (std::pow(L, 3) * std::cos(theta) * std::cos(theta));
  EXPECT_GT(beyond.contact.forces[0], 0.0);
  EXPECT_NEAR(beyond.contact.forces[0] / linear, 1.0, 5e-3);  // the discretisation's 1/(2N²)
}

TEST(RigidWall, ArchApexQuarterWaveElastica) {
  const double R = 15e-3;
  const double Ro = R + kOffset;
  const rod_theory::ArchApexContact ref = rod_theory::arch_apex_contact(Ro / R);
  const TorusBend bend(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), R, kOffset);
  const Eigen::Vector3d clamp(R, 0.0, 0.0), dir = Eigen::Vector3d::UnitY();
  for (int n : {16, 32, 64}) {
    // Insert the wire in steps (each solve from the last shape), then find the length whose tip
    // bears at the apex (polar angle π/2).
    WallRun run = der_in_lumen(0.6 * R, n, clamp, dir, bend);
    for (double L = 0.7 * R; L < 1.5 * R; L += 0.1 * R) {
      run = der_in_lumen(L, n, clamp, dir, bend, run.contact.x, run.length);
    }
    const auto angle = [](const WallRun& r) { return std::atan2(r.tip.y(), r.tip.x()) - std::numbers::pi / 2; };
    run = secant_length(1.55 * R, 1.6 * R, n, clamp, dir, bend, run, angle);
    const double F = total_force(run.contact) * R * R / wire_EI();
    const double L = run.length / R;
    std::printf("ROD-WALL DER arch_apex %d F %.6f (ref %.6f, %+.2e) L %.6f (ref %.6f, %+.2e)\n", n,
                F, ref.force, F / ref.force - 1, L, ref.length, L / ref.length - 1);
    ASSERT_EQ(run.contact.nodes.size(), 1u);  // no second contact
    EXPECT_GE(run.contact.min_gap, -1e-12);
    if (n == 32) {
      EXPECT_NEAR(F / ref.force, 1.0, 1e-2);
      EXPECT_NEAR(L / ref.length, 1.0, 1e-2);
    }
  }
}

}  // namespace
}  // namespace vessel::msm::rods::test
