#pragma once
/// Static equilibrium of a Discrete Elastic Rod under loads ramped in steps: the project's static
/// Newton (msm/solvers/static_solver) at each load fraction, the reference frames carried to the
/// new equilibrium between steps.
#include <functional>

#include "msm/rods/der_rod.hpp"
#include "msm/solvers/static_solver.hpp"

namespace vessel::msm::rods {

struct RodStaticLoad {
  VectorXd force;  ///< dead nodal loads per dof (N; zero on twist dofs), full value
  const Form* extra = nullptr;  ///< a load Form (e.g. PlanarEndMoment), or none
  /// Sets the extra load at a fraction in (0, 1] of its full value.
  std::function<void(double)> scale_extra;
  std::vector<char> fixed;  ///< held dofs (default: the rod's clamps)
  VectorXd start;           ///< initial state with the held dofs' values (default: rest)
  int steps = 1;
};

struct RodStaticResult {
  VectorXd x;
  int newton_iterations = 0;
};

/// Throws std::runtime_error (from the static solver) if a step does not converge.
RodStaticResult solve_der_static(DerRod& rod, const RodStaticLoad& load,
                                 StaticOptions options = {});

}  // namespace vessel::msm::rods
