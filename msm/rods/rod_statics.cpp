#include "msm/rods/rod_statics.hpp"

#include <algorithm>
#include <stdexcept>

#include "msm/form/form_sum.hpp"
#include "msm/rods/constrained_newton.hpp"
#include "msm/solvers/static_solver.hpp"

namespace vessel::msm::rods {

RodStaticResult solve_rod_static(Rod& rod, const RodStaticLoad& load, double tolerance) {
  std::vector<const Form*> terms{&rod};
  if (load.extra != nullptr) terms.push_back(load.extra);
  const FormSum form(terms);
  const VectorXd rest = rod.rest_state();
  const VectorXd full = load.force.size() > 0 ? load.force : VectorXd::Zero(rest.size());
  const std::vector<char> fixed = load.fixed.empty() ? rod.clamp_fixed() : load.fixed;
  const EqualityConstraints* constraints = rod.constraints();

  ConstrainedProblem kkt;  // a model with hard constraints
  ConstrainedOptions kkt_options;
  Problem plain;  // one without
  StaticOptions plain_options;
  if (constraints) {
    kkt.form = &form;
    kkt.constraints = constraints;
    kkt.rest = rest;
    kkt.fixed = fixed;
    kkt.project = [&rod](VectorXd& x) { rod.project(x); };
    kkt_options.tolerance = tolerance;
    kkt_options.force_scale = std::max(kkt_options.force_scale, bending_force_scale(rod));
  } else {
    plain.form = &form;
    plain.rest = rest;
    plain.mass = rod.lumped_mass();
    plain.fixed = fixed;
    plain_options.tolerance = tolerance;
    // Without nodal loads (an end moment), the residual's scale is EI/L².
    if (full.norm() == 0.0) {
      plain_options.force_scale = std::max(plain_options.force_scale, bending_force_scale(rod));
    }
  }

  RodStaticResult result;
  result.x = load.start.size() > 0 ? load.start : rest;
  double done = 0.0, increment = 1.0 / std::max(1, load.steps);
  int halvings = 0;
  while (done < 1.0 - 1e-12) {
    const double s = std::min(1.0, done + increment);
    if (load.scale_extra) load.scale_extra(s);
    try {
      if (constraints) {
        kkt.external_force = s * full;
        ConstrainedResult r = solve_constrained(kkt, result.x, result.lambda, kkt_options);
        result.x = std::move(r.x);
        result.lambda = std::move(r.lambda);
        result.newton_iterations += r.iterations;
      } else {
        plain.external_force = s * full;
        StaticResult r = solve_static(plain, plain_options, result.x);
        result.x = std::move(r.x);
        result.newton_iterations += r.iterations;
      }
      done = s;
      rod.prepare(result.x);
    } catch (const std::runtime_error&) {
      if (++halvings > 10) throw;
      increment *= 0.5;
    }
  }
  return result;
}

}  // namespace vessel::msm::rods
