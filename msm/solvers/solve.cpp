#include "msm/solvers/solve.hpp"

#include <algorithm>

#include "meshes/foundation/errors.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/local_global.hpp"
#include "msm/solvers/critical_step.hpp"

namespace vessel::msm {

SolverSpec parse_solver(const std::string& name) {
  SolverSpec spec;
  if (name == "static") return spec;
  if (name == "linear") {
    spec.kind = SolverKind::linear;
  } else if (name == "relaxation") {
    spec.kind = SolverKind::relaxation;
  } else if (name == "pbd") {
    spec.kind = SolverKind::pbd;
  } else if (name == "local-global") {
    spec.kind = SolverKind::local_global;
  } else if (name == "local-global-euler") {
    spec.kind = SolverKind::local_global_euler;
  } else if (name == "implicit-euler-rest") {
    spec.kind = SolverKind::integrator;
    spec.integrator = Integrator::implicit_euler;
    spec.implicit_matrix = ImplicitMatrix::rest_prefactored;
  } else if (name == "implicit-euler-pcg") {
    spec.kind = SolverKind::integrator;
    spec.integrator = Integrator::implicit_euler;
    spec.implicit_matrix = ImplicitMatrix::current_pcg;
  } else if (name == "implicit-euler-rest-pcg") {
    spec.kind = SolverKind::integrator;
    spec.integrator = Integrator::implicit_euler;
    spec.implicit_matrix = ImplicitMatrix::rest_pcg;
  } else {
    try {
      spec.integrator = parse_integrator(name);
      spec.kind = SolverKind::integrator;
    } catch (const InputError&) {
      std::string names;
      for (const char* n : kSolverNames) names += (names.empty() ? "" : ", ") + std::string(n);
      throw InputError("solver: expected one of " + names + "; got '" + name + "'");
    }
  }
  return spec;
}

std::string to_string(const SolverSpec& spec) {
  switch (spec.kind) {
    case SolverKind::static_newton: return "static";
    case SolverKind::linear: return "linear";
    case SolverKind::relaxation: return "relaxation";
    case SolverKind::integrator:
      if (spec.integrator == Integrator::implicit_euler &&
          spec.implicit_matrix == ImplicitMatrix::rest_prefactored) {
        return "implicit-euler-rest";
      }
      if (spec.integrator == Integrator::implicit_euler &&
          spec.implicit_matrix == ImplicitMatrix::rest_pcg) {
        return "implicit-euler-rest-pcg";
      }
      if (spec.integrator == Integrator::implicit_euler &&
          spec.implicit_matrix == ImplicitMatrix::current_pcg) {
        return "implicit-euler-pcg";
      }
      return to_string(spec.integrator);
    case SolverKind::pbd: return "pbd";
    case SolverKind::local_global: return "local-global";
    case SolverKind::local_global_euler: return "local-global-euler";
  }
  return "?";
}

double resolved_time_step(const Problem& problem, const SolverSpec& spec) {
  if (spec.dt > 0.0) return spec.dt;
  if (spec.kind == SolverKind::pbd) return 1e-3;
  const double critical = 2.0 / max_frequency_bound(problem);
  if (spec.kind == SolverKind::local_global_euler || spec.integrator == Integrator::implicit_euler) {
    return kImplicitStepMultiple * critical;
  }
  double bound = critical;
  SparseMatrix C;
  problem.form->damping_jacobian(problem.rest, C);
  if (C.cwiseAbs().sum() > 0.0) {
    // Damped: the modal prediction can exceed the true limit (measured up to 2.35×, issue 13);
    // the guaranteed step holds for any PSD damping. ω_min is not needed for a proven bound.
    SpectrumOptions o;
    o.lowest = false;
    const double guaranteed = guaranteed_critical_step(spec.integrator, analyse_spectrum(problem, o));
    if (std::isfinite(guaranteed) && guaranteed > 0.0) bound = std::min(bound, guaranteed);
  }
  return kExplicitStepFraction * bound;
}

namespace {

SolveResult run_pbd_solver(const Problem& problem, const SolverSpec& spec,
                           const SpringNetwork* network, const StepObserver& on_step) {
  if (!network || network->triangles.empty()) {
    throw InputError(
        "solver pbd: seed 002's position-based constraints need a surface network (its "
        "triangles carry the bending constraints); use a surface model");
  }
  if (problem.form && !plain_spring_model(*problem.form)) {
    // PBD projects its own constraints and never reads the Form: an energy term beyond the
    // springs (the discrete-shells bending term) would be silently ignored.
    throw InputError(
        "solver pbd: seed 002's position-based constraints replace the model's energy; this "
        "model has a term beyond its springs (bending = discrete-shells), which PBD would ignore; "
        "use another solver or bending none");
  }
  std::vector<Vec3> loads(network->nodes.size(), Vec3::Zero());
  for (std::size_t i = 0; i < loads.size(); ++i) {
    loads[i] = problem.external_force.segment<3>(3 * static_cast<Eigen::Index>(i));
  }
  PbdConstraintOptions c;
  c.dihedral = spec.pbd.dihedral;
  c.angle = spec.pbd.angle;
  c.bending_compliance = spec.pbd.bending_compliance;
  c.angle_compliance = spec.pbd.bending_compliance;
  PbdOptions o;
  o.dt = resolved_time_step(problem, spec);
  o.steps = static_cast<int>(spec.steps);
  o.iterations = spec.pbd.iterations;
  o.velocity_damping = spec.pbd.velocity_damping;
  o.on_step = on_step;
  PbdResult r = run_pbd(problem, build_pbd_constraints(*network, loads, c), o);
  return {r.x, r.seconds, o.dt, std::move(r)};
}

SolveResult run_integrator(const Problem& problem, const SolverSpec& spec,
                           const StepObserver& on_step) {
  DynamicOptions d;
  d.integrator = spec.integrator;
  d.implicit_matrix = spec.implicit_matrix;
  d.pcg = spec.pcg;
  d.dt = resolved_time_step(problem, spec);
  d.steps = static_cast<int>(spec.steps);
  if (on_step) d.on_step = [&](int step, const VectorXd& x, const VectorXd&) { on_step(step, x); };
  DynamicResult r = integrate(problem, d);
  return {r.x, r.seconds, d.dt, std::move(r)};
}

}  // namespace

SolveResult solve(const Problem& problem, const SolverSpec& spec, const SpringNetwork* network,
                  const StepObserver& on_step) {
  if (spec.is_dynamic() && spec.steps < 1) {
    throw InputError("solver " + to_string(spec) + ": expected a number of steps >= 1, got " +
                     std::to_string(spec.steps));
  }
  switch (spec.kind) {
    case SolverKind::static_newton: {
      StaticResult r = solve_static(problem, spec.static_options);
      return {r.x, r.seconds, 0.0, std::move(r)};
    }
    case SolverKind::linear: {
      StaticResult r = solve_linear(problem);
      return {r.x, r.seconds, 0.0, std::move(r)};
    }
    case SolverKind::relaxation: {
      RelaxationResult r = dynamic_relaxation(problem);
      return {r.x, r.seconds, r.dt, std::move(r)};
    }
    case SolverKind::integrator: return run_integrator(problem, spec, on_step);
    case SolverKind::pbd: return run_pbd_solver(problem, spec, network, on_step);
    case SolverKind::local_global: {
      LocalGlobalOptions o;
      o.tolerance = spec.static_options.tolerance;
      o.force_scale = spec.static_options.force_scale;
      o.max_iterations = spec.local_global.max_iterations;
      StaticResult r = solve_static_local_global(problem, o);
      return {r.x, r.seconds, 0.0, std::move(r)};
    }
    case SolverKind::local_global_euler: {
      DynamicOptions d;
      d.dt = resolved_time_step(problem, spec);
      d.steps = static_cast<int>(spec.steps);
      if (on_step) d.on_step = [&](int step, const VectorXd& x, const VectorXd&) { on_step(step, x); };
      LocalGlobalOptions o;
      o.iterations = spec.local_global.iterations;
      DynamicResult r = integrate_local_global(problem, d, o);
      return {r.x, r.seconds, d.dt, std::move(r)};
    }
  }
  throw InputError("solver: unknown kind");
}

}  // namespace vessel::msm
