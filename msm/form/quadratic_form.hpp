#pragma once
/// A linear elastic body given by its stiffness matrix: E(x) = ½(x − x₀)ᵀK(x − x₀). Lets a linear
/// FEM system (fem::FreeDisplacementSystem: K and f on the free DoFs) run through the same
/// solvers and prepared updates (msm/solvers/updates.hpp) as the mass-spring models, so that the
/// harness times FEM and springs by one procedure.
#include "msm/form/form.hpp"

namespace vessel::msm {

class QuadraticForm final : public Form {
 public:
  /// K: symmetric (both triangles stored), N/m; x0: the state of zero energy, m. InputError if K
  /// is not square or its size differs from x0's.
  QuadraticForm(SparseMatrix K, VectorXd x0);
  [[nodiscard]] int num_dofs() const override { return static_cast<int>(x0_.size()); }
  /// ½(x − x₀)ᵀK(x − x₀), J.
  [[nodiscard]] double energy(const VectorXd& x) const override;
  /// K(x − x₀), N.
  void gradient(const VectorXd& x, VectorXd& g) const override;
  /// K whatever x; project_psd changes nothing (K is taken as given: a positive semi-definite
  /// FEM stiffness needs no projection).
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;

 private:
  SparseMatrix K_;
  VectorXd x0_;
};

}  // namespace vessel::msm
