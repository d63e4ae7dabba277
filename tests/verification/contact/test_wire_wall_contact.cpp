// A rod inside a deformable tube, the wire's surface (a capsule of radius r_w) against the wall's
// inner surface, the contact found by the solve (contact::solve_wire_wall_contact on a
// contact::CondensedWall). Set-up of the straight-tube reference (guidewire_notes.md,
// fem_reference/rod_theory/tube_contact.hpp): a 0.356 mm nitinol wire clamped on the axis of a
// 3 mm tube, tilted by 0.3 rad towards the wall, its tip bearing on the wall at z_c = 20 mm.
// Rows printed as "WIRE-WALL ...".
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/rod_theory/tube_contact.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rigid_wall.hpp"
#include "verification/contact/wire_wall_contact.hpp"
#include "wire_in_tube.hpp"

using namespace vessel;

using namespace vessel::wire_in_tube;

// The rigid limit: the scenes' wall made 10⁶ times stiffer. The force must be the rigid-wall
// solve's of the same discrete wire (the wall's compliance ~0.5e-6 m/N moves it by ~1e-5) and so
// the shooting reference's F z_c²/EI = 0.470968 within DER's error at N = 32 (4.3e-4, measured in
// tests/rods/test_rigid_wall.cpp).
TEST(WireWallContact, RigidLimitMatchesTheStraightTubeReference) {
  const TetMesh& mesh = tube_mesh();
  const double r_aim = std::hypot(mesh.nodes[aim_node(mesh)].x(), mesh.nodes[aim_node(mesh)].y());
  ASSERT_NEAR(r_aim, kA, 1e-12);  // the aimed node is on the exact cylinder
  const double d = 0.356e-3;
  const CoupledRun run = coupled_run(kWallE * 1e6, d, 32);
  double total = 0.0;
  for (const int j : run.solution.active) total += run.solution.force[j];
  const double EI = msm::rods::solid_section(kNitinol, d).EI;
  const rod_theory::StraightTubeContact ref =
      rod_theory::straight_tube_contact(kTheta, (kA - d / 2) / kZc);
  const double scaled = total * kZc * kZc / EI;
  std::printf(
      "WIRE-WALL rigid limit N=32: F z^2/EI %.6f (ref %.6f, %+.2e; rigid-wall solve "
      "%+.2e), %zu in contact, %d active-set changes, %d Newton, %.3f s (W %.3f s)\n",
      scaled, ref.force, scaled / ref.force - 1, total / run.rigid_force - 1,
      run.solution.active.size(), run.solution.active_set_changes, run.solution.newton_iterations,
      run.solution.seconds, run.setup_seconds);
  EXPECT_EQ(run.solution.active.size(), 1u);  // the tip's hemisphere on one node
  EXPECT_LT(std::abs(total / run.rigid_force - 1), 1e-4);
  EXPECT_LT(std::abs(scaled / ref.force - 1), 1.5 * 4.26e-4);
}

// Action and reaction on a compliant wall (the scenes' wall 100 times stiffer, 1.4 MPa, the wire
// denting it by a few tenths of a mm): the wire's clamp reaction (from the rod's own forces at the
// held nodes) plus the wall's support reactions (deal.II's, from a second FEM solve under the
// contact forces as nodal loads) sum to zero; that FEM solve's displacement along each active
// node's direction is the condensed wall's Wλ; Signorini's conditions hold on every candidate.
TEST(WireWallContact, ActionEqualsReactionAndSignoriniHolds) {
  const TetMesh& mesh = tube_mesh();
  const double young = kWallE * 100;
  const CoupledRun run = coupled_run(young, 0.356e-3, 32);
  const contact::WireWallSolution& s = run.solution;
  fem::ElasticityProblem p = wall_problem(young);
  const fem::ElasticitySolver condensing(mesh, p);
  const std::vector<int> nodes = band(mesh, mesh.nodes[aim_node(mesh)].z(), 4e-3, 1.05);
  const contact::ComponentCandidates all = contact::every_component(nodes);
  const contact::CondensedWall wall(condensing.free_displacement_system(), all.nodes,
                                    all.directions);
  p.patches = nodal_loads(mesh, wall, s);
  ASSERT_EQ(p.patches.size(), s.active.size());
  fem::ElasticitySolver solver(mesh, p);
  const fem::ElasticityResult& r = solver.solve();
  Vec3 supports = Vec3::Zero();
  for (const fem::GroupReaction& g : r.reactions) supports += g.force;
  const Vec3 on_wall = s.total_force_on_wall();
  const Vec3 sum = run.clamp + supports;
  std::printf(
      "WIRE-WALL action-reaction E=%.3g Pa: %zu in contact, force on wall (%.6e, %.6e, "
      "%.6e) N, clamp + supports |%.3e| N (%.2e relative), %d active-set changes, %d "
      "Newton, %.3f s\n",
      young, s.active.size(), on_wall.x(), on_wall.y(), on_wall.z(), sum.norm(),
      sum.norm() / on_wall.norm(), s.active_set_changes, s.newton_iterations, s.seconds);
  EXPECT_LT(sum.norm(), 1e-9 * on_wall.norm());
  const Eigen::VectorXd condensed = wall.compliance() * s.wall_loads();
  double dent = 0.0;
  for (const int j : s.active) {
    const Vec3 u = r.nodal_displacement[static_cast<std::size_t>(wall.nodes()[3 * j])];
    EXPECT_LT((u - condensed.segment<3>(3 * j)).norm(), 1e-9 * condensed.cwiseAbs().maxCoeff());
    dent = std::max(dent, u.norm());
  }
  std::printf("WIRE-WALL action-reaction: largest dent %.4e m\n", dent);
  for (int j = 0; j < s.force.size(); ++j) {
    EXPECT_GE(s.force[j], 0.0);
    EXPECT_GE(s.gap[j], -1e-13);
    EXPECT_LE(s.force[j] * std::abs(s.gap[j]), 1e-13 * s.force.maxCoeff());
  }
}

// The series-spring law F = F_rigid·C_r/(C_r + C_v) (C_r the wire's compliance at the rigid
// contact, C_v the wall's under the contact force): the first-order expansion of the coupled
// equilibrium in C_v/C_r for a contact that stays at one point. So on a tip contact its error
// must fall as (C_v/C_r)²: walls 1e4, 1e3 and 1e2 times the scenes' modulus.
TEST(WireWallContact, SeriesSpringLawIsTheSmallComplianceLimit) {
  double previous_error = 0.0, previous_ratio = 0.0;
  for (const double factor : {1e4, 1e3, 1e2}) {
    const CoupledRun run = coupled_run(kWallE * factor, 0.356e-3, 32);
    const double ratio = run.wall_compliance / run.wire_compliance;
    const double series = run.rigid_force / (1 + ratio);
    const double error = run.total / series - 1;
    std::printf(
        "WIRE-WALL series spring E=%.3g Pa: F %.6e N, rigid %.6e, series %.6e (F/series-1 "
        "%+.2e, F/rigid-1 %+.2e), C_v/C_r %.3e, %zu in contact\n",
        kWallE * factor, run.total, run.rigid_force, series, error, run.total / run.rigid_force - 1,
        ratio, run.solution.active.size());
    ASSERT_EQ(run.solution.active.size(), 1u);
    EXPECT_LT(std::abs(error), 0.1 * std::abs(run.total / run.rigid_force - 1));
    if (previous_ratio > 0) {
      const double order =
          std::log(std::abs(error / previous_error)) / std::log(ratio / previous_ratio);
      std::printf("WIRE-WALL series spring: order of its error in C_v/C_r %.2f\n", order);
      EXPECT_GT(order, 1.8);
    }
    previous_error = error;
    previous_ratio = ratio;
  }
}

// A line of contact on a compliant wall (1.4 MPa) meshed finely where the wire bears (gmsh, 0.08 mm
// within 1 mm of the aimed point, growing to the wall's 1 mm elsewhere): the tip's hemisphere and
// the body behind it dent the wall by ~0.14 mm (0.8 r_w) over a zone of many nodes. Checks: the
// zone lies inside the candidates (no contact at their edge), action = reaction against the FEM's
// support reactions, Signorini on every candidate. The force is printed beside the rigid wall's and
// the series-spring law's with the wall's compliance under the converged contact forces.
TEST(WireWallContact, LineOfContactOnACompliantWall) {
  const Vec3& target = kAimPoint;
  const auto t0 = std::chrono::steady_clock::now();
  const TetMesh mesh = line_of_contact_mesh();
  const double mesh_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  constexpr double kBand = 1.6e-3;
  const std::vector<int> nodes = nodes_within(mesh, target, kBand);
  const double young = kWallE * 100;
  const CoupledRun run = coupled_run(mesh, target, nodes, young, 0.356e-3, 32, 1.0);
  const contact::WireWallSolution& s = run.solution;
  double dent = 0, reach = 0, z_min = 1, z_max = 0;
  for (const int j : s.active) {
    const Vec3& x = mesh.nodes[nodes[j]];
    dent = std::max(dent, run.dent[j]);
    reach = std::max(reach, (x - target).norm());
    z_min = std::min(z_min, x.z());
    z_max = std::max(z_max, x.z());
  }
  const double ratio = run.wall_compliance / run.wire_compliance;
  const double series = run.rigid_force / (1 + ratio);
  std::printf(
      "WIRE-WALL line contact E=%.3g Pa: mesh %zu nodes (%.1f s), %zu candidates (W %.1f "
      "s), %zu in contact over z %.3f..%.3f mm (reach %.3f mm), largest dent %.3e m, F "
      "%.6e N, rigid %.6e (%+.2e), series spring %.6e (F/series-1 %+.2e, C_v/C_r %.3e), "
      "%d contact-set changes, %d steps, %.2f s\n",
      young, mesh.nodes.size(), mesh_seconds, nodes.size(), run.setup_seconds, s.active.size(),
      z_min * 1e3, z_max * 1e3, reach * 1e3, dent, run.total, run.rigid_force,
      run.total / run.rigid_force - 1, series, run.total / series - 1, ratio, s.active_set_changes,
      s.newton_iterations, s.seconds);
  EXPECT_GE(s.active.size(), 10u);
  EXPECT_LT(reach, kBand - 0.3e-3);  // well inside the candidates
  // Action and reaction, against deal.II's reactions under the contact forces as nodal loads.
  fem::ElasticityProblem problem = wall_problem(young);
  const fem::ElasticitySolver condensing(mesh, problem);
  const contact::ComponentCandidates all = contact::every_component(nodes);
  const contact::CondensedWall wall(condensing.free_displacement_system(), all.nodes,
                                    all.directions);
  problem.patches = nodal_loads(mesh, wall, s);
  fem::ElasticitySolver solver(mesh, problem);
  Vec3 supports = Vec3::Zero();
  for (const fem::GroupReaction& g : solver.solve().reactions) supports += g.force;
  const Vec3 sum = run.clamp + supports;
  std::printf("WIRE-WALL line contact: clamp + supports |%.3e| N (%.2e of the force)\n", sum.norm(),
              sum.norm() / run.total);
  EXPECT_LT(sum.norm(), 1e-9 * run.total);
  // No inner-wall node outside the candidates is inside the wire (the wall's whole displacement).
  const std::vector<Vec3> u = wall.displacement(s.wall_loads());
  double outside = std::numeric_limits<double>::infinity();
  for (const int n : inner_nodes(mesh)) {
    if (std::find(nodes.begin(), nodes.end(), n) != nodes.end()) continue;
    outside =
        std::min(outside, contact::capsule_gap(run.wire, run.solution.x, mesh.nodes[n] + u[n]));
  }
  std::printf("WIRE-WALL line contact: smallest gap of the non-candidates %.3e m\n", outside);
  EXPECT_GT(outside, 0.0);
  for (int j = 0; j < s.force.size(); ++j) {
    EXPECT_GE(s.force[j], 0.0);
    EXPECT_GE(s.gap[j], -1e-12);
    EXPECT_LE(s.force[j] * std::abs(s.gap[j]), 1e-12 * s.force.maxCoeff());
  }
}

// The line of contact on a wall of 30 × 14.24 kPa, where the dent is twice r_w, solved directly
// with the band grown: Signorini's conditions, action = reaction against the wall's total force,
// no inner-wall node outside the candidates inside the wire; the dent against r_w and the wall's
// strains are printed (the linear wall is the model here: whether it is valid at that dent is
// the neo-Hookean reference's question).
TEST(WireWallContact, LineOfContactOnASofterWall) {
  const Vec3& target = kAimPoint;
  const TetMesh mesh = line_of_contact_mesh();
  const std::vector<int> nodes = nodes_within(mesh, target, 1.6e-3);
  const double young = kWallE * 30;
  const double c = kA - 0.356e-3 / 2;
  const double length = rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(0.356e-3, length, 32, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  const fem::ElasticitySolver solver(mesh, wall_problem(young));
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const int first =
      nearest_candidate(mesh, nodes, tip + w.radius * Vec3(tip.x(), tip.y(), 0).normalized());
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  const contact::GrownContact grown = contact::solve_wire_wall_contact_growing(
      w.contact(), solver.free_displacement_system(), mesh, nodes, rigid.x, {first}, o);
  const contact::WireWallSolution& s = grown.solution;
  const std::vector<Vec3> u = grown.wall->displacement(s.wall_loads());
  double dent = 0;
  for (const int j : s.active)
    dent = std::max(dent, u[static_cast<std::size_t>(grown.nodes[j])].norm());
  const WallStrain strain = largest_strain(mesh, u);
  const double total = s.force.sum();
  std::printf(
      "WIRE-WALL softer wall E=%.4g Pa: %zu candidates grown to %zu in %d rounds, %zu in "
      "contact, largest dent %.3e m (dent/r_w %.2f), largest strain %.3f (Green-Lagrange %.3f), "
      "F %.6e N (rigid %.6e), %d contact-set changes, %d steps, %.2f s\n",
      young, nodes.size(), grown.nodes.size(), grown.rounds, s.active.size(), dent, dent / w.radius,
      strain.small, strain.green, total, rigid.force, s.active_set_changes, s.newton_iterations,
      s.seconds);
  const Vec3 clamp = contact::clamp_reaction(w.contact(), *grown.wall, mesh, s);
  EXPECT_LT((clamp - s.total_force_on_wall()).norm(), 1e-9 * total);
  double outside = std::numeric_limits<double>::infinity();
  for (const int n : inner_nodes(mesh)) {
    if (std::find(grown.nodes.begin(), grown.nodes.end(), n) != grown.nodes.end()) continue;
    outside = std::min(outside, contact::capsule_gap(w.contact(), s.x, mesh.nodes[n] + u[n]));
  }
  EXPECT_GT(outside, 0.0);
  for (int j = 0; j < s.force.size(); ++j) {
    EXPECT_GE(s.force[j], 0.0);
    EXPECT_GE(s.gap[j], -1e-12);
    EXPECT_LE(s.force[j] * std::abs(s.gap[j]), 1e-12 * s.force.maxCoeff());
  }
}

// Band growth: the line of contact's candidates cut to the nodes within 0.3 mm of the aimed
// point (the contact reaches ~1 mm), grown by solve_wire_wall_contact_growing until no pressed
// candidate lies on the band's edge. The answer must be the wide band's (1.6 mm, which the
// contact stays well inside): the same pressed nodes with the same forces.
TEST(WireWallContact, GrownBandMatchesTheWideBand) {
  const Vec3& target = kAimPoint;
  const TetMesh mesh = line_of_contact_mesh();
  auto within = [&](double radius) { return nodes_within(mesh, target, radius); };
  const std::vector<int> wide_nodes = within(1.6e-3), small_nodes = within(0.3e-3);
  const double young = kWallE * 100;
  const CoupledRun wide = coupled_run(mesh, target, wide_nodes, young, 0.356e-3, 32, 1.0);

  const double c = kA - 0.356e-3 / 2;
  const double length = rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(0.356e-3, length, 32, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  const fem::ElasticitySolver solver(mesh, wall_problem(young));
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const int first =
      nearest_candidate(mesh, small_nodes, tip + w.radius * Vec3(tip.x(), tip.y(), 0).normalized());
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  const contact::GrownContact grown = contact::solve_wire_wall_contact_growing(
      w.contact(), solver.free_displacement_system(), mesh, small_nodes, rigid.x, {first}, o);
  const contact::WireWallSolution& s = grown.solution;
  std::printf(
      "WIRE-WALL band growth: %zu candidates grown to %zu in %d rounds, %zu in contact (wide "
      "band: %zu of %zu), F %.9e N (wide %.9e, %+.2e), %.2f s\n",
      small_nodes.size(), grown.nodes.size(), grown.rounds, s.active.size(),
      wide.solution.active.size(), wide_nodes.size(), s.force.sum(), wide.total,
      s.force.sum() / wide.total - 1, s.seconds);
  EXPECT_GE(grown.rounds, 1);
  EXPECT_LT(grown.nodes.size(), wide_nodes.size());
  std::vector<int> pressed, wide_pressed;
  for (const int j : s.active) pressed.push_back(grown.nodes[j]);
  for (const int j : wide.solution.active) wide_pressed.push_back(wide_nodes[j]);
  std::sort(pressed.begin(), pressed.end());
  std::sort(wide_pressed.begin(), wide_pressed.end());
  ASSERT_EQ(pressed, wide_pressed);
  for (const int j : s.active) {
    const auto k =
        std::find(wide_nodes.begin(), wide_nodes.end(), grown.nodes[j]) - wide_nodes.begin();
    EXPECT_NEAR(s.force[j], wide.solution.force[k], 1e-7 * wide.solution.force.maxCoeff());
  }
  EXPECT_NEAR(s.force.sum(), wide.total, 1e-8 * wide.total);
}

// The same rigid limit with CORDE (its inextensibility and unit-quaternion constraints carried by
// the coupled solve, its quaternions projected after each step): within CORDE's own error at
// N = 32 against the rigid tube (6.56e-4, tests/rods/test_rigid_wall.cpp), and the clamp's
// reaction (constraint forces included) against the wall's total force. Started from DER's
// rigid-wall solution: its positions, each edge's frame turned from the rest tangent to the edge's.
TEST(WireWallContact, RigidLimitWithCordeConstraints) {
  const TetMesh& mesh = tube_mesh();
  const Vec3 target = mesh.nodes[aim_node(mesh)];
  const double d = 0.356e-3, c = kA - d / 2;
  const rod_theory::StraightTubeContact ref = rod_theory::straight_tube_contact(kTheta, c / kZc);
  Wire der(d, ref.length * kZc, 32, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(der);
  const msm::rods::CordeRod corde(der.layout);
  Eigen::VectorXd x = corde.rest_state();
  const int nodes = corde.num_nodes();
  x.head(3 * nodes) = rigid.x.head(3 * nodes);
  for (int j = 0; j < der.layout.num_edges(); ++j) {
    if (der.layout.ghost[static_cast<std::size_t>(j)]) continue;
    const Vec3 t0 = (der.layout.rest[j + 1] - der.layout.rest[j]).normalized();
    const Vec3 t = (x.segment<3>(3 * (j + 1)) - x.segment<3>(3 * j)).normalized();
    const Eigen::Vector4d q0 = x.segment<4>(corde.quaternion_dof(j));
    const Eigen::Quaterniond q =
        Eigen::Quaterniond::FromTwoVectors(t0, t) * Eigen::Quaterniond(q0[0], q0[1], q0[2], q0[3]);
    x.segment<4>(corde.quaternion_dof(j)) << q.w(), q.x(), q.y(), q.z();
  }
  const std::vector<int> cand = band(mesh, target.z(), 4e-3, 1.05);
  const fem::ElasticitySolver solver(mesh, wall_problem(kWallE * 1e6));
  const contact::ComponentCandidates all = contact::every_component(cand);
  const contact::CondensedWall wall(solver.free_displacement_system(), all.nodes, all.directions);
  const contact::ContactWire w = contact::contact_wire(corde, d / 2);
  contact::WireWallOptions o;
  o.force_scale = der.EI / (kZc * kZc);
  o.constraint_tolerance = 1e-13;
  const contact::WireWallSolution s = contact::solve_wire_wall_contact(
      w, wall, contact::into_wall_directions(mesh, cand, "inner_wall"), mesh, x, {}, o);
  const double total = s.force.sum();
  const double scaled = total * kZc * kZc / der.EI;
  const Vec3 sum = contact::clamp_reaction(w, wall, mesh, s) - s.total_force_on_wall();
  std::printf(
      "WIRE-WALL rigid limit CORDE N=32: F z^2/EI %.6f (ref %.6f, %+.2e), %zu in contact, "
      "%d steps, %.3f s; clamp reaction - force on wall |%.2e| N (%.1e relative)\n",
      scaled, ref.force, scaled / ref.force - 1, s.active.size(), s.newton_iterations, s.seconds,
      sum.norm(), sum.norm() / total);
  EXPECT_EQ(s.active.size(), 1u);
  EXPECT_LT(std::abs(scaled / ref.force - 1), 1.5 * 6.56e-4);
  EXPECT_LT(sum.norm(), 1e-9 * total);
}

TEST(WireWallContact, RefusesAWireThatDoesNotFit) {
  const TetMesh& mesh = tube_mesh();
  const Vec3 target = mesh.nodes[aim_node(mesh)];
  const std::vector<int> cand = band(mesh, target.z(), 2e-3, 0.5);
  const fem::ElasticitySolver solver(mesh, wall_problem(kWallE));
  const contact::ComponentCandidates all = contact::every_component(cand);
  const contact::CondensedWall wall(solver.free_displacement_system(), all.nodes, all.directions);
  const std::vector<Vec3> directions = contact::into_wall_directions(mesh, cand, "inner_wall");
  const Wire w(0.356e-3, 20e-3, 8, Vec3(0, 0, 5e-3));
  // A wall condensed on one direction per node (no whole displacement), and a direction short.
  const contact::CondensedWall along_one(solver.free_displacement_system(), cand, directions);
  EXPECT_THROW(contact::solve_wire_wall_contact(w.contact(), along_one, directions, mesh,
                                                w.rod.rest_state(), {}),
               std::invalid_argument);
  const std::vector<Vec3> short_by_one(directions.begin() + 1, directions.end());
  EXPECT_THROW(contact::solve_wire_wall_contact(w.contact(), wall, short_by_one, mesh,
                                                w.rod.rest_state(), {}),
               std::invalid_argument);
  contact::ContactWire bad = w.contact();
  bad.radius = 0.0;
  EXPECT_THROW(
      contact::solve_wire_wall_contact(bad, wall, directions, mesh, w.rod.rest_state(), {}),
      std::invalid_argument);
  bad = w.contact();
  bad.last_node = bad.num_nodes;
  EXPECT_THROW(
      contact::solve_wire_wall_contact(bad, wall, directions, mesh, w.rod.rest_state(), {}),
      std::invalid_argument);
  // A candidate that is not a node of the inner wall has no direction.
  EXPECT_THROW(
      contact::into_wall_directions(mesh, {static_cast<int>(mesh.nodes.size())}, "inner_wall"),
      InputError);
}

// The wall condensed on every component of its nodes (3 × 3 blocks) against the same wall
// condensed on one direction per node: n_iᵀ W_ij n_j must be the one-direction compliance, and
// the displacement fields under the same forces must match.
TEST(WireWallContact, EveryComponentHoldsTheOneDirectionCompliance) {
  const TetMesh& mesh = tube_mesh();
  const std::vector<int> cand = band(mesh, mesh.nodes[aim_node(mesh)].z(), 2e-3, 0.5);
  const std::vector<Vec3> n = contact::into_wall_directions(mesh, cand, "inner_wall");
  const fem::ElasticitySolver solver(mesh, wall_problem(kWallE));
  const contact::ComponentCandidates all = contact::every_component(cand);
  const contact::CondensedWall full(solver.free_displacement_system(), all.nodes, all.directions);
  const contact::CondensedWall along(solver.free_displacement_system(), cand, n);
  const Eigen::Index m = static_cast<Eigen::Index>(cand.size());
  ASSERT_EQ(full.compliance().rows(), 3 * m);
  double worst = 0.0;
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) {
      const double projected = n[i].dot(full.compliance().block<3, 3>(3 * i, 3 * j) * n[j]);
      worst = std::max(worst, std::abs(projected - along.compliance()(i, j)));
    }
  }
  std::printf("WIRE-WALL every component: %td nodes, |n W n - W_n| at most %.2e of max W_n\n", m,
              worst / along.compliance().maxCoeff());
  EXPECT_LT(worst, 1e-10 * along.compliance().maxCoeff());
  Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(m, 1e-3, 2e-3);
  Eigen::VectorXd loads(3 * m);
  for (Eigen::Index j = 0; j < m; ++j) loads.segment<3>(3 * j) = lambda[j] * n[j];
  const std::vector<Vec3> a = full.displacement(loads), b = along.displacement(lambda);
  double diff = 0.0, size = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    diff = std::max(diff, (a[k] - b[k]).norm());
    size = std::max(size, b[k].norm());
  }
  EXPECT_LT(diff, 1e-10 * size);
}
