#pragma once
/// Equality constraints c(x) = 0 on a Form's dofs (the rods' inextensibility and frame
/// constraints, active contacts), for the constrained Newton of msm/rods.
#include "msm/form/form.hpp"

namespace vessel::msm {

/// Equality constraints c(x) = 0 on a Form's dofs.
class EqualityConstraints {
 public:
  virtual ~EqualityConstraints() = default;
  [[nodiscard]] virtual int num_constraints() const = 0;
  virtual void evaluate(const VectorXd& x, VectorXd& c) const = 0;
  /// ∂c/∂x (rows: constraints).
  virtual void jacobian(const VectorXd& x, SparseMatrix& J) const = 0;
  /// Σ_k λ_k ∇²c_k(x).
  virtual void weighted_hessian(const VectorXd& x, const VectorXd& lambda, SparseMatrix& H) const = 0;
};

}  // namespace vessel::msm
