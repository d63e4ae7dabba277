#pragma once
/// A rod's inputs (SI) and its discretisation shared by every rod model: a straight rest
/// centreline of one or more sections (a body and a tapered tip), clamped at its start and
/// optionally at its end. A clamp is a ghost edge outside the rod that carries the clamp's frame
/// and no material: the clamp's vertex then owns half a segment (the Voronoi length of its
/// material side only), which keeps the discretisation second order (a clamp owning a full
/// segment makes it first order).
#include <Eigen/Core>
#include <vector>

namespace vessel::msm::rods {

struct RodMaterial {
  double young = 0.0;    ///< E, Pa
  double shear = 0.0;    ///< G, Pa
  double density = 0.0;  ///< ρ, kg/m³
};

/// One section of the rod: solid circular, its diameter varying linearly from start to end.
struct RodSection {
  double length = 0.0;          ///< m
  double diameter_start = 0.0;  ///< m
  double diameter_end = 0.0;    ///< m (equal to diameter_start: a uniform section)
  int segments = 0;
};

struct RodSpec {
  RodMaterial material;
  std::vector<RodSection> sections;  ///< from the clamp to the tip
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< the clamp point, m
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< the clamp's tangent (unit)
  bool clamp_end = false;  ///< clamp the tip as well (a ghost edge beyond it)
};

/// Stiffnesses of a solid circular section of diameter d: EA, EI (= E π d⁴/64), GJ (J = 2I).
struct SectionStiffness {
  double EA = 0.0, EI = 0.0, GJ = 0.0, rhoA = 0.0, rhoJ = 0.0;
};
SectionStiffness solid_section(const RodMaterial& material, double diameter);

struct RodLayout {
  std::vector<Eigen::Vector3d> rest;  ///< node positions, ghost nodes included
  /// Edge j joins nodes j and j+1. Ghost edges (clamps) have no material.
  std::vector<char> ghost;
  std::vector<double> length;  ///< rest edge lengths, m
  std::vector<SectionStiffness> section;  ///< per edge, at its midpoint
  int first_node = 0;  ///< the clamp node (node 1); the ghost node before it is node 0
  int tip_node = 0;    ///< the free end's node (or the end clamp's node)
  bool clamp_end = false;
  Eigen::Vector3d normal;  ///< a unit vector normal to the rest centreline: the clamp's d1

  [[nodiscard]] int num_nodes() const { return static_cast<int>(rest.size()); }
  [[nodiscard]] int num_edges() const { return static_cast<int>(length.size()); }
  /// Material length at node i: half of each adjacent material edge (the Voronoi length), m.
  [[nodiscard]] double voronoi_length(int node) const;
  /// Length-weighted mean of a per-edge quantity over the material edges at node i.
  [[nodiscard]] double vertex_mean(int node, double SectionStiffness::*member) const;
  /// Lumped mass of node i, kg (half of each adjacent material edge).
  [[nodiscard]] double node_mass(int node) const;
  /// Total material length, m.
  [[nodiscard]] double total_length() const;
};

/// Discretises the spec. Throws InputError naming the key (e.g. "rod.sections[1].segments")
/// and what was expected for a non-positive modulus, density, length, diameter or count.
RodLayout make_layout(const RodSpec& spec);

/// A uniform rod: one section of length L, diameter d, N segments, clamped at the origin along x.
RodSpec uniform_rod(const RodMaterial& material, double length, double diameter, int segments);

}  // namespace vessel::msm::rods
