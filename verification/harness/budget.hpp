#pragma once
/// A scene's budget in numbers: the load it applies at and what one update at its rate costs.
#include <utility>

#include "verification/scene.hpp"

namespace vessel {

/// The load the budget applies at: the scene's representative_load (reports/representative_load.hpp,
/// the rule the report draws at too): Budget::magnitude if set, else the largest of the scene's
/// magnitudes whose reference strain (max_abs_strain_unit × magnitude) stays within 5 %, else the
/// smallest.
double budget_magnitude(const Scene& scene, double max_abs_strain_unit);

/// Time per update (s) and steps per update of a run that took `solve_seconds`: static solvers
/// (steps = 0) solve_seconds (their time per update already); integrators `steps` steps of `dt`
/// → per step × ⌈period/dt⌉ (at least 1).
std::pair<double, long> time_per_update(double solve_seconds, long steps, double dt, double period);

}  // namespace vessel
