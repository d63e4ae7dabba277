#pragma once
/// A small limited-memory BFGS minimiser (Nocedal & Wright, "Numerical Optimization", 2nd ed.,
/// 2006: Algorithm 7.4, the two-loop recursion, with the initial Hessian scaling γ = sᵀy/yᵀy of
/// their eq. 7.20) and a backtracking line search on the Armijo (sufficient decrease) condition,
/// eq. 3.6a. A pair (s, y) with sᵀy ≤ ε·|s||y| is not stored (the curvature condition fails for
/// a backtracking step on a non-convex function), which keeps the implicit Hessian positive
/// definite. Used by the stiffness calibration (calibration/stiffness_fit.hpp).
#include <Eigen/Core>
#include <functional>
#include <string>

namespace vessel::msm {

/// f(x) and, into g (resized to x's size), ∇f(x).
using Objective = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd& g)>;

struct LbfgsOptions {
  int memory = 10;                  ///< (s, y) pairs kept
  int max_iterations = 200;
  double gradient_tolerance = 1e-8;  ///< stop when |∇f|_∞ ≤ this × max(1, |∇f(x0)|_∞)
  double relative_decrease = 1e-12;  ///< stop when (f_k − f_{k+1}) ≤ this × max(1, |f_k|)
  double armijo = 1e-4;              ///< c₁ of the sufficient-decrease condition
  int max_backtracks = 40;
  /// Called after each accepted iteration with (iteration, f, |∇f|_∞); may be empty.
  std::function<void(int, double, double)> on_iteration;
};

struct LbfgsResult {
  Eigen::VectorXd x;
  double f = 0.0;
  double gradient_norm = 0.0;  ///< |∇f|_∞ at x
  int iterations = 0;
  int evaluations = 0;  ///< objective calls
  bool converged = false;
  std::string stop_reason;  ///< "gradient", "no decrease", "line search", "iterations"
};

/// Minimises f from x0. Throws std::invalid_argument for memory < 1 or a non-finite f(x0).
LbfgsResult minimize_lbfgs(const Objective& f, const Eigen::VectorXd& x0,
                           const LbfgsOptions& options = {});

}  // namespace vessel::msm
