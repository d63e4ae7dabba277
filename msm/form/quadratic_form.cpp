#include "msm/form/quadratic_form.hpp"

#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

QuadraticForm::QuadraticForm(SparseMatrix K, VectorXd x0) : K_(std::move(K)), x0_(std::move(x0)) {
  if (K_.rows() != K_.cols() || K_.rows() != x0_.size()) {
    throw InputError("quadratic form: stiffness of " + std::to_string(K_.rows()) + " x " +
                     std::to_string(K_.cols()) + " for a state of " +
                     std::to_string(x0_.size()) + " dofs; expected a square matrix of that size");
  }
  K_.makeCompressed();
}

double QuadraticForm::energy(const VectorXd& x) const {
  const VectorXd u = x - x0_;
  return 0.5 * u.dot(K_ * u);
}

void QuadraticForm::gradient(const VectorXd& x, VectorXd& g) const { g = K_ * (x - x0_); }

void QuadraticForm::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  (void)x;
  (void)project_psd;
  H = K_;
}

}  // namespace vessel::msm
