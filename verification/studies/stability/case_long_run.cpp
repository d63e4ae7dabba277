// Hard case: a long run of the smallest model, energy watched.
#include "verification/studies/stability/study_models.hpp"

#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "verification/harness/timing.hpp"

namespace vessel::stability_study {

namespace {

/// One integrator's long run from `v0` at `fraction` × its predicted critical step (undamped
/// explicit Euler, whose prediction is 0: 0.1 × 2/ω_max), energy sampled every 100 steps.
HardCaseOutcome long_run(const StudyModel& base, const std::string& model,
                         const IntegratorConfig& cfg, double fraction, double omega_max,
                         const Eigen::VectorXd& v0, long long steps, long long early,
                         std::ostream& log) {
  const double c = 2.0 * cfg.zeta * omega_max * mean_mass(base.problem);
  const auto m = with_damping(base, c);
  const msm::Spectrum s = msm::analyse_spectrum(m->problem, {.lowest = c > 0});
  double dt = fraction * msm::predicted_critical_step(cfg.integrator, s);
  if (dt == 0.0) dt = 0.1 * 2.0 / s.omega_max;  // undamped explicit Euler: 0.1 × 2/ω_max
  const std::string name = msm::to_string(cfg.integrator) +
                           (c > 0 ? " (point damping, ζ " + fmt(cfg.zeta) + ")" : "");
  log << "  " << name << ": " << steps << " steps of " << fmt(dt) << " s" << std::endl;
  const double H0 = msm::total_energy(m->problem, m->problem.rest, v0);
  double hmax = H0, hmin = H0, hmax_early = H0;
  msm::DynamicOptions d;
  d.integrator = cfg.integrator;
  d.dt = dt;
  d.steps = static_cast<int>(steps);
  Stopwatch clock;
  d.on_step = [&](int step, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
    if (step % 100 == 0) {
      const double h = msm::total_energy(m->problem, x, v);
      hmax = std::max(hmax, h);
      hmin = std::min(hmin, h);
      if (step <= early) hmax_early = hmax;
    }
    if (step % early == 0) {
      const double t = clock.seconds();
      log << "    step " << step << " / " << steps << ", H/H0 " << fmt(hmax / H0) << " max, "
          << fmt(t, 3) << " s, ~" << fmt(t / step * static_cast<double>(steps - step), 2)
          << " s to go" << std::endl;
    }
  };
  HardCaseOutcome oc;
  oc.model = model + ", " + name;
  oc.values["dt_s"] = dt;
  oc.values["steps"] = static_cast<double>(steps);
  try {
    const msm::DynamicResult r = msm::integrate(m->problem, d, m->problem.rest, v0);
    const double secs = clock.seconds();
    oc.finished = true;
    oc.bounded = hmax <= 1.5 * hmax_early;
    oc.reported = std::to_string(steps) + " steps of " + fmt(dt) + " s (" +
                  fmt(dt * s.omega_max / 2.0, 3) + " × 2/ω_max): H/H₀ max " + fmt(hmax / H0) +
                  " over the run (" + fmt(hmax_early / H0) + " over its first 10 %), min " +
                  fmt(hmin / H0) + ", final " + fmt(r.energy / H0) + " (" + fmt(secs, 3) +
                  " s, " + fmt(1e6 * secs / static_cast<double>(steps), 3) + " µs per step)";
    oc.values["energy_max_over_initial"] = hmax / H0;
    oc.values["energy_max_first_tenth_over_initial"] = hmax_early / H0;
    oc.values["energy_final_over_initial"] = r.energy / H0;
    oc.values["seconds"] = secs;
  } catch (const msm::DivergenceError& e) {
    oc.finished = false;
    oc.bounded = false;
    oc.reported = "stopped: " + short_error(e.what());
    oc.values["diverged_at_step"] = e.step;
  }
  return oc;
}

}  // namespace

HardCase case_long_run(const StabilityOptions& o, std::ostream& log) {
  HardCase hc;
  hc.id = "long_run";
  hc.title = "A long run";
  const long long steps = o.long_run_steps > 0 ? o.long_run_steps : (o.quick ? 20000 : 1000000);
  // The smallest mesh that is still the vessel: a 10 mm segment of the default tube (same
  // cross-section and cells, so the same ω_max and step) at structured level 0, 6 rings of 24
  // nodes on the inner wall. On the full 40 mm tube (552 nodes) a step costs ~4× more and the three
  // 10⁶-step runs took ~3 min (measured); on the segment they take under a minute.
  VesselParams params;
  params.style = MeshStyle::structured;
  params.length = 10e-3;
  const Scene scene = study_scene(params, 14.24e3, 0.0);
  const TetMesh mesh = case_mesh(scene, o);
  const ModelSpec spec = surface_model(msm::StiffnessRule::seed000);
  const auto base = build_model(scene, mesh, spec, 0.25);
  const msm::Spectrum s0 = msm::analyse_spectrum(base->problem, {.lowest = false});
  const long long early = std::max<long long>(steps / 10, 1);
  hc.setup = "The smallest model: seed 000's grid surface model on a 10 mm segment of the "
             "structured level-0 tube (" +
             std::to_string(base->built.network.nodes.size()) + " nodes, " +
             std::to_string(base->built.network.springs.size()) + " springs), ends fixed, no "
             "load, started from a random velocity (strain ~1e-4); " + std::to_string(steps) +
             " steps at 0.9 × each integrator's predicted critical step" +
             (o.quick ? " (quick mode: scaled down from 10⁶)" : "") +
             "; energy H = ½vᵀMv + E(x) sampled every 100 steps. Bounded: no blow-up and the "
             "largest H/H₀ over the whole run at most 1.5 × the largest over its first 10 % (" +
             std::to_string(early) + " steps). H oscillates from the start without growing: "
             "on a linear mode symplectic Euler and Verlet conserve a modified energy exactly, "
             "and H/H₀ ≤ (1 + a)/(1 − a) (symplectic Euler) or 1/(1 − a²) (Verlet), a = hω/2 "
             "(19 and 5.3 at a = 0.9); energy that grows with time fails the test.";
  // Random velocity giving displacements of ~1e-4 of a spring.
  double mean_rest = 0.0;
  for (const auto& sp : base->built.network.springs) mean_rest += sp.rest_length;
  mean_rest /= static_cast<double>(base->built.network.springs.size());
  const Eigen::VectorXd v0 = msm::random_velocity(base->problem, 1e-4 * mean_rest * s0.omega_max, 11);
  struct Run {
    IntegratorConfig cfg;
    double fraction;
  };
  for (const Run& run : {Run{{Integrator::symplectic_euler, 0.0}, 0.9},
                         Run{{Integrator::verlet, 0.0}, 0.9},
                         Run{{Integrator::explicit_euler, 0.3}, 0.9},
                         Run{{Integrator::explicit_euler, 0.0}, 0.0}}) {
    hc.outcomes.push_back(long_run(*base, spec.name, run.cfg, run.fraction, s0.omega_max, v0,
                                   steps, early, log));
  }
  return hc;
}

}  // namespace vessel::stability_study
