#pragma once
/// `vesselverify validity`: the measured limit of the linear reference's validity, and the
/// mass-spring models and linear, corotational and XPBD P1 FEM judged against the finite-strain
/// reference over a load ladder, optionally with each model's time per update. For contact the
/// ladder spans seed 000's force range up to 140 mN. Per scene: the linear reference
/// (unit load, scaled) and one finite-strain continuation (fem::HyperelasticSolver with the
/// ladder as checkpoints, kept in the FEM solution cache) on the same mesh and elements; at each
/// load of the ladder the two references' relative difference at the QoI and over the mesh's
/// nodes, and each model's errors against the finite-strain reference. The loads where the
/// references part by 1 %, 5 % and 10 % are interpolated between ladder loads. Writes
/// validity.json (schema "vesselverify.validity", version 1; validity.schema.json), which the
/// report reads back (reports/study_files.hpp).
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/solution_cache.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// Where the references part: the thresholds the report shows (relative differences).
inline constexpr double kValidityThresholds[] = {0.01, 0.05, 0.10};

/// The load where a relative difference d(F) first reaches `threshold` on a ladder of loads.
struct ThresholdCrossing {
  double threshold = 0.0;
  /// "interpolated": between the ladder loads `lower` and `upper` (d(lower) < threshold ≤
  /// d(upper)), by linear interpolation of ln d against ln F (exact for d = c Fᵏ: at small loads
  /// d grows like F, the difference of the references being O(F²)); "below_ladder": reached
  /// already at the smallest load (load = upper = that load); "not_reached": below the threshold
  /// up to the largest load of the ladder (load empty, lower = that load).
  std::string status;
  std::optional<double> load;
  double lower = 0.0, upper = 0.0;
};

/// The crossing of `threshold` by `differences` (one per load, loads ascending and > 0).
/// std::invalid_argument for unequal or empty inputs, or loads not ascending.
ThresholdCrossing threshold_crossing(const std::vector<double>& loads,
                                     const std::vector<double>& differences, double threshold);

/// A model's update timed as `vesselverify run` times it (set-up apart), s.
struct ValidityTiming {
  double setup_seconds = 0.0;  ///< assembly, factorisation (XPBD FEM: its constraints)
  /// Linear P1 and the static models: the median update of a ramp of kRampUpdates warm-started
  /// updates to the load (timed_updates); XPBD FEM: its run from rest to steady state.
  double update_seconds = 0.0;
  long steps = 0;   ///< XPBD FEM: that run's steps; 0 otherwise
  double dt = 0.0;  ///< XPBD FEM: its step, s; 0 otherwise
  /// What a simulator pays per update at 30 Hz and at 1 kHz (harness/budget.hpp time_per_update:
  /// XPBD FEM's per-step cost × the steps one period holds; the others update_seconds).
  double update_seconds_30hz = 0.0, update_seconds_1khz = 0.0;
};

/// One model's errors against the finite-strain reference at one load.
struct ValidityModelError {
  std::string model;
  bool ok = false;
  std::string failure;       ///< why it gave no answer (ok false)
  double relative_l2 = 0.0;  ///< over its nodes, as results.json's relative L2
  double max_error_mm = 0.0;
  double qoi_error_mm = 0.0;     ///< |u_model − u_ref| at its QoI node
  double qoi_relative = 0.0;     ///< that over |u_ref| there
  double qoi_model_mm = 0.0;     ///< |u_model| at its QoI node
  int iterations = 0;  ///< Newton iterations of its update (XPBD FEM: steps; linear P1: 1)
  std::optional<ValidityTiming> timing;  ///< when ValidityOptions::time_updates
  /// The VTU of its fields against the finite-strain reference (written at the largest load
  /// reached when ValidityOptions::fields_dir is set); empty otherwise.
  std::filesystem::path fields_file;
};

/// One load of the ladder.
struct ValidityRow {
  double magnitude = 0.0;         ///< the scene's load unit
  double linear_qoi_mm = 0.0;     ///< |u| of the linear reference at the QoI point
  double finite_qoi_mm = 0.0;     ///< |u| of the finite-strain reference there
  double qoi_difference = 0.0;    ///< |u_lin − u_fs| / |u_fs| at the QoI point
  double l2_difference = 0.0;     ///< ‖u_lin − u_fs‖ / ‖u_fs‖ over the reference mesh's nodes
  double linear_strain = 0.0;     ///< the linear reference's largest |principal strain|
  /// How close the finite-strain wall comes to touching itself across the lumen: the smallest
  /// deformed distance between inner-wall nodes at least the inner radius apart at rest
  /// (closest_approach, meshes/self_contact.hpp), mm. None for a vessel from a file.
  std::optional<double> wall_gap_mm;
  int newton_iterations = 0;      ///< of the continuation up to this load (cumulative)
  int load_steps = 0;             ///< accepted, cumulative
  double finite_seconds = 0.0;    ///< assembly + solves up to this load (cumulative), s
  std::vector<ValidityModelError> models;
};

struct ValidityModel {
  std::string name, detail;
  int level = 0;
  std::size_t nodes = 0;
};

struct ValidityScene {
  std::string scene, source, load_kind, load_unit;
  double poisson_ratio = 0.0;
  int reference_level = 0, degree = 2, model_level = 0;
  std::string element;          ///< e.g. "P2"
  Vec3 qoi_point = Vec3::Zero();  ///< m, where the QoI columns are read
  std::size_t dofs = 0;
  std::vector<double> ladder;   ///< the loads asked for
  std::vector<ValidityModel> models;
  std::vector<ValidityRow> rows;  ///< the ladder's loads up to the largest reached
  std::vector<ThresholdCrossing> qoi_limits, l2_limits;  ///< one per kValidityThresholds
  /// The continuation: whether it reached the ladder's top, the largest load at which it found
  /// equilibrium (may lie between ladder loads) and why it stopped.
  bool completed = false;
  double largest_load = 0.0;
  std::string stop_reason;
  /// It stopped because the next load would make the wall pass through itself (the reference
  /// models no self-contact; fem::HyperelasticResult::self_contact).
  bool self_contact = false;
  int load_steps = 0, rejected_steps = 0, newton_iterations = 0;
  double finite_seconds = 0.0;  ///< assembly + linear solves of the continuation, s
  bool finite_from_cache = false;  ///< read from the FEM solution cache (its seconds: the original's)
  double seconds = 0.0;         ///< this scene's wall time in the study, s
};

struct ValidityOptions {
  /// false (default, the main job's): reference P2 on level 0, the short ladder of
  /// default_ladder, the seed models (stiffness seed000 / seed001). true: the scene's reference level, the full
  /// ladder, every whole-vessel static mass-spring model of the scene.
  bool full = false;
  /// The quick ladder (`verify.sh --quick`): contact 0.1, 1 and 10 mN, where the linear
  /// reference's 1, 5 and 10 % limits lie; other loads, the scene's largest alone.
  bool quick = false;
  int reference_level = -1;      ///< −1: as `full` says
  int degree = 2;                ///< the references' elements
  std::vector<double> ladder;    ///< scene's unit; empty: as `full` says
  std::vector<std::string> models;  ///< model names; empty: as `full` says
  std::filesystem::path mesh_cache_dir;  ///< generated meshes ("" none)
  /// Each model's fields against the finite-strain reference at the largest load reached, as
  /// `vesselverify run` writes them (harness/model_readout.hpp write_fields_vtu), under
  /// <fields_dir>/<scene>/; "" none.
  std::filesystem::path fields_dir;
  /// Each model's update also timed afresh at each load (ValidityTiming), scenes one at a time.
  bool time_updates = false;
  fem::SolutionCache* cache = nullptr;   ///< the finite-strain continuation and linear solve
  fem::HyperelasticOptions finite;       ///< Newton settings (target and checkpoints: the study's)
  std::ostream* log = nullptr;
};

/// The default ladders: contact (N) 0.1, 0.3, 1, 3, 10, 30, 50, 70 mN (full: 20 loads from
/// 0.01 mN to seed 000's 140 mN; quick: 0.1, 1, 10 mN); other loads, 50 % and 100 % of the
/// scene's largest (full: 1, 10, 25, 50, 75, 100 %; quick: 100 %).
std::vector<double> default_ladder(const Scene& scene, bool full, bool quick = false);

/// The study on one scene at its first Poisson's ratio. InputError for a scene it cannot run
/// (a dynamic or modal-only scene, a model named that is not a whole-vessel static mass-spring
/// model, linear P1 FEM, corotational P1 or XPBD FEM).
ValidityScene run_validity_scene(const Scene& scene, const ValidityOptions& options);

/// run_validity_scene for each scene, `jobs` scenes at a time (one at a time when it times the
/// models' updates). With jobs > 1 the meshes are made first, one at a time (gmsh is not
/// thread-safe), and the threads read them from the mesh cache; without a mesh cache, one at a
/// time. In the scenes' order.
std::vector<ValidityScene> run_validity(const std::vector<Scene>& scenes,
                                        const ValidityOptions& options, int jobs);

struct ValidityStudy {
  std::string command;
  bool full = false;
  double total_seconds = 0.0;
  std::vector<ValidityScene> scenes;
};

/// The study as one record: run_validity over `scenes`, its wall time, the command recorded.
ValidityStudy run_validity_study(const std::vector<Scene>& scenes, const ValidityOptions& options,
                                 int jobs, const std::string& command);

/// validity.json (schema "vesselverify.validity", version 1), written atomically.
void write_validity_json(const ValidityStudy& study, const std::filesystem::path& path);

/// A short text summary per scene (what the command prints).
void print_validity_summary(const ValidityStudy& study, std::ostream& out);

}  // namespace vessel
