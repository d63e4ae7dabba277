#pragma once
/// The harness's records: what a run of a scene produces (the reference's answer per ν, each
/// model's outcome at one ν, level and load, natural frequencies) and the error statistics and
/// quantities inside them. Plain data: the code that fills them is in references, metrics and
/// the model runs; results.hpp writes them.
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "meshes/lumen_mesh.hpp"
#include "meshes/mesh_quality.hpp"
#include "meshes/tet_mesh.hpp"
#include "verification/guidewire/guidewire_outcome.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// A model's nodal error against the reference at the same points: the statistics seed 000
/// reports (max, mean, standard deviation, RMS of the nodal error) plus the relative L2 error, mm.
struct GuidewireContact;  // verification/harness/guidewire_contact.hpp

struct ErrorStatistics {
  double max_mm = 0.0;     ///< max_i |u_i − u_ref,i|
  double mean_mm = 0.0;    ///< mean of |e_i|
  double stddev_mm = 0.0;  ///< population standard deviation of |e_i|
  double rms_mm = 0.0;     ///< sqrt(mean |e_i|²)
  double relative_l2 = 0.0;  ///< sqrt(Σ|e_i|²) / sqrt(Σ|u_ref,i|²) (0 if the reference is 0)
  std::size_t points = 0;
  /// sqrt(Σ|u_i|²) / sqrt(Σ|u_ref,i|²) (0 if the reference is 0): with relative_l2 it gives the
  /// relative L2 error of the model's field scaled against the reference's (guidewire coupling).
  double model_l2_over_reference = 0.0;
};

/// The reference's answer for one ν (at unit load; scale by the magnitude).
struct ReferenceInfo {
  double poisson_ratio = 0.0;
  std::string element;
  int level = 0;
  std::size_t dofs = 0;
  double solve_seconds = 0.0;  ///< fine level, assembly + solve
  double max_abs_strain_unit = 0.0;  ///< largest |principal strain| at unit load
  double budget_magnitude = 0.0;     ///< the load the budget applies at for this ν (scene's unit)
  /// The order of the linear reference's Richardson/GCI uncertainty (fem::gci_order): observed
  /// from the QoI on three levels when the scene's reference level is ≥ 2, else assumed
  /// (kAssumedReferenceOrder*); gci_order_source "none" without a coarser level.
  double gci_order = 0.0;
  std::string gci_order_source = "none";  ///< observed | assumed | none
  double gci_safety_factor = 0.0;
  std::string gci_note;
};

/// The error on each quantity a budget may name (issue #7), against the reference at the model's
/// own nodes. Unset optionals: not computable for this scene (reaction: contact loads only; patch:
/// the budget names no patch radius).
struct QuantityErrors {
  /// |u_model − u_ref| at the QoI (contact) node, mm; for integrators the larger of that (final
  /// state against the static reference) and the history's largest difference from the FEM
  /// transient there.
  double contact_point_mm = 0.0;
  double field_mm = 0.0;           ///< max |u_model − u_ref| over all model nodes, mm
  std::optional<double> patch_mm;  ///< max within the budget's radius of the QoI point, mm
  /// Contact loads: the indentation d = Σ f_i·u_i / |Σ f_i| (work-conjugate to the total contact
  /// force, over the model's loaded nodes, the same nodal loads for model and reference), mm.
  std::optional<double> indentation_mm, indentation_reference_mm;
  /// Contact loads: the force the instrument feels when it imposes the reference's indentation,
  /// F·d_ref/d_model (secant contact stiffness), minus the true force F, |·| in mN; infinite if
  /// the model does not indent.
  std::optional<double> reaction_mN;
};

/// Radial displacement u·e_ρ along the wall line through the QoI point (the model's nodes at the
/// QoI's angle around the centreline and nearest its radius), sorted by arc length s.
struct WallProfile {
  std::vector<double> s_mm;
  std::vector<double> model_mm;
  std::vector<double> reference_mm;
};

/// The QoI displacement magnitude over time (dynamic models), sampled. The reference is the FEM
/// transient (Newmark, average acceleration) of the same step load on the reference mesh, at the
/// model's QoI node, with the model's point damping mapped to mass-proportional damping,
/// interpolated linearly to the model's sample times.
struct History {
  std::vector<double> time_s;
  std::vector<double> model_mm;
  std::vector<double> reference_mm;
  double max_error_mm = 0.0;  ///< max over the samples of |model − reference|
  long steps = 0;
  double simulated_s = 0.0;   ///< dt × steps
  double mass_damping = 0.0;  ///< α of the FEM transient, 1/s
  int reference_level = 0;    ///< mesh level of the FEM transient (P2)
};

/// Where a measured outcome's timings come from (verification/harness/outcome_cache.hpp).
struct TimingProvenance {
  bool cached = false;      ///< read from the outcome cache instead of measured in this run
  std::string measured_at;  ///< when they were measured, UTC (ISO 8601); empty if unknown
};

/// One model at one (ν, level, magnitude).
struct ModelOutcome {
  std::string model;
  std::string kind;       ///< fem | surface_msm | volume_msm
  std::string detail;     ///< element or topology, rules, solver
  double poisson_ratio = 0.0;
  double magnitude = 0.0;  ///< N, Pa or g
  int level = 0;           ///< mesh level of the model
  bool ok = false;
  std::string failure;     ///< why it did not finish (divergence, no convergence, ...)
  std::size_t nodes = 0;
  std::size_t unknowns = 0;  ///< DoFs or 3 × free nodes
  /// Model build, plus for mass-spring models the solver's preparation (static and linear:
  /// assembly and factorisation at rest, msm::prepare_updates; implicit-euler-rest its
  /// factorisation), for FEM models the solver's construction, the assembly of its system on the
  /// free DoFs and the "linear" updater's preparation (timed_fem_updates), s; median over repeats
  /// where timed per repeat.
  double setup_seconds = 0.0;
  /// The solver's time after set-up, s. Static and linear mass-spring models: the time per
  /// update, the median over the warm-started updates of a load ramp to the case's magnitude
  /// (timed_updates); dynamic ones: the run's steps (median over repeats); FEM: the median
  /// update of the same ramp by the "linear" updater the mass-spring models' linear solver uses
  /// (timed_fem_updates: K factorised once).
  double solve_seconds = 0.0;
  /// Static and linear mass-spring models and FEM: the ramp's updates (0: timed as one solve),
  /// and per update the mean Newton iterations and CHOLMOD factorisations (last repeat).
  int updates = 0;
  double iterations_per_update = 0.0;
  double factorisations_per_update = 0.0;
  /// Peak resident memory added by set-up and solve; 0 for models outside the suite (a child
  /// process's peak is not measured: wait4's ru_maxrss counts the memory it shared with this
  /// process while being spawned).
  double memory_mib = 0.0;
  /// Where setup_seconds and solve_seconds come from for models outside the suite: "simulator"
  /// (the simulator's own timing.json), "process" (the wall time of its whole process: start-up
  /// and file I/O included), "none" (displacements read from files: no time); empty for the
  /// suite's own models, which it times itself.
  std::string timing_source;
  ErrorStatistics error;       ///< against the reference at the model's nodes
  ErrorStatistics reference_uncertainty;  ///< the reference's own estimated error there (max, rms)
  bool has_reference_uncertainty = false;  ///< false when the reference has no coarser level
  double qoi_displacement_mm = 0.0;  ///< model displacement magnitude at the node nearest the QoI point
  double qoi_reference_mm = 0.0;     ///< reference there
  double max_strain = 0.0;           ///< largest strain of the model (springs or FEM)
  bool beyond_linear_regime = false;  ///< max strain of the reference > 5 %
  /// Which reference judged the case: "linear" or "finite-strain" (the scene's `reference`).
  std::string reference = "linear";
  WallProfile wall_profile;
  History history;  ///< dynamic models only
  double roi_radius = 0.0;  ///< m; 0: the whole vessel
  QuantityErrors quantities;
  /// The scene's budget quantity's error (mm, or mN for reaction); NaN without a [budget].
  double budget_error = std::numeric_limits<double>::quiet_NaN();
  /// Compute time per update at the budget's rate, s: solve_seconds for static solvers (the
  /// ramp's median update); for integrators the time per step × the steps one update period
  /// needs (at least 1). Set-up is excluded. 0 without a budget rate.
  double update_seconds = 0.0;
  long steps_per_update = 0;  ///< integrators with a budget rate
  /// The VTU the run wrote this case's fields to (model and reference displacements, error);
  /// empty when it wrote none.
  std::filesystem::path fields_file;
  TimingProvenance timing;  ///< measured in this run, or read from the outcome cache
};

/// The lowest natural frequencies of one model, or of the modal reference, at one ν and level
/// (the scene's [modes]): mass-spring models K φ = ω² M φ with K their exact Hessian at rest and
/// M their lumped masses (msm::natural_frequencies); FEM models and the reference with the
/// consistent mass (fem::ElasticitySolver::modes). The scene's supports are held in both.
struct ModalOutcome {
  std::string model;   ///< the model's name; "reference" for the modal reference
  std::string kind;    ///< fem | surface_msm | volume_msm
  std::string detail;  ///< element and mass (FEM), or the model's description
  double poisson_ratio = 0.0;
  int level = 0;
  bool ok = false;
  std::string failure;
  std::vector<double> frequencies_hz;  ///< ascending
  int mechanisms = 0;       ///< zero-frequency modes among them (mass-spring models)
  std::size_t dofs = 0;     ///< free dofs of the eigenproblem
  double seconds = 0.0;     ///< assembly, factorisation and Lanczos
};

struct SceneResult {
  Scene scene;
  Vec3 qoi_point = Vec3::Zero();  ///< where the "contact-point displacement" is read
  /// Contact loads: the patch's mean outward unit normal on the reference mesh's wall.
  Vec3 contact_normal = Vec3::Zero();
  std::vector<ReferenceInfo> references;
  std::vector<ModelOutcome> outcomes;
  /// Natural frequencies (scene.modes.count > 0): the modal reference per ν, then each model's.
  std::vector<ModalOutcome> reference_modes;
  std::vector<ModalOutcome> model_modes;
  /// A guidewire load: the wire and each model's coupled contact force (guidewire_coupling.hpp).
  std::optional<GuidewireOutcome> guidewire;
  /// coupling = "contact": each model's wall in a contact solve with the wire
  /// (guidewire_contact.hpp); null otherwise.
  std::shared_ptr<const GuidewireContact> guidewire_contact;
  /// A vessel from a lumen file: its ends, each with its group (inlet or outlet).
  std::vector<std::pair<std::string, LumenEnd>> lumen_ends;
  /// Each mesh the scene ran on (models' levels and the reference's): its dihedral extremes and
  /// slivers, by level. A model's error on a mesh with slivers includes the mesh's.
  std::map<int, SliverReport> mesh_slivers;
  double seconds = 0.0;
};

}  // namespace vessel
