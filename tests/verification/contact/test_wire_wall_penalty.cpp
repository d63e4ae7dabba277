// Two contact formulations of the wire against the wall on the same discrete problem (the line of
// contact of tests/verification/contact/test_wire_wall_contact.cpp on a wall of 30 × 14.24 kPa,
// where the wire dents it by twice its radius): Signorini's conditions (Lagrange multipliers on
// an active set) and the penalty law λ = k max(0, −g) with the same gap, solved at k, 2k, ..., 16k
// and extrapolated to k → ∞. Rows printed as "WIRE-WALL PENALTY ...". Labelled slow (six coupled
// solves on 811 candidates).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "wire_in_tube.hpp"

using namespace vessel;
using namespace vessel::wire_in_tube;

namespace {

/// The total force Σλ (N) and the largest displacement of a pressed node |u_j| (m).
struct Measured {
  double force = 0.0, dent = 0.0;
};
Measured measure(const contact::CondensedWall& wall, const contact::WireWallSolution& s) {
  const Eigen::VectorXd u = wall.compliance() * s.wall_loads();
  Measured m{s.force.sum(), 0.0};
  for (const int j : s.active) m.dent = std::max(m.dent, u.segment<3>(3 * j).norm());
  return m;
}

/// Richardson extrapolation of values at h, h/2, h/4, ... (h = 1/k) for an error series
/// a₁h + a₂h² + ...: the first two levels of the table, its finest entry, and as its error the
/// larger of the finest entry's distance to the last first-level entry and to the previous
/// second-level entry.
struct Extrapolated {
  double value = 0.0, error = 0.0;
};
Extrapolated richardson(const std::vector<double>& f) {
  std::vector<double> r1, r2;
  for (std::size_t i = 0; i + 1 < f.size(); ++i) r1.push_back(2 * f[i + 1] - f[i]);
  for (std::size_t i = 0; i + 1 < r1.size(); ++i) r2.push_back((4 * r1[i + 1] - r1[i]) / 3);
  const double best = r2.back();
  return {best, std::max(std::abs(best - r1.back()), std::abs(best - r2[r2.size() - 2]))};
}

}  // namespace

TEST(WireWallContactSlow, PenaltyExtrapolatedToInfiniteStiffnessMatchesSignorini) {
  VesselParams p;
  p.length = kTubeLength;
  const Vec3 target(kA, 0, 25e-3);
  const TetMesh mesh = refined_patch_mesh(p, target, 0.08e-3, 1.0e-3);
  std::vector<int> nodes;
  for (const int n : inner_nodes(mesh)) {
    if ((mesh.nodes[n] - target).norm() < 1.6e-3) nodes.push_back(n);
  }
  const double young = kWallE * 30;
  const double c = kA - 0.356e-3 / 2;
  const double length = rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(0.356e-3, length, 32, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  const fem::ElasticitySolver solver(mesh, wall_problem(young));
  const contact::ComponentCandidates all = contact::every_component(nodes);
  const contact::CondensedWall wall(solver.free_displacement_system(), all.nodes, all.directions);
  const std::vector<Vec3> directions = contact::into_wall_directions(mesh, nodes, "inner_wall");
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const int first =
      nearest_candidate(mesh, nodes, tip + w.radius * Vec3(tip.x(), tip.y(), 0).normalized());
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  o.max_newton = 400;
  const contact::WireWallSolution lagrange =
      contact::solve_wire_wall_contact(w.contact(), wall, directions, mesh, rigid.x, {first}, o);
  const Measured exact = measure(wall, lagrange);
  std::printf(
      "WIRE-WALL PENALTY Signorini E=%.4g Pa: %zu in contact, F %.9e N, largest dent %.6e m, "
      "%d steps, %.2f s\n",
      young, lagrange.active.size(), exact.force, exact.dent, lagrange.newton_iterations,
      lagrange.seconds);
  // k₀: a hundred times the stiffest candidate's own stiffness along its direction, so each
  // penetration λ/k is at most a hundredth of the dent its own force makes.
  double own = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    own = std::min(own,
                   directions[j].dot(wall.compliance().block<3, 3>(3 * j, 3 * j) * directions[j]));
  }
  const double k0 = 100.0 / own;
  std::vector<double> force, dent;
  for (int level = 0; level < 5; ++level) {
    contact::WireWallOptions penalty = o;
    penalty.penalty_stiffness = k0 * std::pow(2.0, level);
    const contact::WireWallSolution s = contact::solve_wire_wall_contact(
        w.contact(), wall, directions, mesh, rigid.x, {first}, penalty);
    const Measured m = measure(wall, s);
    double penetration = 0.0;
    for (int j = 0; j < s.gap.size(); ++j) penetration = std::max(penetration, -s.gap[j]);
    std::printf(
        "WIRE-WALL PENALTY k=%.4e N/m: %zu in contact, F %.9e N (%+.3e), dent %.6e m "
        "(%+.3e), deepest penetration %.3e m, %d steps, %.2f s\n",
        penalty.penalty_stiffness, s.active.size(), m.force, m.force / exact.force - 1, m.dent,
        m.dent / exact.dent - 1, penetration, s.newton_iterations, s.seconds);
    force.push_back(m.force);
    dent.push_back(m.dent);
  }
  const Extrapolated F = richardson(force), D = richardson(dent);
  std::printf(
      "WIRE-WALL PENALTY extrapolated: F %.9e N (estimated error %.2e, Signorini's differs by "
      "%.2e), dent %.6e m (estimated error %.2e, Signorini's differs by %.2e)\n",
      F.value, F.error, F.value - exact.force, D.value, D.error, D.value - exact.dent);
  // The penalty's error is first order in 1/k: each halving of 1/k halves it.
  const double order = std::log2((force[1] - force[0]) / (force[2] - force[1]));
  std::printf("WIRE-WALL PENALTY observed order in 1/k: %.3f\n", order);
  EXPECT_NEAR(order, 1.0, 0.1);
  EXPECT_LE(std::abs(F.value - exact.force), F.error);
  EXPECT_LE(std::abs(D.value - exact.dent), D.error);
  // The penalty's answer approaches Signorini's from below (the wall's give grows by λ/k).
  EXPECT_LT(force.back(), exact.force);
}
