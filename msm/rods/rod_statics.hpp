#pragma once
/// Static equilibrium of any rod model (msm/rods/rod.hpp) under loads ramped in increments, each
/// from the last equilibrium, the model readied for the new state between increments (DER's
/// frames carried by parallel transport). A model without hard constraints (DER) is solved by
/// the project's static Newton (msm/solvers/static_solver), one with them (CORDE) by Newton on the
/// KKT system (constrained_newton.hpp, iterates projected onto unit quaternions). An increment
/// that does not converge is halved, at most 10 times, and retried.
#include <functional>
#include <vector>

#include "msm/rods/rod.hpp"

namespace vessel::msm::rods {

struct RodStaticLoad {
  VectorXd force;  ///< dead loads per dof (N; zero on frame dofs), full value; empty: none
  const Form* extra = nullptr;  ///< a load Form on the same dofs (e.g. PlanarEndMoment), or none
  /// Sets the extra load at a fraction in (0, 1] of its full value.
  std::function<void(double)> scale_extra;
  std::vector<char> fixed;  ///< held dofs (default: the rod's clamps)
  VectorXd start;           ///< initial state with the held dofs' values (default: rest)
  int steps = 1;            ///< load increments
};

struct RodStaticResult {
  VectorXd x;
  /// The multipliers of the rod's own constraints (empty for a model without any), in the
  /// Lagrangian Π + λᵀc.
  VectorXd lambda;
  int newton_iterations = 0;
};

/// `tolerance`: on the free dofs' residual, relative to the larger of the nodal loads' norm and
/// EI/L² of the stiffest section (DER), or to EI/L² (CORDE). Throws std::runtime_error if an
/// increment still fails after 10 halvings.
RodStaticResult solve_rod_static(Rod& rod, const RodStaticLoad& load, double tolerance = 1e-10);

}  // namespace vessel::msm::rods
