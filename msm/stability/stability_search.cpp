#include "msm/stability/stability_search.hpp"

#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace vessel::msm {

VectorXd random_velocity(const Problem& p, double speed, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VectorXd v(p.num_dofs());
  for (int i = 0; i < p.num_dofs(); ++i) v[i] = p.fixed[i] ? 0.0 : speed * u(rng);
  return v;
}

bool is_stable(const Problem& p, Integrator integrator, double dt, int steps, const VectorXd& v0,
               double blowup_factor, long long* steps_run) {
  Problem unloaded = p;
  unloaded.external_force.setZero();
  DynamicOptions o;
  o.integrator = integrator;
  o.dt = dt;
  o.steps = steps;
  o.blowup_factor = blowup_factor;
  try {
    const DynamicResult r = integrate(unloaded, o, p.rest, v0);
    if (steps_run) *steps_run += r.steps;
    return true;
  } catch (const DivergenceError& e) {
    if (steps_run) *steps_run += e.step;
    return false;
  }
}

StabilitySearchResult bisect_stable_step(double guess, double tolerance, int max_trials,
                                         const std::function<bool(double)>& run) {
  if (!(guess > 0) || !std::isfinite(guess)) {
    throw std::invalid_argument("stability search: the initial guess must be a finite step > 0");
  }
  const auto t0 = std::chrono::steady_clock::now();
  StabilitySearchResult r;
  auto trial = [&](double dt) {
    if (r.trials >= max_trials) {
      throw std::runtime_error("stability search: no bracket after " + std::to_string(max_trials) +
                               " trials (last dt " + std::to_string(dt) + " s)");
    }
    ++r.trials;
    return run(dt);
  };
  double lo = 0.0, hi = 0.0;
  if (trial(guess / 1.02)) {
    lo = guess / 1.02;
    double dt = guess * 1.02;
    while (trial(dt)) {
      lo = dt;
      dt *= 1.25;
    }
    hi = dt;
  } else {
    hi = guess / 1.02;
    double dt = hi / 1.25;
    while (!trial(dt)) {
      hi = dt;
      dt /= 1.25;
    }
    lo = dt;
  }
  while (hi - lo > tolerance * lo) {
    const double mid = 0.5 * (lo + hi);
    (trial(mid) ? lo : hi) = mid;
  }
  r.stable_dt = lo;
  r.unstable_dt = hi;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

StabilitySearchResult find_stable_step(const Problem& p, double guess,
                                       const StabilitySearchOptions& o) {
  if (!(guess > 0) || !std::isfinite(guess)) {
    throw std::invalid_argument("find_stable_step: the initial guess must be a finite step > 0");
  }
  // Velocity amplitude: displacements of ~1e-9 of the model's size over one period at the guess.
  double extent = 0.0;
  for (int i = 0; i < p.num_dofs(); ++i) extent = std::max(extent, std::abs(p.rest[i]));
  const VectorXd v0 = random_velocity(p, 1e-9 * std::max(extent, 1e-3) / guess, o.seed);
  long long steps_run = 0;
  StabilitySearchResult r = bisect_stable_step(guess, o.tolerance, o.max_trials, [&](double dt) {
    const bool ok = is_stable(p, o.integrator, dt, o.steps, v0, o.blowup_factor, &steps_run);
    if (o.on_trial) o.on_trial(dt, ok);
    return ok;
  });
  r.steps_run = steps_run;
  return r;
}

}  // namespace vessel::msm
