#pragma once
/// The verification harness: runs a scene's models against the FEM reference and measures the
/// displacement error and the time of each, for every Poisson's ratio and load magnitude.
///
/// The reference is P2 (Taylor–Hood P2–P1 where ν calls for it) on the scene's reference level,
/// evaluated at each model node's rest position; the same reference on the level below gives its
/// own discretisation uncertainty (pointwise Richardson; its order observed on three levels where the
/// scene's reference level allows, else assumed: ReferenceInfo::gci_order), which
/// is reported next to every model error. Linear FEM responses are solved once per ν for a unit
/// load and scaled; mass-spring models are solved for every magnitude (they are nonlinear).
///
/// The parts: outcome.hpp (the records), options.hpp, references.hpp (the references and their
/// scheduling), model_runs.hpp (FEM, mass-spring and outside models), metrics.hpp (every error
/// quantity), budget.hpp, timed_updates.hpp; results.hpp writes what a run returns.
#include <vector>

#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// The --quick variant of a scene: the coarsest useful levels (models at 0, reference at 1 so that
/// level 0 gives its uncertainty) and only the smallest and largest load. Taylor–Hood (ν ≥ 0.49)
/// goes to a direct solver that needs minutes and gigabytes at level 1, so scenes with such a ν
/// keep their reference at level 0 (then without an uncertainty estimate). A guidewire's
/// coupling = "contact" becomes "compliant" (the series springs without the contact solve).
Scene quick_variant(Scene scene);

/// Runs the scene. Throws InputError for inputs the scene validation cannot see (a contact point
/// off the generated wall, roller ends on the arch); a model that fails (diverges, does not
/// converge) is recorded as failed with its reason, and the others still run.
SceneResult run_scene(const Scene& scene, const HarnessOptions& options);

/// Runs the scenes: with options.jobs > 1 every scene's references first, in parallel, then each
/// scene's models, one at a time; otherwise run_scene after run_scene. A header line per scene on
/// options.log. The results are the same either way (the FEM solves agree to round-off).
std::vector<SceneResult> run_scenes(const std::vector<Scene>& scenes, const HarnessOptions& options);

}  // namespace vessel
