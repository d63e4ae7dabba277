#pragma once
/// A linear-elastic wall condensed on its contact candidates: the FEM reference's displacement
/// system K u = f (its supports held) factorised once, and per candidate (a mesh node with a unit
/// direction) the wall's displacement along every candidate's direction per unit force along its
/// own: the compliance W of contact::solve_signorini. One factorisation and one solve per
/// candidate; then any contact forces give the wall's whole displacement field by one more solve.
#include <Eigen/Dense>
#include <array>
#include <memory>
#include <vector>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/elasticity.hpp"
#include "meshes/tet_mesh.hpp"

namespace vessel::contact {

class CondensedWall {
 public:
  /// `system`: the wall's free displacement system (ElasticitySolver::free_displacement_system,
  /// homogeneous supports; its load f is ignored). `nodes`: the candidates' mesh nodes;
  /// `directions`: per candidate, the unit direction a contact force pushes the wall.
  /// std::invalid_argument on mismatched sizes or a candidate with every component held.
  CondensedWall(fem::FreeDisplacementSystem system, std::vector<int> nodes,
                std::vector<Vec3> directions);
  ~CondensedWall();

  /// W (m/N), symmetric positive definite: W_ij = d_i · u_i under a unit force d_j at node j.
  [[nodiscard]] const Eigen::MatrixXd& compliance() const { return compliance_; }
  /// The wall's displacement at every mesh node (m; zero where held) under the forces λ (N, one
  /// per candidate, along its direction).
  [[nodiscard]] std::vector<Vec3> displacement(const Eigen::VectorXd& forces) const;
  /// The candidates' mesh nodes and their unit directions, as given.
  [[nodiscard]] const std::vector<int>& nodes() const { return nodes_; }
  [[nodiscard]] const std::vector<Vec3>& directions() const { return directions_; }
  /// Seconds spent factorising K and solving for W's columns.
  [[nodiscard]] double setup_seconds() const { return setup_seconds_; }

 private:
  [[nodiscard]] Eigen::VectorXd load_vector(const Eigen::VectorXd& forces) const;
  fem::FreeDisplacementSystem system_;
  std::vector<int> nodes_;
  std::vector<Vec3> directions_;
  std::unique_ptr<fem::CholmodFactor> factor_;
  Eigen::MatrixXd compliance_;
  double setup_seconds_ = 0.0;
};

/// Per mesh node, its x, y, z entries of the row vector x (`node_rows` as
/// FreeDisplacementSystem's; zero where a component has no row).
std::vector<Vec3> per_node(const std::vector<std::array<int, 3>>& node_rows,
                           const Eigen::VectorXd& x);

/// Every displacement component of `nodes` as a candidate: candidate 3k + c is nodes[k] along the
/// unit axis e_c, so a CondensedWall on them holds the wall's full 3 × 3 compliance block per pair
/// of nodes (W_(3i+a)(3j+b) = u_i,a under a unit force e_b at node j).
struct ComponentCandidates {
  std::vector<int> nodes;
  std::vector<Vec3> directions;
};
ComponentCandidates every_component(const std::vector<int>& nodes);

/// The largest principal strain magnitudes over a wall's tets under the vertex displacements u
/// (m), from each tet's P1 gradient H = ∇u: the small strain ½(H + Hᵀ) and Green–Lagrange's
/// ½(H + Hᵀ + HᵀH). How far a linear wall's answer is beyond its small-strain range.
struct WallStrain {
  double small = 0.0;
  double green = 0.0;
};
WallStrain largest_strain(const TetMesh& mesh, const std::vector<Vec3>& u);

}  // namespace vessel::contact
