#pragma once
/// Implicit Euler for any rod model (msm/rods/rod.hpp), written once: each step minimises the
/// incremental potential ½ |x₁ − x − h v|²_M / h² + E(x₁) − f·x₁ to convergence (a fully
/// converged backward Euler step, not the one-Newton-step linearisation of Baraff & Witkin),
/// v₁ = (x₁ − x)/h, by full Newton steps on the KKT system of the model's own constraints
/// (constrained_newton.hpp; none for DER, CORDE's inextensibility and unit quaternions); the model
/// is readied for x₁ afterwards (DER's frames).
#include <vector>

#include "msm/rods/rod.hpp"

namespace vessel::msm::rods {

struct RodStep {
  VectorXd x;  ///< the state after the step
  VectorXd v;  ///< (x₁ − x)/h, per dof (m/s on positions)
};

/// One step of length dt (s, > 0) from (x, v) under the dead loads `force` (N per dof; empty:
/// none), `fixed` held (empty: the rod's clamps). InputError for dt ≤ 0 or mis-sized vectors;
/// std::runtime_error if Newton does not converge.
RodStep rod_implicit_euler_step(Rod& rod, const VectorXd& x, const VectorXd& v,
                                const VectorXd& force, double dt,
                                const std::vector<char>& fixed = {});

}  // namespace vessel::msm::rods
