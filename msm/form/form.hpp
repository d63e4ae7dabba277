#pragma once
/// The one interface every mass-spring variant offers on a flat vector of positions
/// x = (x0, y0, z0, x1, ...) (PolyFEM's Form, ipc-toolkit's Potential): energy, gradient, sparse
/// Hessian, plus optional velocity-dependent damping. Solvers work on this, not on one model.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

namespace vessel::msm {

using Eigen::VectorXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

class Form {
 public:
  virtual ~Form() = default;
  /// Number of degrees of freedom (3 × nodes for the mass-spring models; the rods of msm/rods
  /// append their frames' dofs after the 3 × nodes positions: a twist angle per edge for DER, a
  /// quaternion per edge for CORDE).
  [[nodiscard]] virtual int num_dofs() const = 0;
  /// Potential energy at x, J.
  [[nodiscard]] virtual double energy(const VectorXd& x) const = 0;
  /// ∂E/∂x, N (resized to num_dofs).
  virtual void gradient(const VectorXd& x, VectorXd& g) const = 0;
  /// Both in one call; returns the energy, the same value energy(x) returns. Default: the two
  /// calls; a Form whose kernel makes both in one pass (SpringModel) overrides it.
  virtual double energy_gradient(const VectorXd& x, VectorXd& g) const {
    gradient(x, g);
    return energy(x);
  }
  /// ∂²E/∂x², N/m, as a sparse symmetric matrix with a pattern that does not depend on x (so a
  /// symbolic factorisation can be reused). With project_psd, each element's block is projected
  /// onto the positive semi-definite cone.
  virtual void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const = 0;
  /// Velocity-dependent (damping) force at (x, v), N. Default: none.
  virtual void damping_force(const VectorXd& x, const VectorXd& v, VectorXd& f) const {
    (void)x;
    (void)v;
    f.setZero(num_dofs());
  }
  /// −∂f_damping/∂v (N·s/m), same pattern as the Hessian. Default: zero.
  virtual void damping_jacobian(const VectorXd& x, SparseMatrix& D) const {
    hessian(x, D, false);
    D *= 0.0;
  }
};

/// A model with its loads, masses and boundary conditions: what the solvers need.
struct Problem {
  const Form* form = nullptr;
  VectorXd rest;            ///< rest positions x0, m
  VectorXd external_force;  ///< constant nodal loads f_ext, N (per dof)
  VectorXd mass;            ///< lumped mass per dof, kg
  std::vector<char> fixed;  ///< per dof: held at its rest position

  [[nodiscard]] int num_dofs() const { return static_cast<int>(rest.size()); }
  /// Total potential energy Π(x) = E(x) − f_ext·(x − x0), J.
  [[nodiscard]] double potential(const VectorXd& x) const {
    return form->energy(x) - external_force.dot(x - rest);
  }
  /// ∇Π on the free dofs (zero on fixed ones), N.
  void potential_gradient(const VectorXd& x, VectorXd& g) const {
    form->gradient(x, g);
    g -= external_force;
    for (int i = 0; i < g.size(); ++i) {
      if (fixed[i]) g[i] = 0.0;
    }
  }
};

/// Replaces the rows and columns of fixed dofs by those of the identity, keeping the pattern.
void apply_dirichlet(SparseMatrix& A, const std::vector<char>& fixed);

}  // namespace vessel::msm
