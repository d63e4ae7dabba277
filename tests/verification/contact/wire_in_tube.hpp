#pragma once
// The wire in the straight tube, shared by the wire–wall contact tests: the set-up of the
// straight-tube reference (guidewire_notes.md, fem_reference/rod_theory/tube_contact.hpp), a
// 0.356 mm nitinol wire clamped on the axis of a 3 mm tube, tilted by 0.3 rad towards the wall,
// its tip bearing on the wall at z_c = 20 mm; the wall as a deal.II elasticity problem; the
// coupled solve's run and the wall's largest strain.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "fem_reference/rod_theory/tube_contact.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rigid_wall.hpp"
#include "verification/contact/wire_wall_contact.hpp"

namespace vessel::wire_in_tube {

const msm::rods::RodMaterial kNitinol{48e9, 48e9 / 2.66, 6450.0};
constexpr double kA = 3e-3;         // lumen radius, m
constexpr double kTheta = 0.3;      // clamp tilt, rad
constexpr double kZc = 20e-3;       // the reference's contact distance, m
constexpr double kWallE = 14.24e3;  // the scenes' wall modulus, Pa
constexpr double kTubeLength = 30e-3;

/// The structured straight tube (axis z, 0 ≤ z ≤ 30 mm, a = 3 mm, t = 1 mm), level 0.
inline const TetMesh& tube_mesh() {
  static const TetMesh mesh = [] {
    VesselParams p;
    p.length = kTubeLength;
    p.style = MeshStyle::structured;
    p.level = 0;
    return generate_vessel_mesh(p);
  }();
  return mesh;
}

inline std::vector<int> inner_nodes(const TetMesh& mesh) {
  return mesh.group_nodes(mesh.require_group("inner_wall", 2, "tube"));
}

/// The inner-wall node on the +x line (y = 0) nearest z = 25 mm: where the tip is aimed, so the
/// tip's hemisphere meets the faceted wall at one of its nodes (which lie on the exact cylinder).
inline int aim_node(const TetMesh& mesh) {
  int best = -1;
  for (const int n : inner_nodes(mesh)) {
    const Vec3& x = mesh.nodes[n];
    if (std::abs(x.y()) > 1e-9 || x.x() < 0) continue;
    if (best < 0 || std::abs(x.z() - 25e-3) < std::abs(mesh.nodes[best].z() - 25e-3)) best = n;
  }
  return best;
}

inline fem::ElasticityProblem wall_problem(double young) {
  fem::ElasticityProblem p;
  p.material.youngs_modulus = young;
  p.material.poisson_ratio = 0.45;
  p.options.degree = 1;
  p.dirichlet = {fem::DirichletCondition::clamped("inlet"),
                 fem::DirichletCondition::clamped("outlet")};
  return p;
}

/// Where the tilted wire's tip is aimed on the line-of-contact set-up: the +x inner wall at z = 25 mm.
inline const Vec3 kAimPoint(kA, 0, 25e-3);

/// The line-of-contact tube: 30 mm, gmsh's mesh refined to 0.08 mm within 1 mm of kAimPoint.
inline TetMesh line_of_contact_mesh() {
  VesselParams p;
  p.length = kTubeLength;
  return refined_patch_mesh(p, kAimPoint, 0.08e-3, 1.0e-3);
}

/// Candidates: the inner-wall nodes within `radius` (m) of `point`.
inline std::vector<int> nodes_within(const TetMesh& mesh, const Vec3& point, double radius) {
  std::vector<int> out;
  for (const int n : inner_nodes(mesh)) {
    if ((mesh.nodes[n] - point).norm() < radius) out.push_back(n);
  }
  return out;
}

/// Candidates: inner-wall nodes within `half_length` of z along the axis and `half_angle` of +x.
inline std::vector<int> band(const TetMesh& mesh, double z, double half_length, double half_angle) {
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
  Wire(double diameter, double length, int segments, const Vec3& origin,
       const msm::rods::RodMaterial& material = kNitinol)
      : layout([&] {
          msm::rods::RodSpec s = msm::rods::uniform_rod(material, length, diameter, segments);
          s.origin = origin;
          s.direction = Vec3(std::sin(kTheta), 0.0, std::cos(kTheta));
          return msm::rods::make_layout(s);
        }()),
        rod(layout),
        EI(msm::rods::solid_section(material, diameter).EI),
        radius(diameter / 2) {}
  [[nodiscard]] contact::ContactWire contact() const { return contact::contact_wire(rod, radius); }
};

/// The same wire against the exact rigid cylinder (msm/rods/rigid_wall): its contact force, N.
struct RigidRun {
  Eigen::VectorXd x;
  double force = 0.0;
};
inline RigidRun rigid_run(Wire& w, double wall_shift = 0.0) {
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
inline int nearest_candidate(const TetMesh& mesh, const std::vector<int>& nodes,
                             const Vec3& point) {
  int best = 0;
  for (int j = 1; j < static_cast<int>(nodes.size()); ++j) {
    if ((mesh.nodes[nodes[j]] - point).norm() < (mesh.nodes[nodes[best]] - point).norm()) best = j;
  }
  return best;
}

/// The contact forces as nodal loads for a second FEM solve (deal.II's own assembly): each active
/// candidate's λ n as a point at its node of an inner-wall triangle.
inline std::vector<TractionPatch> nodal_loads(const TetMesh& mesh,
                                              const contact::CondensedWall& wall,
                                              const contact::WireWallSolution& s) {
  const PhysicalGroup& inner = mesh.require_group("inner_wall", 2, "tube");
  std::vector<TractionPatch> loads;
  for (const int j : s.active) {
    const int node = wall.nodes()[3 * static_cast<std::size_t>(j)];
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
      p.traction = s.force[j] * s.direction[static_cast<std::size_t>(j)];
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
inline CoupledRun coupled_run(const TetMesh& mesh, const Vec3& target,
                              const std::vector<int>& nodes, double young, double diameter,
                              int segments, double length_factor);

inline CoupledRun coupled_run(double young, double diameter, int segments,
                              double length_factor = 1.0) {
  const TetMesh& mesh = tube_mesh();
  const Vec3 target = mesh.nodes[aim_node(mesh)];
  return coupled_run(mesh, target, band(mesh, target.z(), 4e-3, 1.05), young, diameter, segments,
                     length_factor);
}

/// The wire aimed at `target` on the wall (its tip at z_c = 20 mm from the clamp), candidates
/// `nodes`.
inline CoupledRun coupled_run(const TetMesh& mesh, const Vec3& target,
                              const std::vector<int>& nodes, double young, double diameter,
                              int segments, double length_factor) {
  const double c = kA - diameter / 2;
  const double length =
      length_factor * rod_theory::straight_tube_contact(kTheta, c / kZc).length * kZc;
  Wire w(diameter, length, segments, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  const fem::ElasticitySolver solver(mesh, wall_problem(young));
  const contact::ComponentCandidates all = contact::every_component(nodes);
  const contact::CondensedWall wall(solver.free_displacement_system(), all.nodes, all.directions);
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const Vec3 radial = Vec3(tip.x(), tip.y(), 0).normalized();
  const int first = nearest_candidate(mesh, nodes, tip + w.radius * radial);
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  CoupledRun run;
  run.solution = contact::solve_wire_wall_contact(
      w.contact(), wall, contact::into_wall_directions(mesh, nodes, "inner_wall"), mesh, rigid.x,
      {first}, o);
  run.clamp = contact::clamp_reaction(w.contact(), wall, mesh, run.solution);
  run.wire = w.contact();
  run.wire.form = nullptr;
  run.rigid_force = rigid.force;
  run.setup_seconds = wall.setup_seconds();
  run.total = run.solution.force.sum();
  const Eigen::VectorXd loads = run.solution.wall_loads();
  const Eigen::VectorXd u = wall.compliance() * loads;
  run.wall_compliance = loads.dot(u) / (run.total * run.total);
  run.dent.resize(run.solution.force.size());
  for (Eigen::Index j = 0; j < run.dent.size(); ++j) run.dent[j] = u.segment<3>(3 * j).norm();
  constexpr double kShift = 1e-8;
  run.wire_compliance = 2 * kShift / (rigid_run(w, -kShift).force - rigid_run(w, kShift).force);
  return run;
}

using contact::largest_strain;
using contact::WallStrain;

}  // namespace vessel::wire_in_tube
