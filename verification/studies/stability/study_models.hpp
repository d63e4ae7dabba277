#pragma once
/// The stability study's shared pieces (internal to verification/studies/stability): the models
/// each hard case runs, the FEM runs beside them, and how a run becomes a HardCaseOutcome.
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"
#include "verification/studies/stability/stability.hpp"

namespace vessel::stability_study {

using msm::Integrator;

/// A sink for progress when the options give no log.
std::ostream& null_stream();
/// `v` with `precision` significant digits.
std::string fmt(double v, int precision = 4);
/// An error message cut to 300 characters.
std::string short_error(const std::string& what);

/// A case's problem as a Scene, for scene_problems to build (the one place that builds FEM and
/// mass-spring problems): the vessel `vessel`, Young's modulus E (Pa), both ends clamped, and a
/// contact load of `force` (N) on a patch of radius `patch_radius` (m) on the inner wall at the
/// shared default contact point (default_contact_point). ν is given per run.
Scene study_scene(const VesselParams& vessel, double E, double force,
                  double patch_radius = ContactPatchSpec{}.radius);

/// The study's mass-spring models: consistent masses, the inner wall for surface models, named
/// "volume / seed001" in its tables.
ModelSpec volume_model(msm::StiffnessRule rule);
ModelSpec surface_model(msm::StiffnessRule rule);

/// A mass-spring model of a case's scene on one mesh, with its problem (loads and supports).
struct StudyModel {
  msm::BuiltNetwork built;
  std::unique_ptr<msm::MassSpringModel> model;
  msm::Problem problem;
  std::size_t contact_node = 0;  ///< the network node nearest the scene's contact point
  [[nodiscard]] double contact_displacement(const Eigen::VectorXd& x) const {
    const auto i = static_cast<Eigen::Index>(3 * contact_node);
    return (x.segment<3>(i) - problem.rest.segment<3>(i)).norm();
  }
};

/// The model `spec` of `scene` at ν on `mesh` (the scene's generated mesh, or one a case made
/// from it): network_options, msm::build_network and msm_problem of scene_problems, the point
/// damping of spec.damping, the contact load at the scene's magnitude.
std::unique_ptr<StudyModel> build_model(const Scene& scene, const TetMesh& mesh,
                                        const ModelSpec& spec, double nu);
/// The same network and problem with point damping c, N·s/m per node (a new model).
std::unique_ptr<StudyModel> with_damping(const StudyModel& base, double c);
double mean_mass(const msm::Problem& p);

struct FemRun {
  bool ok = false;
  std::string error;
  std::string element;
  double u_contact = 0.0;  ///< m, at the mesh node nearest the contact point
  double max_strain = 0.0;
  double seconds = 0.0;
  std::vector<Vec3> u;
};

/// The FEM reference of `scene` at ν on `mesh` (fem_problem of scene_problems) with elements of
/// `degree` in formulation `f` (the study chooses it: the ν → 0.5 case compares them) and the
/// direct solver. Errors are recorded in the run, not thrown.
FemRun run_fem(const Scene& scene, const TetMesh& mesh, double nu, int degree, fem::Formulation f);

std::vector<Vec3> unflatten(const Eigen::VectorXd& x);

HardCaseOutcome fem_outcome(const std::string& name, const FemRun& r);
/// Static Newton on a model; outcome with the contact displacement.
HardCaseOutcome static_outcome(const std::string& name, const StudyModel& m,
                               Eigen::VectorXd* x_out = nullptr);
/// A dynamic run; outcome bounded or the DivergenceError's message.
HardCaseOutcome dynamic_outcome(const std::string& name, const msm::Problem& p, Integrator in,
                                double dt, int steps, const Eigen::VectorXd& v0 = {},
                                Eigen::VectorXd* x_out = nullptr);
/// Predicted and found symplectic-Euler step of a model, as an outcome.
HardCaseOutcome step_outcome(const std::string& name, const StudyModel& m, int steps);

/// The scene's generated mesh at its vessel's level (scene_mesh), from the options' cache.
TetMesh case_mesh(const Scene& scene, const StabilityOptions& o);

/// An explicit integrator and the damping ratio its point damping targets on the top mode.
struct IntegratorConfig {
  Integrator integrator;
  double zeta;  ///< target damping ratio on the top mode; 0: undamped
};

// (a) predicted vs found critical steps (critical_steps.cpp); `provenance`: one per (level,
// model), whether its rows were computed or read from o.outcome_cache
std::vector<CriticalStepRow> critical_step_table(const StabilityOptions& o, int max_level,
                                                 int steps, std::ostream& log,
                                                 std::vector<TimingProvenance>& provenance);
std::vector<RefinementFit> refinement_fits(const std::vector<CriticalStepRow>& rows);

// (b) the hard cases, one file each (case_<id>.cpp), in kHardCaseIds' order
HardCase case_poisson(const StabilityOptions& o, std::ostream& log);
HardCase case_youngs_modulus(const StabilityOptions& o, std::ostream& log);
HardCase case_sliver(const StabilityOptions& o, std::ostream& log);
HardCase case_refined_patch(const StabilityOptions& o, std::ostream& log);
HardCase case_inverting_load(const StabilityOptions& o, std::ostream& log);
HardCase case_long_run(const StabilityOptions& o, std::ostream& log);
HardCase case_tight_bend(const StabilityOptions& o, std::ostream& log);
HardCase case_zero_length(const StabilityOptions& o, std::ostream& log);

}  // namespace vessel::stability_study
