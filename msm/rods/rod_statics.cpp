#include "msm/rods/rod_statics.hpp"

#include <algorithm>

#include "msm/form/form_sum.hpp"
#include "msm/rods/rod_loads.hpp"

namespace vessel::msm::rods {

RodStaticResult solve_der_static(DerRod& rod, const RodStaticLoad& load, StaticOptions options) {
  const VectorXd rest = rod.rest_state();
  std::vector<const Form*> terms{&rod};
  if (load.extra != nullptr) terms.push_back(load.extra);
  const FormSum form(terms);
  Problem problem;
  problem.form = &form;
  problem.rest = rest;
  problem.mass = rod.lumped_mass();
  problem.fixed = load.fixed.empty() ? rod.clamp_fixed() : load.fixed;
  // Without nodal loads (an end moment), the residual scale is EI/L² of the stiffest section.
  if (load.force.size() == 0 || load.force.norm() == 0.0) {
    double ei = 0.0;
    for (const auto& section : rod.layout().section) ei = std::max(ei, section.EI);
    const double L = rod.layout().total_length();
    options.force_scale = std::max(options.force_scale, ei / (L * L));
  }
  RodStaticResult result;
  VectorXd x = load.start.size() > 0 ? load.start : rest;
  const int steps = std::max(1, load.steps);
  for (int k = 1; k <= steps; ++k) {
    const double s = static_cast<double>(k) / steps;
    problem.external_force = s * (load.force.size() > 0 ? load.force : VectorXd::Zero(rest.size()));
    if (load.scale_extra) load.scale_extra(s);
    const StaticResult r = solve_static(problem, options, x);
    x = r.x;
    result.newton_iterations += r.iterations;
    rod.update_reference(x);
  }
  result.x = x;
  return result;
}

}  // namespace vessel::msm::rods
