#pragma once
/// Newton on the KKT system of min Π(x) = E(x) − f·(x − x0) [+ inertia] subject to c(x) = 0
/// (Lagrange multipliers), held dofs at their start values. The matrix
///   [ ∇²E + Σ λ_k ∇²c_k   Jᵀ ] [Δx]     [∇E − f + Jᵀλ]
///   [ J                    0 ] [Δλ] = − [c           ]
/// is factorised by sparse LU (it is indefinite). Used by the rods' statics with hard constraints
/// (CORDE) and by every rod's implicit Euler step (rod_dynamics.hpp).
#include <functional>
#include <vector>

#include "msm/form/equality_constraints.hpp"
#include "msm/form/form.hpp"

namespace vessel::msm::rods {

struct ConstrainedProblem {
  const Form* form = nullptr;
  const EqualityConstraints* constraints = nullptr;  ///< none: plain Newton with full steps
  VectorXd rest;            ///< x0 of the load's potential
  VectorXd external_force;  ///< dead loads per dof
  std::vector<char> fixed;  ///< held dofs
  /// Implicit Euler's inertia ½ (x − x̃)ᵀ M (x − x̃)/h² (empty mass: statics).
  VectorXd inertia_mass;
  VectorXd inertia_target;
  double time_step = 0.0;
  /// Maps each Newton iterate back onto part of the constraint manifold (e.g. normalises the
  /// quaternions, so that a stiff penalty does not amplify their quadratic drift); may be empty.
  std::function<void(VectorXd&)> project;
};

struct ConstrainedOptions {
  double tolerance = 1e-10;   ///< on ‖∇L‖ (free dofs) relative to force_scale
  double force_scale = 1e-12;  ///< N, for problems without nodal loads
  double constraint_tolerance = 1e-14;  ///< on max |c_k| (units of c)
  int max_iterations = 60;
};

struct ConstrainedResult {
  VectorXd x;
  VectorXd lambda;
  int iterations = 0;
  double residual = 0.0;            ///< ‖∇L‖ on free dofs
  double constraint_residual = 0.0;  ///< max |c_k|
};

/// Full Newton steps from (start, lambda_start). Throws std::runtime_error naming the iteration and residuals if it does not converge.
ConstrainedResult solve_constrained(const ConstrainedProblem& problem, const VectorXd& start,
                                    const VectorXd& lambda_start,
                                    const ConstrainedOptions& options = {});

}  // namespace vessel::msm::rods
