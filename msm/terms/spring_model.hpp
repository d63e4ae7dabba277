#pragma once
/// The spring model: a Form over a SpringNetwork (any family mix, Hooke or bilinear springs),
/// with axial (seed 000 eq. 3.4) and point (eq. 3.3) damping. Energy and gradient run on the
/// node-centric kernel (kernels/node_springs.hpp); the Hessian adds one 3×3 block per spring (spring_hessian's
/// formula) into a fixed pattern; damping uses the per-spring kernel (kernels/spring_kernels.hpp),
/// which reference_energy/gradient/hessian keep callable as the reference.
#include <string>

#include "meshes/tet_mesh.hpp"
#include "msm/kernels/node_springs.hpp"
#include "msm/form/form.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

class SpringModel : public Form {
 public:
  /// point_damping: k_v of seed 000 eq. (3.3), N·s/m per node. The force pass uses
  /// spring_kernel_threads() threads (set_threads changes it for this model).
  explicit SpringModel(const SpringNetwork& network, double point_damping = 0.0);

  [[nodiscard]] int num_dofs() const override { return 3 * num_nodes_; }
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  double energy_gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;
  void damping_force(const VectorXd& x, const VectorXd& v, VectorXd& f) const override;
  void damping_jacobian(const VectorXd& x, SparseMatrix& D) const override;

  [[nodiscard]] const std::vector<Spring>& springs() const { return springs_; }
  /// Threads of this model's energy and gradient pass (its own setting; set_solver_threads does
  /// not change it). InputError if n < 1.
  void set_threads(int n);
  [[nodiscard]] int threads() const { return kernel_.threads(); }
  /// The same energy and gradient by the per-spring reference kernel, one spring at a time
  /// (spring_energy / spring_gradient), single-threaded: the fast paths' check and benchmark.
  [[nodiscard]] double reference_energy(const VectorXd& x) const;
  void reference_gradient(const VectorXd& x, VectorXd& g) const;
  /// The Hessian assembled from spring_hessian's 6×6 blocks (hessian() builds each spring's 3×3
  /// block once and adds it with its signs into the same pattern).
  void reference_hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const;
  /// Largest strain |L − l|/l over the springs at x.
  [[nodiscard]] double max_strain(const VectorXd& x) const;

 private:
  /// Adds each spring's 6×6 block (from `block(spring)`) into H, whose pattern is fixed once.
  void require_size(const VectorXd& x) const;  ///< std::invalid_argument unless 3·nodes values
  template <class BlockFn>
  void assemble(SparseMatrix& H, double diagonal, BlockFn block) const;

  int num_nodes_ = 0;
  std::vector<Spring> springs_;
  double point_damping_ = 0.0;
  std::vector<Vec3> rest_nodes_;     ///< rest positions (the kernel's node order), m
  NodeSprings kernel_;                 ///< the springs laid out for the node-centric kernel
  std::vector<int> damped_;          ///< springs with axial damping k_d ≠ 0
  SparseMatrix pattern_;             ///< the Hessian's sparsity pattern (values zero)
  std::vector<int> slots_;           ///< per spring, 36 indices into pattern_'s value array
  std::vector<int> diagonal_slots_;  ///< per dof, its diagonal entry
};

/// Flattens node positions to (x0, y0, z0, x1, ...).
VectorXd flatten(const std::vector<Vec3>& nodes);

/// Builds the Problem of a network: rest = its nodes, masses per node (kg) repeated per dof,
/// external nodal loads (N) given on the TetMesh's nodes and mapped through source_node (loads on
/// mesh nodes absent from the network are moved to the nearest network node), and the nodes whose
/// source node lies in the named surface groups fixed.
Problem make_problem(const Form& form, const SpringNetwork& net, const std::vector<double>& masses,
                     const TetMesh& mesh, const std::vector<Vec3>& mesh_loads,
                     const std::vector<std::string>& fixed_groups);

}  // namespace vessel::msm
