#pragma once
/// The one rule for the load a scene is judged and drawn at, shared by the harness (the budget's
/// load, the fields it writes) and the report (its summary and figures).
#include <optional>
#include <vector>

namespace vessel {

/// Linear elasticity is a valid reference only at small strain (its strain measure drops the
/// quadratic terms of the Green–Lagrange strain, ½∇uᵀ∇u, which at 5 % strain is about 2.5 % of
/// the linear one): a load whose largest reference strain exceeds this is outside the linear
/// regime.
inline constexpr double kLinearRegimeStrain = 0.05;

/// The representative load: `budget_magnitude` when the scene's budget sets one, else the largest
/// of `magnitudes` whose reference strain (max_abs_strain_at_unit_load × magnitude) stays within
/// kLinearRegimeStrain, else the smallest of `magnitudes`. All in the scene's load unit (N, Pa or
/// multiples of g); the strain is the reference's largest absolute principal strain at unit load.
double representative_load(const std::vector<double>& magnitudes,
                           double max_abs_strain_at_unit_load,
                           std::optional<double> budget_magnitude);

}  // namespace vessel
