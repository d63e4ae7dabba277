#pragma once
/// The one generic finite-difference helper used for every energy in the msm tests: central
/// differences of the energy give the gradient, central differences of the gradient give the
/// Hessian; both are compared with the analytic ones.
#include <Eigen/Dense>
#include <functional>

namespace vessel::msm::test {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct DerivativeCheck {
  double gradient_error = 0.0;  ///< ‖g − g_fd‖ / max(‖g_fd‖, floor)
  double hessian_error = 0.0;   ///< ‖H − H_fd‖_F / max(‖H_fd‖_F, floor)
  double hessian_asymmetry = 0.0;  ///< ‖H − Hᵀ‖_F / max(‖H‖_F, floor)
};

/// Central-difference check at x with step h (relative to the scale of x's entries).
inline DerivativeCheck check_derivatives(const std::function<double(const VectorXd&)>& energy,
                                         const std::function<VectorXd(const VectorXd&)>& gradient,
                                         const std::function<MatrixXd(const VectorXd&)>& hessian,
                                         const VectorXd& x, double h) {
  const Eigen::Index n = x.size();
  VectorXd g_fd(n);
  MatrixXd H_fd(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    g_fd[i] = (energy(xp) - energy(xm)) / (2 * h);
    H_fd.col(i) = (gradient(xp) - gradient(xm)) / (2 * h);
  }
  const VectorXd g = gradient(x);
  const MatrixXd H = hessian(x);
  DerivativeCheck c;
  c.gradient_error = (g - g_fd).norm() / std::max(g_fd.norm(), 1e-30);
  c.hessian_error = (H - H_fd).norm() / std::max(H_fd.norm(), 1e-30);
  c.hessian_asymmetry = (H - H.transpose()).norm() / std::max(H.norm(), 1e-30);
  return c;
}

}  // namespace vessel::msm::test
