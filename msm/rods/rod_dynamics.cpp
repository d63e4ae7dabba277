#include "msm/rods/rod_dynamics.hpp"

#include <algorithm>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/rods/constrained_newton.hpp"

namespace vessel::msm::rods {

RodStep rod_implicit_euler_step(Rod& rod, const VectorXd& x, const VectorXd& v,
                                const VectorXd& force, double dt, const std::vector<char>& fixed) {
  const auto n = static_cast<Eigen::Index>(rod.num_dofs());
  if (!(dt > 0.0)) {
    throw InputError("rod_implicit_euler_step: expected a time step > 0 s, got " +
                     std::to_string(dt));
  }
  if (x.size() != n || v.size() != n || (force.size() != 0 && force.size() != n) ||
      (!fixed.empty() && static_cast<Eigen::Index>(fixed.size()) != n)) {
    throw InputError("rod_implicit_euler_step: expected x, v (and force, fixed if given) of " +
                     std::to_string(n) + " dofs");
  }
  const VectorXd load = force.size() > 0 ? force : VectorXd::Zero(n);
  // The residual is judged against the largest force scale of the step: the rod's bending force
  // EI/L², its inertial force |M v|/h, or the load.
  const VectorXd mass = rod.lumped_mass();
  const double force_scale =
      std::max({bending_force_scale(rod), mass.cwiseProduct(v).norm() / dt, load.norm()});
  ConstrainedProblem p;
  p.form = &rod;
  p.constraints = rod.constraints();
  p.rest = x;
  p.external_force = load;
  p.fixed = fixed.empty() ? rod.clamp_fixed() : fixed;
  p.inertia_mass = mass;
  p.inertia_target = x + dt * v;
  p.time_step = dt;
  p.project = [&rod](VectorXd& y) { rod.project(y); };
  ConstrainedOptions options;
  options.force_scale = force_scale;
  RodStep step;
  step.x = solve_constrained(p, x, VectorXd(), options).x;
  step.v = (step.x - x) / dt;
  rod.prepare(step.x);
  return step;
}

}  // namespace vessel::msm::rods
