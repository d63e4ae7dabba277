#pragma once
/// A linear wall as a potential on a band of its nodes: the wire-wall potential
/// (wire_wall_potential.hpp) on the wall condensed on the contact candidates, so the Newton matrix
/// holds 3 rows per band node instead of the whole wall's.
///
/// For a linear wall loaded only on the band B, the energy of the displacement field that takes
/// the values u_B on B and minimises ½vᵀKv elsewhere is ½u_Bᵀ S u_B, S = W⁻¹ the Schur complement
/// of K on B's components (W the wall's compliance on them, as CondensedWall's on every_component):
/// minimising Π over (x, u_B) is minimising it over (x, v) with no load off the band. The whole
/// field follows from the band's forces S u_B by one back-solve.
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <array>
#include <memory>
#include <vector>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/elasticity.hpp"
#include "meshes/tet_mesh.hpp"
#include "verification/contact/wire_wall_contact.hpp"
#include "verification/contact/wire_wall_potential.hpp"

namespace vessel::contact {

/// The linear wall ½u_BᵀS u_B on the displacements of the band's nodes (rows 3k, 3k+1, 3k+2 for
/// band node k; every other node held, its displacement the condensed field's). K is factorised
/// once; a growth solves only the new nodes' columns of W.
class CondensedLinearWall final : public WallPotential {
 public:
  /// `system`: the wall's free displacement system (homogeneous supports). InputError for a band
  /// node not in the mesh, given twice or with a component held by a support.
  CondensedLinearWall(fem::FreeDisplacementSystem system, const std::vector<int>& band);
  ~CondensedLinearWall() override;
  /// Adds nodes to the band (the same errors): 3 back-solves per node, W's old block kept.
  void grow(const std::vector<int>& added);
  [[nodiscard]] int num_dofs() const override { return static_cast<int>(3 * band_.size()); }
  [[nodiscard]] const std::vector<std::array<int, 3>>& node_rows() const override {
    return node_rows_;
  }
  double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd* gradient,
                  Eigen::SparseMatrix<double>* hessian, bool project_psd = false) const override;
  /// Small strain of the whole field.
  [[nodiscard]] double largest_strain(const TetMesh& mesh, const Eigen::VectorXd& u) const override;
  /// The whole wall's displacement per mesh node (m; zero where held): the field the band's
  /// forces S u give.
  [[nodiscard]] std::vector<Vec3> nodal(const Eigen::VectorXd& u) const override;
  [[nodiscard]] const std::vector<int>& band() const { return band_; }
  /// The band's rows of a whole-wall field given per mesh node.
  [[nodiscard]] Eigen::VectorXd band_rows(const std::vector<Vec3>& field) const;
  /// Seconds spent factorising K, solving for W and inverting it, over every growth.
  [[nodiscard]] double setup_seconds() const { return setup_seconds_; }

 private:
  fem::FreeDisplacementSystem system_;
  std::unique_ptr<fem::CholmodFactor> factor_;
  std::vector<int> band_;
  std::vector<std::array<int, 3>> node_rows_;
  Eigen::MatrixXd compliance_;  ///< W, m/N
  Eigen::MatrixXd stiffness_;   ///< S = W⁻¹, N/m
  Eigen::SparseMatrix<double> sparse_stiffness_;
  double setup_seconds_ = 0.0;
};

struct GrownPotentialContact {
  /// Its u: the final band's rows (wall->nodal(u) the whole field); Newton steps, factorisations
  /// and seconds summed over every growth.
  PotentialContactSolution solution;
  std::unique_ptr<CondensedLinearWall> wall;  ///< on the final band
  int rounds = 0;                             ///< growths
};

/// solve_wire_wall_potential on `wall` (every band node a candidate), the band grown in place as
/// BandGrowth says (solve_wire_wall_potential_growing), from the wire's `start` and the wall's
/// whole field `field` (per mesh node, m; the solve starts from its band rows): the last solve,
/// its u on the wall's final band, its Newton steps, factorisations and seconds summed over every
/// growth; `rounds` the growths. An insertion keeps its wall (and its band) from step to step.
PotentialContactSolution solve_on_growing_band(msm::rods::Rod& rod, double radius,
                                               CondensedLinearWall& wall, const TetMesh& mesh,
                                               const Eigen::VectorXd& start,
                                               std::vector<Vec3> field,
                                               const PotentialContactOptions& options,
                                               const BandGrowth& growth, int& rounds);

/// solve_wire_wall_potential on the wall condensed on `band` (every band node a candidate), the
/// band grown as BandGrowth says (a pressed node on its edge brings its surface neighbours, a
/// surface node outside it within `margin` of the wire's surface joins; a solve that stops with
/// the wire through the wall beyond the band brings the nodes within `crossing_reach` of the
/// crossing, one through the band's own triangles is rethrown) and the
/// contact re-solved from the last equilibrium (the wire's state, the band's displacements from
/// the whole field) until nothing joins. std::runtime_error after growth.max_rounds growths that
/// still add nodes; solve_wire_wall_potential's errors.
GrownPotentialContact solve_wire_wall_potential_growing(
    msm::rods::Rod& rod, double radius, const fem::FreeDisplacementSystem& system,
    const TetMesh& mesh, const std::vector<int>& band, const Eigen::VectorXd& start,
    const PotentialContactOptions& options = {}, const BandGrowth& growth = {});

}  // namespace vessel::contact
