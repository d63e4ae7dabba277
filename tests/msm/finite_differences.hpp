#pragma once
/// The one generic finite-difference helper used for every energy in the msm tests: central
/// differences of the energy give the gradient, central differences of the gradient give the
/// Hessian; both are compared with the analytic ones.
#include <Eigen/Dense>
#include <array>
#include <functional>

#include "msm/form/form.hpp"

namespace vessel::msm::test {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct DerivativeCheck {
  double gradient_error = 0.0;     ///< ‖g − g_fd‖ / max(‖g_fd‖, floor)
  double hessian_error = 0.0;      ///< ‖H − H_fd‖_F / max(‖H_fd‖_F, floor)
  double hessian_asymmetry = 0.0;  ///< ‖H − Hᵀ‖_F / max(‖H‖_F, floor)
};

/// Central differences of a scalar function: the gradient.
inline VectorXd fd_gradient(const std::function<double(const VectorXd&)>& f, const VectorXd& x,
                            double h) {
  VectorXd g(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    g[i] = (f(xp) - f(xm)) / (2 * h);
  }
  return g;
}

/// Central differences of a vector function: its Jacobian (column i = ∂g/∂x_i).
inline MatrixXd fd_jacobian(const std::function<VectorXd(const VectorXd&)>& g, const VectorXd& x,
                            double h) {
  MatrixXd J(g(x).size(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    VectorXd xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    J.col(i) = (g(xp) - g(xm)) / (2 * h);
  }
  return J;
}

/// Central-difference check at x with step h (relative to the scale of x's entries).
inline DerivativeCheck check_derivatives(const std::function<double(const VectorXd&)>& energy,
                                         const std::function<VectorXd(const VectorXd&)>& gradient,
                                         const std::function<MatrixXd(const VectorXd&)>& hessian,
                                         const VectorXd& x, double h) {
  const VectorXd g_fd = fd_gradient(energy, x, h);
  const MatrixXd H_fd = fd_jacobian(gradient, x, h);
  const VectorXd g = gradient(x);
  const MatrixXd H = hessian(x);
  DerivativeCheck c;
  c.gradient_error = (g - g_fd).norm() / std::max(g_fd.norm(), 1e-30);
  c.hessian_error = (H - H_fd).norm() / std::max(H_fd.norm(), 1e-30);
  c.hessian_asymmetry = (H - H.transpose()).norm() / std::max(H.norm(), 1e-30);
  return c;
}

/// The same check of one four-node element's kernel (a tet's or a hinge's energy, gradient and
/// 12×12 Hessian as functions of its four corners), at the corners stacked in x (12 values).
template <class Energy, class Gradient, class Hessian>
DerivativeCheck check_element_derivatives(Energy energy, Gradient gradient, Hessian hessian,
                                          const VectorXd& x, double h) {
  using Corners = std::array<Eigen::Vector3d, 4>;
  auto corners = [](const VectorXd& y) {
    return Corners{y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9)};
  };
  return check_derivatives([&](const VectorXd& y) { return energy(corners(y)); },
                           [&](const VectorXd& y) -> VectorXd { return gradient(corners(y)); },
                           [&](const VectorXd& y) -> MatrixXd { return hessian(corners(y)); }, x,
                           h);
}

/// The same check of a Form's energy, gradient and (unprojected, densified) Hessian.
inline DerivativeCheck check_form_derivatives(const Form& form, const VectorXd& x, double h) {
  return check_derivatives([&form](const VectorXd& y) { return form.energy(y); },
                           [&form](const VectorXd& y) -> VectorXd {
                             VectorXd g;
                             form.gradient(y, g);
                             return g;
                           },
                           [&form](const VectorXd& y) -> MatrixXd {
                             SparseMatrix H;
                             form.hessian(y, H, false);
                             return MatrixXd(H);
                           },
                           x, h);
}

}  // namespace vessel::msm::test
