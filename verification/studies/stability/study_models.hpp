#pragma once
/// The stability study's shared pieces (internal to verification/studies/stability): the models
/// each hard case runs, the FEM runs beside them, and how a run becomes a HardCaseOutcome.
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "verification/studies/stability/stability.hpp"

namespace vessel::stability_study {

using msm::Integrator;

/// A sink for progress when the options give no log.
std::ostream& null_stream();
/// `v` with `precision` significant digits.
std::string fmt(double v, int precision = 4);
/// An error message cut to 300 characters.
std::string short_error(const std::string& what);

/// Default contact point: inner wall at mid-length on the θ = 0 side (as `vesselverify msm`).
Vec3 default_contact_point(const VesselParams& p);
int nearest_node(const std::vector<Vec3>& nodes, const Vec3& p);

/// A mass-spring model on a mesh with the shared contact load, inlet and outlet fixed.
struct Msm {
  msm::BuiltNetwork built;
  std::unique_ptr<msm::SpringModel> model;
  msm::Problem problem;
  Vec3 point = Vec3::Zero();
  int contact_node = 0;
  [[nodiscard]] double contact_displacement(const Eigen::VectorXd& x) const {
    return (x.segment<3>(3 * contact_node) - problem.rest.segment<3>(3 * contact_node)).norm();
  }
};

struct ModelSpec {
  std::string model;  ///< surface | volume
  msm::StiffnessRule rule;
  [[nodiscard]] std::string name() const { return model + " / " + msm::to_string(rule); }
};

std::unique_ptr<Msm> make_msm(const TetMesh& mesh, const VesselParams& params,
                              const ModelSpec& spec, double E, double nu, double force,
                              const Vec3& point, double patch_radius = 0.5e-3,
                              double point_damping = 0.0);
/// The same network with point damping c (a new SpringModel; problem copied).
std::unique_ptr<Msm> with_damping(const Msm& base, double c);
double mean_mass(const msm::Problem& p);

struct FemRun {
  bool ok = false;
  std::string error;
  std::string element;
  double u_contact = 0.0;  ///< m
  double max_strain = 0.0;
  double seconds = 0.0;
  std::vector<Vec3> u;
};

FemRun run_fem(const TetMesh& mesh, double E, double nu, int degree, fem::Formulation f,
               const Vec3& point, double force, double patch_radius = 0.5e-3);

/// Tets of `mesh` with non-positive signed volume when its nodes are at `x`.
std::size_t inverted_tets(const TetMesh& mesh, const std::vector<Vec3>& x);
std::vector<Vec3> unflatten(const Eigen::VectorXd& x);

HardCaseOutcome fem_outcome(const std::string& name, const FemRun& r);
/// Static Newton on an Msm; outcome with the contact displacement.
HardCaseOutcome static_outcome(const std::string& name, const Msm& m,
                               Eigen::VectorXd* x_out = nullptr);
/// A dynamic run; outcome bounded or the DivergenceError's message.
HardCaseOutcome dynamic_outcome(const std::string& name, const msm::Problem& p, Integrator in,
                                double dt, int steps, const Eigen::VectorXd& v0 = {},
                                Eigen::VectorXd* x_out = nullptr);
/// Predicted and found symplectic-Euler step of a model, as an outcome.
HardCaseOutcome step_outcome(const std::string& name, const Msm& m, int steps);

/// The vessel's mesh from the options' cache.
TetMesh load_mesh(const VesselParams& p, const StabilityOptions& o);

/// An explicit integrator and the damping ratio its point damping targets on the top mode.
struct IntegratorConfig {
  Integrator integrator;
  double zeta;  ///< target damping ratio on the top mode; 0: undamped
};

// (a) predicted vs found critical steps (critical_steps.cpp)
std::vector<CriticalStepRow> critical_step_table(const StabilityOptions& o, int max_level,
                                                 int steps, std::ostream& log);
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
