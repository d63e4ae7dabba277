#pragma once
/// Natural frequencies in the harness (the scene's [modes], issue 14): the modal reference, the
/// scene's FEM models' and each mass-spring model's lowest modes, as ModalOutcome
/// (verification/harness/outcome.hpp). The eigen-solvers are the libraries' (fem::ElasticitySolver::modes,
/// msm::natural_frequencies); this file only says which problem each one gets.
#include <string>

#include "fem_reference/elasticity.hpp"
#include "msm/form/form.hpp"
#include "verification/harness/outcome.hpp"

namespace vessel {

/// The mesh level the modal reference runs at: scene.modes.reference_level, else the scene's
/// reference_level.
int modal_reference_level(const Scene& scene);

/// The modal reference at ν: P2, displacement formulation (the mixed Taylor–Hood system has no
/// modal analysis; at ν ≥ 0.49 P2's displacement form is used, at ν = 0.5 it is recorded as
/// failed), consistent mass, the scene's supports and density, on `mesh` (the scene's vessel at
/// `level`). A failure is recorded, not thrown.
ModalOutcome reference_modes(const Scene& scene, double nu, const TetMesh& mesh, int level);

/// The lowest scene.modes.count modes of a FEM model already set up (displacement formulation),
/// named and placed as `base` says.
ModalOutcome fem_model_modes(const fem::ElasticitySolver& solver, const ModelOutcome& base,
                             int count);

/// The lowest `count` modes of a mass-spring model's problem (its supports held, its lumped
/// masses); a failure (e.g. a Hessian that is not positive semi-definite) is recorded.
ModalOutcome msm_model_modes(const msm::Problem& problem, const ModelOutcome& base, int count);

}  // namespace vessel
