#pragma once
/// Static equilibrium of a Problem: Newton on the total potential with a backtracking line search,
/// the analytic (PSD-projected) Hessian and CHOLMOD; and the linearised model (stiffness at the
/// rest state) for small-displacement comparisons.
#include <ostream>

#include "msm/model/form.hpp"

namespace vessel::msm {

class CholmodSolver;  // msm/solvers/linear_solver.hpp

struct StaticOptions {
  /// Converged when ‖∇Π‖ on the free dofs ≤ tolerance·max(‖f_ext‖, force_scale), or below the
  /// round-off floor ε·max|K_ii|·(model size)·√n.
  double tolerance = 1e-8;
  double force_scale = 1e-12;  ///< N, for unloaded problems
  int max_iterations = 200;
  bool project_psd = true;
  int load_steps = 1;           ///< load increments (Newton from each previous equilibrium)
  /// Where the exact Hessian is indefinite: power iterations for a direction of negative
  /// curvature (0: off, plain projected Newton). Off by default: fewer iterations on the level
  /// 0–1 surface models, but more (and more time) on the level-2 grid; docs/msm_measurements.md.
  int curvature_iterations = 0;
  /// After the exact Hessian fails to factorise (indefinite), skip the attempt for 1, 2, 4 …
  /// iterations, at most this many (0: try every iteration).
  int exact_backoff = 0;
  /// With a negative-curvature direction found (generalised eigenvalue λ < 0 of H v = λ Hp v):
  /// the Newton step uses (1 − τ)H + τHp, τ the smallest blend whose eigenvalues are ≥ this
  /// (relative to Hp), instead of Hp alone. 1 or more: off.
  double curvature_shift = 0.3;
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
  int indefinite_iterations = 0;     ///< iterations whose exact Hessian was not positive definite
  int negative_curvature_steps = 0;  ///< of those, steps taken along a negative-curvature direction
  double factorisation_seconds = 0.0;  ///< of `seconds`: CHOLMOD symbolic + numeric factorisations
  double assembly_seconds = 0.0;       ///< of `seconds`: Hessian assembly
  double curvature_seconds = 0.0;      ///< of `seconds`: power iterations for negative curvature
};

/// Newton with Armijo backtracking from `start` (rest positions if empty): the exact Hessian
/// where it is positive definite; elsewhere the per-spring PSD-projected Hessian for a descent
/// direction plus a step along a direction of negative curvature of the exact Hessian (escaping
/// saddles and buckling points). Throws std::runtime_error naming the iteration and residual if it
/// does not converge.
StaticResult solve_static(const Problem& problem, const StaticOptions& options = {},
                          const VectorXd& start = VectorXd());
/// The same with the caller's CHOLMOD solver: its symbolic analysis is reused while the pattern
/// stays, and on return it holds the last factorisation (of the Hessian at the last iterate but
/// one), which modified-Newton updates reuse (msm/solvers/updates.hpp). The result's counts and
/// times are this call's own.
StaticResult solve_static(const Problem& problem, const StaticOptions& options,
                          const VectorXd& start, CholmodSolver& solver);

/// Linearised model: K(x0) u = f_ext with the Hessian at rest, one CHOLMOD solve; x = x0 + u.
StaticResult solve_linear(const Problem& problem);

}  // namespace vessel::msm
