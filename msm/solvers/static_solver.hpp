#pragma once
/// Static equilibrium of a Problem: Newton on the total potential with a backtracking line search,
/// the analytic (PSD-projected) Hessian and CHOLMOD; and the linearised model (stiffness at the
/// rest state) for small-displacement comparisons.
#include <ostream>
#include <string>

#include "msm/form/form.hpp"

namespace vessel::msm {

class CholmodSolver;  // msm/linalg/linear_solver.hpp

/// How static Newton makes each step a descent that converges.
enum class StaticGlobalisation {
  /// Exact Hessian where it factorises, else the per-spring PSD-projected one; Armijo
  /// backtracking on the step (options below). Linear rate where the Hessian is indefinite.
  line_search,
  /// Trust region: each step minimises the quadratic model with the exact Hessian H within a
  /// radius, by Steihaug–Toint conjugate gradients preconditioned with the factorised projected
  /// Hessian; directions of negative curvature are followed to the boundary (Nocedal & Wright
  /// 2006, Algorithms 4.1 and 7.2). One factorisation per iteration, never of an indefinite H.
  trust_region,
};

/// "line-search" or "trust-region"; InputError naming both otherwise.
StaticGlobalisation parse_static_globalisation(const std::string& name);
std::string to_string(StaticGlobalisation globalisation);

struct StaticOptions {
  /// Converged when ‖∇Π‖ on the free dofs ≤ tolerance·max(‖f_ext‖, force_scale), or below the
  /// round-off floor ε·max|K_ii|·(model size)·√n.
  double tolerance = 1e-8;
  double force_scale = 1e-12;  ///< N, for unloaded problems
  int max_iterations = 200;
  bool project_psd = true;
  int load_steps = 1;           ///< load increments (Newton from each previous equilibrium)
  StaticGlobalisation globalisation = StaticGlobalisation::line_search;
  // The options below belong to line_search.
  /// Where the exact Hessian is indefinite: power iterations for a direction of negative
  /// curvature (0: off, plain projected Newton). Off by default: fewer iterations on the level
  /// 0–1 surface models, but more (and more time) on the level-2 grid; docs/measurements/msm_measurements.md.
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
                                     ///< (trust_region: where CG met negative curvature)
  int negative_curvature_steps = 0;  ///< of those, steps taken along a negative-curvature direction
                                     ///< (trust_region: accepted CG steps that met one)
  int boundary_steps = 0;            ///< trust_region: iterations whose step ended on the boundary
  int rejected_steps = 0;  ///< trust_region: trial steps rejected (radius cut, same Hessian)
  double factorisation_seconds = 0.0;  ///< of `seconds`: CHOLMOD symbolic + numeric factorisations
  double assembly_seconds = 0.0;       ///< of `seconds`: Hessian assembly
  double curvature_seconds = 0.0;      ///< of `seconds`: power iterations for negative curvature
};

/// Newton from `start` (rest positions if empty), globalised as options.globalisation says:
/// line_search: Armijo backtracking, the exact Hessian where it is positive definite, elsewhere
/// the per-spring PSD-projected Hessian for a descent direction (optionally plus a step along a
/// direction of negative curvature); trust_region: Steihaug–Toint CG steps within a trust
/// region. Throws std::runtime_error naming the iteration and residual if it does not converge.
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
