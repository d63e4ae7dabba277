// Two contact formulations of the wire against the wall on the same discrete problem (the line of
// contact of tests/verification/contact/test_wire_wall_contact.cpp on a wall of 30 × 14.24 kPa,
// where the wire dents it by twice its radius): Signorini's conditions (Lagrange multipliers on
// an active set) and the penalty law λ = k max(0, −g) with the same gap, solved at k, 2k, ..., 16k
// and extrapolated to k → ∞. Rows printed as "WIRE-WALL PENALTY ...". Then the scenes' own floppy
// wire (EI = 4e-7 N·m²) on the scenes' own wall (14.24 kPa) by both formulations, rows
// "WIRE-WALL scene-wire ...". Labelled slow (six coupled solves on 811 candidates each).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
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
  const Vec3& target = kAimPoint;
  const TetMesh mesh = line_of_contact_mesh();
  const std::vector<int> nodes = nodes_within(mesh, target, 1.6e-3);
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

// The scenes' own wire and wall (verification/scenes/guidewire_straight.toml): a floppy wire,
// EI = 4e-7 N·m² on the 0.356 mm section, against the wall at 14.24 kPa, ν = 0.45, on the
// line-of-contact mesh with the band grown. Its rigid-wall force 0.470968 EI/z_c² is 0.47 mN, so
// it dents the wall by ~0.2 mm. Checks: Signorini on every candidate, action = reaction against
// deal.II's support reactions under the contact forces, no inner-wall node outside the candidates
// inside the wire, the force below the rigid wall's (the wall gives), and the penalty law on the
// same candidates extrapolated to k → ∞ agreeing with Signorini's force.
TEST(WireWallContactSlow, ScenesWireOnTheScenesWall) {
  const auto t0 = std::chrono::steady_clock::now();
  const Vec3& target = kAimPoint;
  const TetMesh mesh = line_of_contact_mesh();
  const std::vector<int> nodes = nodes_within(mesh, target, 1.6e-3);
  const double d = 0.356e-3, c = kA - d / 2, EI = 4e-7;
  // Nitinol's E scaled so that E·I = 4e-7 N·m² (E ≈ 5.073e8 Pa), its E/G kept.
  const double scale = EI / msm::rods::solid_section(kNitinol, d).EI;
  const msm::rods::RodMaterial floppy{kNitinol.young * scale, kNitinol.shear * scale,
                                      kNitinol.density};
  const rod_theory::StraightTubeContact ref = rod_theory::straight_tube_contact(kTheta, c / kZc);
  Wire w(d, ref.length * kZc, 32, Vec3(0, 0, target.z() - kZc), floppy);
  ASSERT_NEAR(w.EI, EI, 1e-12 * EI);
  const RigidRun rigid = rigid_run(w);
  const double rigid_ref = ref.force * EI / (kZc * kZc);
  const fem::ElasticitySolver condensing(mesh, wall_problem(kWallE));
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const int first =
      nearest_candidate(mesh, nodes, tip + w.radius * Vec3(tip.x(), tip.y(), 0).normalized());
  contact::WireWallOptions o;
  o.force_scale = EI / (kZc * kZc);
  o.max_newton = 400;
  const contact::GrownContact grown = contact::solve_wire_wall_contact_growing(
      w.contact(), condensing.free_displacement_system(), mesh, nodes, rigid.x, {first}, o);
  const contact::WireWallSolution& s = grown.solution;
  const contact::CondensedWall& wall = *grown.wall;
  const std::vector<Vec3> u = wall.displacement(s.wall_loads());
  double dent = 0;
  for (const int j : s.active)
    dent = std::max(dent, u[static_cast<std::size_t>(grown.nodes[j])].norm());
  const WallStrain strain = largest_strain(mesh, u);
  const double total = s.force.sum();
  std::printf(
      "WIRE-WALL scene-wire Signorini: %zu candidates grown to %zu in %d rounds, %zu pressed, F "
      "%.6e N, rigid-wall solve %.6e N (reference %.6e N), dent %.3e m, %d steps, %.2f s\n",
      nodes.size(), grown.nodes.size(), grown.rounds, s.active.size(), total, rigid.force,
      rigid_ref, dent, s.newton_iterations, s.seconds);
  std::fflush(stdout);

  // Signorini on every candidate.
  for (int j = 0; j < s.force.size(); ++j) {
    EXPECT_GE(s.force[j], 0.0);
    EXPECT_GE(s.gap[j], -1e-12);
    EXPECT_LE(s.force[j] * std::abs(s.gap[j]), 1e-12 * s.force.maxCoeff());
  }
  // Action and reaction: the clamp's reaction against deal.II's support reactions under the
  // contact forces as nodal loads (a second FEM solve).
  fem::ElasticityProblem problem = wall_problem(kWallE);
  problem.patches = nodal_loads(mesh, wall, s);
  ASSERT_EQ(problem.patches.size(), s.active.size());
  fem::ElasticitySolver loaded(mesh, problem);
  Vec3 supports = Vec3::Zero();
  for (const fem::GroupReaction& g : loaded.solve().reactions) supports += g.force;
  const Vec3 clamp = contact::clamp_reaction(w.contact(), wall, mesh, s);
  const Vec3 sum = clamp + supports;
  EXPECT_LT(sum.norm(), 1e-9 * total);
  // No inner-wall node outside the candidates inside the wire.
  double outside = std::numeric_limits<double>::infinity();
  for (const int n : inner_nodes(mesh)) {
    if (std::find(grown.nodes.begin(), grown.nodes.end(), n) != grown.nodes.end()) continue;
    outside = std::min(outside, contact::capsule_gap(w.contact(), s.x, mesh.nodes[n] + u[n]));
  }
  EXPECT_GT(outside, 0.0);
  // For comparison only: the series-spring law F_rigid/(1 + C_v/C_r) with the wall's compliance
  // under the converged forces, λᵀWλ/F², and the wire's at its rigid contact (central difference).
  const Eigen::VectorXd loads = s.wall_loads();
  const double wall_compliance = loads.dot(wall.compliance() * loads) / (total * total);
  constexpr double kShift = 1e-8;
  const double wire_compliance =
      2 * kShift / (rigid_run(w, -kShift).force - rigid_run(w, kShift).force);
  const double series = rigid.force / (1 + wall_compliance / wire_compliance);
  std::printf(
      "WIRE-WALL scene-wire checks: clamp + supports |%.3e| N (%.2e of F), smallest gap of the "
      "non-candidates %.3e m; C_v %.4f m/N, C_r %.4f m/N, series spring %.6e N (F/series-1 "
      "%+.2e)\n",
      sum.norm(), sum.norm() / total, outside, wall_compliance, wire_compliance, series,
      total / series - 1);
  std::fflush(stdout);
  // The wall gives, so the force is below the rigid wall's (DER at N = 32 within 4.3e-4 of the
  // shooting reference, tests/rods/test_rigid_wall.cpp).
  EXPECT_LT(total, rigid.force);
  EXPECT_LT(total, rigid_ref * (1 + 1.5 * 4.26e-4));
  EXPECT_LT(std::abs(rigid.force / rigid_ref - 1), 1.5 * 4.26e-4);

  // The penalty law on the same candidates, k = k₀ ... 16 k₀, extrapolated to k → ∞.
  const std::vector<Vec3> directions =
      contact::into_wall_directions(mesh, grown.nodes, "inner_wall");
  double own = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < grown.nodes.size(); ++j) {
    own = std::min(own,
                   directions[j].dot(wall.compliance().block<3, 3>(3 * j, 3 * j) * directions[j]));
  }
  const double k0 = 100.0 / own;
  const int first_grown = static_cast<int>(
      std::find(grown.nodes.begin(), grown.nodes.end(), nodes[first]) - grown.nodes.begin());
  std::vector<double> force, dents;
  for (int level = 0; level < 5; ++level) {
    contact::WireWallOptions penalty = o;
    penalty.penalty_stiffness = k0 * std::pow(2.0, level);
    const contact::WireWallSolution sp = contact::solve_wire_wall_contact(
        w.contact(), wall, directions, mesh, rigid.x, {first_grown}, penalty);
    const Measured m = measure(wall, sp);
    std::printf(
        "WIRE-WALL scene-wire penalty k=%.4e N/m: %zu pressed, F %.9e N (%+.3e), %d steps, "
        "%.2f s\n",
        penalty.penalty_stiffness, sp.active.size(), m.force, m.force / total - 1,
        sp.newton_iterations, sp.seconds);
    std::fflush(stdout);
    force.push_back(m.force);
    dents.push_back(m.dent);
  }
  const Extrapolated F = richardson(force);
  const double order = std::log2((force[1] - force[0]) / (force[2] - force[1]));
  std::printf(
      "WIRE-WALL scene-wire penalty extrapolated: F %.9e N (estimated error %.2e, "
      "Signorini's differs by %.2e), observed order in 1/k %.3f\n",
      F.value, F.error, F.value - total, order);
  EXPECT_NEAR(order, 1.0, 0.1);
  EXPECT_LE(std::abs(F.value - total), F.error);
  EXPECT_LT(force.back(), total);

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double load = 0.0;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1) load = -1.0;
    std::fclose(f);
  }
  std::printf(
      "WIRE-WALL scene-wire 1x: F = %.4f mN (rigid %.4f mN, %+.2e), %zu pressed nodes, dent "
      "%.3f mm (%.2f r_w), largest strain %.3f (Green-Lagrange %.3f), %d steps, %.1f s, load avg "
      "%.2f\n",
      total * 1e3, rigid.force * 1e3, total / rigid.force - 1, s.active.size(), dent * 1e3,
      dent / w.radius, strain.small, strain.green, s.newton_iterations, seconds, load);
}
