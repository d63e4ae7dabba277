#pragma once
/// Static equilibrium of a Problem: Newton on the total potential with a backtracking line search,
/// the analytic (PSD-projected) Hessian and CHOLMOD; and the linearised model (stiffness at the
/// rest state) for small-displacement comparisons.
#include <ostream>

#include "msm/model/form.hpp"

namespace vessel::msm {

struct StaticOptions {
  /// Converged when ‖∇Π‖ on the free dofs ≤ tolerance·max(‖f_ext‖, force_scale), or below the
  /// round-off floor ε·max|K_ii|·(model size)·√n.
  double tolerance = 1e-8;
  double force_scale = 1e-12;  ///< N, for unloaded problems
  int max_iterations = 200;
  bool project_psd = true;
  int load_steps = 1;           ///< load increments (Newton from each previous equilibrium)
  std::ostream* log = nullptr;  ///< per-iteration residual, step length, regularisation
};

struct StaticResult {
  VectorXd x;  ///< equilibrium positions, m
  int iterations = 0;
  double residual = 0.0;  ///< ‖∇Π‖ on free dofs at the end, N
  bool converged = false;
  double seconds = 0.0;
  int symbolic_analyses = 0;
  int numeric_factorisations = 0;
};

/// Newton with Armijo backtracking from `start` (rest positions if empty). Throws
/// std::runtime_error naming the iteration and residual if it does not converge.
StaticResult solve_static(const Problem& problem, const StaticOptions& options = {},
                          const VectorXd& start = VectorXd());

/// Linearised model: K(x0) u = f_ext with the Hessian at rest, one CHOLMOD solve; x = x0 + u.
StaticResult solve_linear(const Problem& problem);

}  // namespace vessel::msm
