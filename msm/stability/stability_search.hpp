#pragma once
/// The largest stable time step found by running: bisection on dt, each trial a fixed number of
/// steps from a small random perturbation of the rest state, unstable when the integrator's
/// divergence check (DivergenceError: non-finite state or energy beyond the blow-up bound) fires.
#include <cstdint>
#include <functional>

#include "msm/form/form.hpp"
#include "msm/solvers/integrators.hpp"

namespace vessel::msm {

struct StabilitySearchOptions {
  Integrator integrator = Integrator::symplectic_euler;
  int steps = 1000;            ///< steps per trial
  double tolerance = 5e-3;     ///< stop when (unstable − stable)/stable ≤ tolerance
  double blowup_factor = 1e3;  ///< energy bound: |H₀|(1 + blowup_factor), see DynamicOptions
  std::uint32_t seed = 12345;  ///< of the random initial velocity (deterministic)
  int max_trials = 60;
  /// Called after every trial with (dt, stable); may be empty (progress output).
  std::function<void(double, bool)> on_trial;
};

struct StabilitySearchResult {
  double stable_dt = 0.0;    ///< largest step that stayed bounded, s
  double unstable_dt = 0.0;  ///< smallest step that diverged, s
  int trials = 0;
  long long steps_run = 0;  ///< over all trials
  double seconds = 0.0;
};

/// Initial velocity of the trials: uniform random in [−1, 1] per free dof (zero on fixed dofs),
/// scaled so that the kinetic energy is tiny (linear regime): amplitude `speed` m/s.
VectorXd random_velocity(const Problem& problem, double speed, std::uint32_t seed);

/// One trial: integrates `steps` steps at dt from rest with velocity v0 and no external load;
/// true if no DivergenceError was raised.
bool is_stable(const Problem& problem, Integrator integrator, double dt, int steps,
               const VectorXd& v0, double blowup_factor = 1e3, long long* steps_run = nullptr);

/// The bracketing and bisection of find_stable_step on any stability trial: `trial(dt)` true when
/// a run at dt stayed bounded. Brackets from `guess` (s, > 0) by factors of 1.02 then 1.25, then
/// bisects until (unstable − stable)/stable ≤ tolerance. Throws std::runtime_error if no bracket
/// is found in max_trials.
StabilitySearchResult bisect_stable_step(double guess, double tolerance, int max_trials,
                                         const std::function<bool(double)>& trial);

/// Bisection for the largest stable step, starting from `guess` (s, > 0, e.g. the predicted
/// critical step): brackets by factors of 1.02 then 1.25, then bisects to `tolerance`. The
/// external load is removed (linear stability at rest, the setting of the prediction). Throws
/// std::runtime_error if no bracket is found in max_trials (e.g. stable at every step tried).
StabilitySearchResult find_stable_step(const Problem& problem, double guess,
                                       const StabilitySearchOptions& options = {});

}  // namespace vessel::msm
