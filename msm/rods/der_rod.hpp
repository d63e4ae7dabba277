#pragma once
/// Discrete Elastic Rods (Bergou, Wardetzky, Robinson, Audoly, Grinspun, SIGGRAPH 2008) for an
/// isotropic section, as a Form. Dofs: the node positions (x, y, z per node, ghost nodes
/// included), then one twist angle θ_j per edge (its material frame's angle from the reference
/// frame). Energy:
///   stretching  Σ_j ½ EA_j l_j (|e_j|/l_j − 1)²,
///   bending     Σ_i EI_i/(2 l̄_i) |κb_i|²,  κb_i = 2 e_{i−1}×e_i / (|e_{i−1}||e_i| + e_{i−1}·e_i),
///   twisting    Σ_i GJ_i/(2 l̄_i) (θ_i − θ_{i−1} + m_ref,i)²,
/// l̄_i the vertex's material Voronoi length (half a segment at a clamp), m_ref,i the reference
/// twist between the reference frames, which are carried from the last update_reference by
/// parallel transport in time (Bergou 2008 §4.2; 2010 "discrete viscous threads" §A).
/// Rest: straight and untwisted.
#include <vector>

#include "msm/rods/rod.hpp"

namespace vessel::msm::rods {

class DerRod : public Rod {
 public:
  explicit DerRod(RodLayout layout);

  [[nodiscard]] int num_dofs() const override;
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;

  /// Index of edge j's twist angle in x.
  [[nodiscard]] int twist_dof(int edge) const { return 3 * num_nodes() + edge; }
  /// The rest state: rest positions, zero twist angles.
  [[nodiscard]] VectorXd rest_state() const override;
  /// Held dofs of the clamps: the ghost nodes, the clamp nodes and the ghost edges' angles.
  [[nodiscard]] std::vector<char> clamp_fixed() const override;
  /// Lumped masses per dof: ρA per half segment at the nodes, ρJ l̄ on the twist angles.
  [[nodiscard]] VectorXd lumped_mass() const override;
  /// Carries the reference frames to the edges of x by parallel transport (leaves the energy at
  /// x unchanged). Call between load steps or time steps so the frames never need a transport
  /// through a half turn.
  void update_reference(const VectorXd& x);
  /// Rod's hook: update_reference.
  void prepare(const VectorXd& x) override { update_reference(x); }

 private:
  std::vector<Eigen::Vector3d> ref_t_;  ///< tangent of each edge when its frame was stored
  std::vector<Eigen::Vector3d> ref_u_;  ///< reference director u_j ⟂ ref_t_j
};

/// Parallel transport of u from unit tangent a to unit tangent b (rotation about a×b).
Eigen::Vector3d parallel_transport(const Eigen::Vector3d& u, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b);

}  // namespace vessel::msm::rods
