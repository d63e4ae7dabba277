#pragma once
/// Private to fem_reference: the checks of an ElasticityProblem shared by the serial and the
/// distributed solver. Free of deal.II.
#include "fem_reference/elasticity.hpp"

namespace vessel::fem::detail {

/// InputError naming the parameter, group or load for a problem neither solver can solve: E ≤ 0,
/// ν ∉ [0, 0.5], density < 0, degree ∉ {1, 2}, ν = 0.5 with the displacement formulation, a
/// mixed threshold ≤ 0, a non-positive CG tolerance or iteration limit, non-finite gravity, a
/// missing group, a bad roller or point-constraint component, a non-finite pressure, and a traction
/// patch with a non-finite traction or a point off the mesh's triangles or with non-finite
/// barycentric coordinates or weight. Depends on the input only, so every MPI rank throws alike.
void validate_problem(const TetMesh& mesh, const ElasticityProblem& problem);

/// Whether the problem is solved with the mixed Taylor–Hood element: asked for, or automatic at
/// ν ≥ options.mixed_threshold (and always at ν = 0.5, where λ is infinite).
[[nodiscard]] bool uses_mixed_formulation(const ElasticityProblem& problem);

}  // namespace vessel::fem::detail
