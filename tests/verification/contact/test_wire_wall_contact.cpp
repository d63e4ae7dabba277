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

using namespace vessel;

namespace {

const msm::rods::RodMaterial kNitinol{48e9, 48e9 / 2.66, 6450.0};
constexpr double kA = 3e-3;         // lumen radius, m
constexpr double kTheta = 0.3;      // clamp tilt, rad
constexpr double kZc = 20e-3;       // the reference's contact distance, m
constexpr double kWallE = 14.24e3;  // the scenes' wall modulus, Pa
constexpr double kTubeLength = 30e-3;

/// The structured straight tube (axis z, 0 ≤ z ≤ 30 mm, a = 3 mm, t = 1 mm), level 0.
const TetMesh& tube_mesh() {
  static const TetMesh mesh = [] {
    VesselParams p;
    p.length = kTubeLength;
    p.style = MeshStyle::structured;
    p.level = 0;
    return generate_vessel_mesh(p);
  }();
  return mesh;
}

std::vector<int> inner_nodes(const TetMesh& mesh) {
  return mesh.group_nodes(mesh.require_group("inner_wall", 2, "tube"));
}

/// The inner-wall node on the +x line (y = 0) nearest z = 25 mm: where the tip is aimed, so the
/// tip's hemisphere meets the faceted wall at one of its nodes (which lie on the exact cylinder).
int aim_node(const TetMesh& mesh) {
  int best = -1;
  for (const int n : inner_nodes(mesh)) {
    const Vec3& x = mesh.nodes[n];
    if (std::abs(x.y()) > 1e-9 || x.x() < 0) continue;
    if (best < 0 || std::abs(x.z() - 25e-3) < std::abs(mesh.nodes[best].z() - 25e-3)) best = n;
  }
  return best;
}

fem::ElasticityProblem wall_problem(double young) {
  fem::ElasticityProblem p;
  p.material.youngs_modulus = young;
  p.material.poisson_ratio = 0.45;
  p.options.degree = 1;
  p.dirichlet = {fem::DirichletCondition::clamped("inlet"),
                 fem::DirichletCondition::clamped("outlet")};
  return p;
}

/// Candidates: inner-wall nodes within `half_length` of z along the axis and `half_angle` of +x.
std::vector<int> band(const TetMesh& mesh, double z, double half_length, double half_angle) {
  std::vector<int> out;
  for (const int n : inner_nodes(mesh)) {
    const Vec3& x = mesh.nodes[n];
    if (std::abs(x.z() - z) <= half_length && std::abs(std::atan2(x.y(), x.x())) <= half_angle)
      out.push_back(n);
  }
  return out;
}

struct Wire {
  msm::rods::RodLayout layout;
  msm::rods::DerRod rod;
  double EI = 0.0, radius = 0.0;
  Wire(double diameter, double length, int segments, const Vec3& origin)
      : layout([&] {
          msm::rods::RodSpec s = msm::rods::uniform_rod(kNitinol, length, diameter, segments);
          s.origin = origin;
          s.direction = Vec3(std::sin(kTheta), 0.0, std::cos(kTheta));
          return msm::rods::make_layout(s);
        }()),
        rod(layout),
        EI(msm::rods::solid_section(kNitinol, diameter).EI),
        radius(diameter / 2) {}
  [[nodiscard]] contact::ContactWire contact() const {
    contact::ContactWire w;
    w.form = &rod;
    w.fixed = rod.clamp_fixed();
    w.num_nodes = rod.num_nodes();
    w.first_node = layout.first_node;
    w.last_node = layout.tip_node;
    w.radius = radius;
    return w;
  }
};

/// The same wire against the exact rigid cylinder (msm/rods/rigid_wall): its contact force, N.
struct RigidRun {
  Eigen::VectorXd x;
  double force = 0.0;
};
RigidRun rigid_run(Wire& w, double wall_shift = 0.0) {
  const msm::rods::StraightTube tube(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(),
                                     kA + wall_shift - w.radius);
  Eigen::VectorXd x = w.rod.rest_state();
  w.rod.update_reference(x);
  msm::rods::ConstrainedOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  const msm::rods::ContactSolution s = msm::rods::solve_wall_contact(
      w.rod, nullptr, w.rod.clamp_fixed(), x, tube, 2, w.layout.tip_node, o);
  RigidRun r{s.x, 0.0};
  for (const double f : s.forces) r.force += f;
  return r;
}

/// The candidate nearest the wire's tip pushed out by r_w (the rigid contact's wall point).
int nearest_candidate(const TetMesh& mesh, const std::vector<int>& nodes, const Vec3& point) {
  int best = 0;
  for (int j = 1; j < static_cast<int>(nodes.size()); ++j) {
    if ((mesh.nodes[nodes[j]] - point).norm() < (mesh.nodes[nodes[best]] - point).norm()) best = j;
  }
  return best;
}

/// The contact forces as nodal loads for a second FEM solve (deal.II's own assembly): each active
/// candidate's λ n as a point at its node of an inner-wall triangle.
std::vector<TractionPatch> nodal_loads(const TetMesh& mesh, const contact::CondensedWall& wall,
                                       const contact::WireWallSolution& s) {
  const PhysicalGroup& inner = mesh.require_group("inner_wall", 2, "tube");
  std::vector<TractionPatch> loads;
  for (const int j : s.active) {
    const int node = wall.nodes()[static_cast<std::size_t>(j)];
    for (const int t : inner.elements) {
      const Triangle& tri = mesh.triangles[static_cast<std::size_t>(t)];
      int corner = -1;
      for (int k = 0; k < 3; ++k) {
        if (tri[k] == node) corner = k;
      }
      if (corner < 0) continue;
      TractionPatch p;
      p.triangles = {t};
      SurfacePoint q;
      q.triangle = t;
      q.barycentric[corner] = 1.0;
      q.weight = 1.0;
      p.points = {q};
      p.traction = s.force[j] * wall.directions()[static_cast<std::size_t>(j)];
      p.area = 1.0;
      loads.push_back(p);
      break;
    }
  }
  return loads;
}

struct CoupledRun {
  contact::WireWallSolution solution;
  contact::ContactWire wire;  ///< its centreline nodes and radius (no form: the rod is gone)
  Vec3 clamp = Vec3::Zero();
  double rigid_force = 0.0;
  /// The wire's compliance at its rigid contact, m/N: −dc/dF with the rigid wall moved out by
  /// ±1e-8 m (central difference on the same discrete wire).
  double wire_compliance = 0.0;
  /// The wall's compliance under the contact forces, m/N: λᵀWλ/F² (F = Σλ).
  double wall_compliance = 0.0;
  double total = 0.0;    ///< Σλ, N
  Eigen::VectorXd dent;  ///< Wλ per candidate, m
  double setup_seconds = 0.0;
};

/// The wire (diameter d, N segments, the reference's length for z_c = 20 mm) in the tube of wall
/// modulus E, candidates within 4 mm and 60° of the aimed node.
CoupledRun coupled_run(const TetMesh& mesh, const Vec3& target, const std::vector<int>& nodes,
                       double young, double diameter, int segments, double length_factor);

CoupledRun coupled_run(double young, double diameter, int segments, double length_factor = 1.0) {
  const TetMesh& mesh = tube_mesh();
  const Vec3 target = mesh.nodes[aim_node(mesh)];
  return coupled_run(mesh, target, band(mesh, target.z(), 4e-3, 1.05), young, diameter, segments,
                     length_factor);
}

/// The wire aimed at `target` on the wall (its tip at z_c = 20 mm from the clamp), candidates
/// `nodes`.
CoupledRun coupled_run(const TetMesh& mesh, const Vec3& target, const std::vector<int>& nodes,
                       double young, double diameter, int segments, double length_factor) {
  const double c = kA - diameter / 2;
  const double length =
      length_factor * rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(diameter, length, segments, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  const fem::ElasticitySolver solver(mesh, wall_problem(young));
  const contact::CondensedWall wall(solver.free_displacement_system(), nodes,
                                    contact::into_wall_directions(mesh, nodes, "inner_wall"));
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const Vec3 radial = Vec3(tip.x(), tip.y(), 0).normalized();
  const int first = nearest_candidate(mesh, nodes, tip + w.radius * radial);
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  CoupledRun run;
  run.solution = contact::solve_wire_wall_contact(w.contact(), wall, mesh, rigid.x, {first}, o);
  run.clamp = contact::clamp_reaction(w.contact(), wall, mesh, run.solution);
  run.wire = w.contact();
  run.wire.form = nullptr;
  run.rigid_force = rigid.force;
  run.setup_seconds = wall.setup_seconds();
  run.total = run.solution.force.sum();
  run.wall_compliance =
      run.solution.force.dot(wall.compliance() * run.solution.force) / (run.total * run.total);
  run.dent = wall.compliance() * run.solution.force;
  constexpr double kShift = 1e-8;
  run.wire_compliance = 2 * kShift / (rigid_run(w, -kShift).force - rigid_run(w, kShift).force);
  return run;
}

}  // namespace

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
  const contact::CondensedWall wall(condensing.free_displacement_system(), nodes,
                                    contact::into_wall_directions(mesh, nodes, "inner_wall"));
  p.patches = nodal_loads(mesh, wall, s);
  ASSERT_EQ(p.patches.size(), s.active.size());
  fem::ElasticitySolver solver(mesh, p);
  const fem::ElasticityResult& r = solver.solve();
  Vec3 supports = Vec3::Zero();
  for (const fem::GroupReaction& g : r.reactions) supports += g.force;
  const Vec3 on_wall = s.total_force_on_wall(wall);
  const Vec3 sum = run.clamp + supports;
  std::printf(
      "WIRE-WALL action-reaction E=%.3g Pa: %zu in contact, force on wall (%.6e, %.6e, "
      "%.6e) N, clamp + supports |%.3e| N (%.2e relative), %d active-set changes, %d "
      "Newton, %.3f s\n",
      young, s.active.size(), on_wall.x(), on_wall.y(), on_wall.z(), sum.norm(),
      sum.norm() / on_wall.norm(), s.active_set_changes, s.newton_iterations, s.seconds);
  EXPECT_LT(sum.norm(), 1e-9 * on_wall.norm());
  const Eigen::VectorXd along = wall.compliance() * s.force;
  double dent = 0.0;
  for (const int j : s.active) {
    const Vec3 u = r.nodal_displacement[static_cast<std::size_t>(wall.nodes()[j])];
    EXPECT_NEAR(u.dot(wall.directions()[j]), along[j], 1e-9 * along.cwiseAbs().maxCoeff());
    dent = std::max(dent, along[j]);
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
  VesselParams p;
  p.length = kTubeLength;
  const Vec3 target(kA, 0, 25e-3);
  const auto t0 = std::chrono::steady_clock::now();
  const TetMesh mesh = refined_patch_mesh(p, target, 0.08e-3, 1.0e-3);
  const double mesh_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  constexpr double kBand = 1.6e-3;
  std::vector<int> nodes;
  for (const int n : inner_nodes(mesh)) {
    if ((mesh.nodes[n] - target).norm() < kBand) nodes.push_back(n);
  }
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
  const contact::CondensedWall wall(condensing.free_displacement_system(), nodes,
                                    contact::into_wall_directions(mesh, nodes, "inner_wall"));
  problem.patches = nodal_loads(mesh, wall, s);
  fem::ElasticitySolver solver(mesh, problem);
  Vec3 supports = Vec3::Zero();
  for (const fem::GroupReaction& g : solver.solve().reactions) supports += g.force;
  const Vec3 sum = run.clamp + supports;
  std::printf("WIRE-WALL line contact: clamp + supports |%.3e| N (%.2e of the force)\n", sum.norm(),
              sum.norm() / run.total);
  EXPECT_LT(sum.norm(), 1e-9 * run.total);
  // No inner-wall node outside the candidates is inside the wire (the wall's whole displacement).
  const std::vector<Vec3> u = wall.displacement(s.force);
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

/// The largest principal strain magnitude over the mesh's tets (P1 gradient of u): the small
/// strain's and the Green–Lagrange strain's, ½(H + Hᵀ) and ½(H + Hᵀ + HᵀH).
struct WallStrain {
  double small = 0.0, green = 0.0;
};
WallStrain largest_strain(const TetMesh& mesh, const std::vector<Vec3>& u) {
  WallStrain out;
  for (const Tet& t : mesh.tets) {
    Eigen::Matrix3d dX, dU;
    for (int k = 0; k < 3; ++k) {
      dX.col(k) = mesh.nodes[t[k + 1]] - mesh.nodes[t[0]];
      dU.col(k) = u[t[k + 1]] - u[t[0]];
    }
    const Eigen::Matrix3d H = dU * dX.inverse();
    const Eigen::Matrix3d e = 0.5 * (H + H.transpose());
    const Eigen::Matrix3d E = e + 0.5 * H.transpose() * H;
    out.small = std::max(
        out.small,
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(e).eigenvalues().cwiseAbs().maxCoeff());
    out.green = std::max(
        out.green,
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(E).eigenvalues().cwiseAbs().maxCoeff());
  }
  return out;
}

// The line of contact on a wall of 30 × 14.24 kPa, where the dent is twice r_w, solved directly
// with the band grown: Signorini's conditions, action = reaction against the wall's total force,
// no inner-wall node outside the candidates inside the wire; the dent against r_w and the wall's
// strains are printed (the linear wall is the model here: whether it is valid at that dent is
// the neo-Hookean reference's question).
TEST(WireWallContact, LineOfContactOnASofterWall) {
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
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const int first =
      nearest_candidate(mesh, nodes, tip + w.radius * Vec3(tip.x(), tip.y(), 0).normalized());
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  const contact::GrownContact grown = contact::solve_wire_wall_contact_growing(
      w.contact(), solver.free_displacement_system(), mesh, nodes, rigid.x, {first}, o);
  const contact::WireWallSolution& s = grown.solution;
  const Eigen::VectorXd dents = grown.wall->compliance() * s.force;
  double dent = 0;
  for (const int j : s.active) dent = std::max(dent, dents[j]);
  const std::vector<Vec3> u = grown.wall->displacement(s.force);
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
  EXPECT_LT((clamp - s.total_force_on_wall(*grown.wall)).norm(), 1e-9 * total);
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
  VesselParams p;
  p.length = kTubeLength;
  const Vec3 target(kA, 0, 25e-3);
  const TetMesh mesh = refined_patch_mesh(p, target, 0.08e-3, 1.0e-3);
  auto within = [&](double radius) {
    std::vector<int> out;
    for (const int n : inner_nodes(mesh)) {
      if ((mesh.nodes[n] - target).norm() < radius) out.push_back(n);
    }
    return out;
  };
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
  const contact::CondensedWall wall(solver.free_displacement_system(), cand,
                                    contact::into_wall_directions(mesh, cand, "inner_wall"));
  contact::ContactWire w;
  w.form = &corde;
  w.constraints = &corde;
  w.fixed = corde.clamp_fixed();
  w.num_nodes = corde.num_nodes();
  w.first_node = der.layout.first_node;
  w.last_node = der.layout.tip_node;
  w.radius = d / 2;
  w.project = [&corde](Eigen::VectorXd& y) { corde.normalise_quaternions(y); };
  contact::WireWallOptions o;
  o.force_scale = der.EI / (kZc * kZc);
  o.constraint_tolerance = 1e-13;
  const contact::WireWallSolution s = contact::solve_wire_wall_contact(w, wall, mesh, x, {}, o);
  const double total = s.force.sum();
  const double scaled = total * kZc * kZc / der.EI;
  const Vec3 sum = contact::clamp_reaction(w, wall, mesh, s) - s.total_force_on_wall(wall);
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
  const contact::CondensedWall wall(solver.free_displacement_system(), cand,
                                    contact::into_wall_directions(mesh, cand, "inner_wall"));
  const Wire w(0.356e-3, 20e-3, 8, Vec3(0, 0, 5e-3));
  contact::ContactWire bad = w.contact();
  bad.radius = 0.0;
  EXPECT_THROW(contact::solve_wire_wall_contact(bad, wall, mesh, w.rod.rest_state(), {}),
               std::invalid_argument);
  bad = w.contact();
  bad.last_node = bad.num_nodes;
  EXPECT_THROW(contact::solve_wire_wall_contact(bad, wall, mesh, w.rod.rest_state(), {}),
               std::invalid_argument);
  // A candidate that is not a node of the inner wall has no direction.
  EXPECT_THROW(
      contact::into_wall_directions(mesh, {static_cast<int>(mesh.nodes.size())}, "inner_wall"),
      InputError);
}
