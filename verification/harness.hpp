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
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "msm/model/form.hpp"
#include "msm/solvers/solve.hpp"
#include "verification/metrics.hpp"
#include "verification/scene.hpp"

namespace vessel::fem {
class SolutionCache;
}

namespace vessel {

class OutcomeCache;  // verification/outcome_cache.hpp

/// Updates of the load ramp static and linear mass-spring models are timed on (timed_updates).
inline constexpr int kRampUpdates = 8;

struct HarnessOptions {
  std::filesystem::path cache_dir;  ///< generated meshes (empty: no cache)
  /// FEM references solved once and kept on disk (nullptr: each solved afresh). The FEM models
  /// the scene times (P1, P2 as models) are always solved: their time is a measurement.
  fem::SolutionCache* solution_cache = nullptr;
  /// The models' outcomes (timings included) kept on disk per model, ν and level, keyed by their
  /// definition and by the executable and machine (nullptr: every model measured). Models outside
  /// the suite (external, displacements) are always run.
  OutcomeCache* outcome_cache = nullptr;
  std::ostream* log = nullptr;      ///< progress; nullptr for none
  int repeats = 1;                  ///< timed repeats of each model solve (median reported)
  /// Static and linear mass-spring models: updates in the timed load ramp (timed_updates).
  int ramp_updates = kRampUpdates;
  /// Run the models only at the budget's load (Budget::magnitude, else the representative load:
  /// the largest magnitude within the reference's linear regime, else the smallest), per ν.
  bool budget_load_only = false;
  /// VTU fields for ParaView (model and reference displacement and their difference at the
  /// model's nodes) written under fields_dir/<scene>/, one file per model, ν and level; empty:
  /// none. Only at the representative load (budget_magnitude()) unless fields_every_load.
  std::filesystem::path fields_dir;
  bool fields_every_load = false;
  /// run_scenes: FEM references solved this many at a time before the models (> 1), each sparse
  /// factorisation with cores / jobs threads; the models always run one at a time, because their
  /// set-up and update times are measurements. 1: scene after scene, each ν's reference just
  /// before its models.
  int jobs = 1;
  /// Models of kind `external`: their case folders go under exchange_dir/<scene>/<model>/<case>
  /// (verification/external_model.hpp); empty: a folder under the system's temporary directory.
  std::filesystem::path exchange_dir;
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

/// Where a measured outcome's timings come from (verification/outcome_cache.hpp).
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

/// f_model,k / f_reference,k mode by mode (modes paired by rank, both sorted ascending); as many
/// as both have, 0 where the reference's frequency is 0.
std::vector<double> frequency_ratios(const ModalOutcome& model, const ModalOutcome& reference);

struct SceneResult {
  Scene scene;
  Vec3 qoi_point = Vec3::Zero();  ///< where the "contact-point displacement" is read
  std::vector<ReferenceInfo> references;
  std::vector<ModelOutcome> outcomes;
  /// Natural frequencies (scene.modes.count > 0): the modal reference per ν, then each model's.
  std::vector<ModalOutcome> reference_modes;
  std::vector<ModalOutcome> model_modes;
  double seconds = 0.0;
};

/// The --quick variant of a scene: the coarsest useful levels (models at 0, reference at 1 so that
/// level 0 gives its uncertainty) and only the smallest and largest load. Taylor–Hood (ν ≥ 0.49)
/// goes to a direct solver that needs minutes and gigabytes at level 1, so scenes with such a ν
/// keep their reference at level 0 (then without an uncertainty estimate).
Scene quick_variant(Scene scene);

/// The load the budget applies at: the scene's representative_load (reports/representative_load.hpp,
/// the rule the report draws at too): Budget::magnitude if set, else the largest of the scene's
/// magnitudes whose reference strain (max_abs_strain_unit × magnitude) stays within 5 %, else the
/// smallest.
double budget_magnitude(const Scene& scene, double max_abs_strain_unit);

/// The budget quantities of a model state: displacements u_model and u_ref (m) at the model's
/// nodes, its QoI node index and point, `loads` the model's nodal loads (N, per node; empty
/// unless the load is a contact: no indentation or reaction then), `history` the dynamic history
/// (empty for static models). The patch error is computed when budget.quantity is patch.
QuantityErrors quantity_errors(const Budget& budget, const std::vector<Vec3>& nodes,
                               const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref,
                               std::size_t qoi, const Vec3& qoi_point,
                               const std::vector<Vec3>& loads, const History& history);

/// The budget quantity's value among the quantity errors (NaN if not computable).
double budget_quantity_error(const QuantityErrors& q, BudgetQuantity quantity);

/// Time per update (s) and steps per update of a run that took `solve_seconds`: static solvers
/// (steps = 0) solve_seconds (their time per update already); integrators `steps` steps of `dt`
/// → per step × ⌈period/dt⌉ (at least 1).
std::pair<double, long> time_per_update(double solve_seconds, long steps, double dt, double period);

/// A static or linear mass-spring model timed as a simulator runs it (msm/solvers/updates.hpp):
/// prepared once, then `updates` updates whose loads ramp to the problem's external_force
/// (f·k/updates, k = 1 … updates), each from the previous state. `repeats` times afresh.
struct UpdateSequence {
  Eigen::VectorXd x;            ///< the last update's state, at the full load, m
  double setup_seconds = 0.0;   ///< msm::prepare_updates, median over the repeats, s
  double update_seconds = 0.0;  ///< median over every update of every repeat, s
  int updates = 0;
  double iterations_per_update = 0.0;      ///< mean over the last repeat
  double factorisations_per_update = 0.0;  ///< mean over the last repeat (set-up excluded)
};
/// InputError if the solver has no prepared updates (msm::supports_updates) or updates < 1.
UpdateSequence timed_updates(const msm::Problem& problem, const msm::SolverSpec& solver,
                             int updates, int repeats);

/// Runs the scene. Throws InputError for inputs the scene validation cannot see (a contact point
/// off the generated wall, roller ends on the arch); a model that fails (diverges, does not
/// converge) is recorded as failed with its reason, and the others still run.
SceneResult run_scene(const Scene& scene, const HarnessOptions& options);

/// Runs the scenes: with options.jobs > 1 every scene's references first, in parallel, then each
/// scene's models, one at a time; otherwise run_scene after run_scene. A header line per scene on
/// options.log. The results are the same either way (the FEM solves agree to round-off).
std::vector<SceneResult> run_scenes(const std::vector<Scene>& scenes, const HarnessOptions& options);

/// run_scenes, then writes
/// results.json (with reference_kernel_seconds() timed first), results.csv and summary.md into
/// `output_dir`, which is created and checked writable before anything runs (InputError).
std::vector<SceneResult> run_and_write(const std::vector<Scene>& scenes,
                                       const HarnessOptions& options,
                                       const std::filesystem::path& output_dir,
                                       const std::string& command);

/// Results as versioned JSON (schema "vesselverify.results", version 1; see
/// verification/results.schema.json), CSV (one row per model, ν and magnitude) and a Markdown
/// summary table; each written atomically.
/// `reference_kernel_seconds` (reference_kernel_seconds() of the same run, for the gate's
/// normalised timings) is written when positive.
void write_results_json(const std::filesystem::path& path, const std::vector<SceneResult>& results,
                        const std::string& command, double reference_kernel_seconds = 0.0);
void write_results_csv(const std::filesystem::path& path, const std::vector<SceneResult>& results);
void write_summary_markdown(const std::filesystem::path& path,
                            const std::vector<SceneResult>& results, const std::string& command);

}  // namespace vessel
