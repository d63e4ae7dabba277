#pragma once
/// One model of a scene at one ν and level, at every load magnitude, against the scene's
/// references: FEM models (fem_model_run.cpp), mass-spring models (msm_model_run.cpp) and models
/// outside the suite (outside_model_run.cpp). Each appends its outcomes (and natural frequencies)
/// to `result`; a model that fails is recorded as failed with its reason, and the run goes on.
#include "fem_reference/elasticity.hpp"
#include "meshes/tet_mesh.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/harness/progress.hpp"
#include "verification/harness/references.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// A FEM model: always the displacement formulation of its degree, so that P1's locking near
/// ν = 0.5 shows; at ν = 0.5, where that element cannot be used, it is recorded as failed.
void run_fem_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                   const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                   const HarnessOptions& o, ModelOutcome base, SceneResult& result);

/// A mass-spring model at every load magnitude.
void run_msm_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                   const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                   const HarnessOptions& o, Progress& progress, ModelOutcome base,
                   SceneResult& result);

/// A P1 tet model on the scene's mesh (kinds corotational_fem and xpbd_fem; msm/fem) at every
/// load: corotational P1 by static Newton with its consistent tangent, timed as warm-started
/// updates of the load ramp; XPBD FEM stepped from rest to its steady state (its time per update
/// is then the time per step × the steps an update period holds, as for the integrators).
void run_tet_fem_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                       const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                       const HarnessOptions& o, Progress& progress, ModelOutcome base,
                       SceneResult& result);

/// What a P1 tet model (kinds corotational_fem and xpbd_fem) is, for the results' detail column.
std::string tet_fem_detail(const ModelSpec& spec);

/// A model outside the suite (kinds external and displacements; verification/harness/external_model.hpp)
/// at every load: the case written to its exchange folder and its command run (external), or the
/// answer read from the folder the export named (displacements); then compared as any model. A
/// case whose command fails, times out or answers badly is recorded as failed with the reason,
/// and the run goes on.
void run_outside_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                       const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                       const HarnessOptions& o, Progress& progress, ModelOutcome base,
                       SceneResult& result);

}  // namespace vessel
