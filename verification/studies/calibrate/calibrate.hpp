#pragma once
/// `vesselverify calibrate`: a mass-spring model's stiffness fitted to the FEM
/// reference's displacements on a scene's training loads, then checked on held-out loads.
///
/// - Fit: msm/calibration/stiffness_fit.hpp (least squares on nodal displacements of the model
///   linearised at rest, adjoint gradients, msm/calibration/lbfgs.hpp), at two granularities:
///   a few factors (spring classes and κ) or one factor per spring with a smoothness regulariser.
/// - Cases: the training loads (the scene's load type: its contact point and the point 90° round
///   the centreline, at the scene's budget load; or the scene's pressure/gravity load) and the
///   held-out ones, each named by what it holds out: other magnitudes of the scene's load (within
///   the reference's linear regime), other contact points (180° round, and 45° back and a quarter
///   of the vessel along), other load types (contact, pressure 10 Pa, gravity 1 g, whichever were
///   not trained on) and other vessels (further scenes, e.g. the arch for a straight-tube fit;
///   group calibrations only, applied with calibration_transfer).
/// - Every case is solved as the scene solves the model (the nonlinear static model with its
///   solver, a ramp of warm-started updates as the harness times it), for the base model, the
///   calibrated one and FEM P1 on the model's mesh, all against the P2 reference at the model's
///   nodes (the harness's metric, verification/harness/metrics.hpp). Training and held-out errors are
///   reported apart.
/// - The FEM solutions of each load shape (P2, P1) come from the FEM solution cache
///   (fem::SolutionCache) when given one; a cached P1 keeps the solve time measured when it was
///   computed.
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "msm/calibration/stiffness_fit.hpp"
#include "verification/calibration_file.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/scene.hpp"

namespace vessel::fem {
class SolutionCache;
}

namespace vessel {

/// groups: msm::group_parameters; wall_layers and edge_types: msm::wall_layer_parameters
/// (direction by the largest component, or by the edge's type); per_section_spring:
/// msm::per_section_spring_parameters;
/// per_spring: msm::per_spring_parameters.
enum class CalibrationGranularity {
  groups,
  wall_layers,
  edge_types,
  per_section_spring,
  per_spring
};
/// "groups" | "wall_layers" | "edge_types" | "per_section_spring" | "per_spring"
std::string to_string(CalibrationGranularity g);
CalibrationGranularity parse_calibration_granularity(const std::string& name);  ///< InputError

/// How the training cases weigh in the fit: equal (each case's squared relative L2 error alike)
/// or p1 (each divided by P1's squared relative L2 error on that case, normalised to a mean
/// weight of 1: the fit then minimises the mean squared *ratio to P1*, the metric).
enum class CaseWeights { equal, p1 };
std::string to_string(CaseWeights w);            ///< "equal" | "p1"
CaseWeights parse_case_weights(const std::string& name);  ///< InputError

struct CalibrateOptions {
  /// The scene's mass-spring model to calibrate; empty: its hybrid volume model
  /// (volume_term = true), else its first mass-spring model.
  std::string model;
  std::optional<double> poisson_ratio;  ///< default: 0.45 if the scene has it, else its first ν
  std::optional<int> level;             ///< default: the scene's first model level
  std::optional<int> reference_level;   ///< default: the scene's
  CalibrationGranularity granularity = CalibrationGranularity::groups;
  std::vector<LoadKind> train;  ///< load types fitted on; default: the scene's load type
  /// Per-spring fits: both terms; the class granularities: the ridge alone. Defaults: msm::Regulariser's doc.
  msm::Regulariser regulariser{1e-2, 1e-3, {}};
  /// Per-spring and per-section-spring fits: a class calibration of the same model and mesh to
  /// start from and to
  /// regularise towards (msm::Regulariser::centre: smoothness and ridge act on each spring's
  /// departure from its factor); its κ halves, if it has them, stay apart. prior_source names
  /// it in errors.
  std::optional<Calibration> prior;
  std::string prior_source;
  int max_iterations = 200;
  CaseWeights weights = CaseWeights::equal;
  /// The gravity cases' magnitude (g) on scenes whose own load is not gravity.
  double gravity = 1.0;
  /// Further scenes whose own loads are held-out cases on another vessel (group calibrations).
  std::vector<Scene> other_vessels;
  std::filesystem::path cache_dir;  ///< generated meshes (empty: none)
  fem::SolutionCache* solution_cache = nullptr;  ///< FEM solutions kept on disk (nullptr: none)
  std::ostream* log = nullptr;  ///< progress
};

/// One case solved by the base model, the calibrated model and P1.
struct CalibrationCaseResult {
  std::string scene;
  std::string name;        ///< e.g. "contact θ+180°"
  bool training = false;
  std::string holds_out;   ///< "training", "other magnitude", "other contact point", ...
  LoadKind kind = LoadKind::contact;
  double magnitude = 0.0;  ///< N, Pa or g
  Vec3 point = Vec3::Zero();
  int level = 0;
  ErrorStatistics p1, base, calibrated;
  double p1_solve_seconds = 0.0;
  double base_update_seconds = 0.0, calibrated_update_seconds = 0.0;  ///< per update (ramp median)
  double max_strain_reference = 0.0;  ///< reference's largest principal strain at this load
  bool ok = true;
  std::string failure;  ///< why the calibrated model could not be evaluated (a refused
                        ///< transfer, or its solver's failure on this case)
  bool base_ok = true;
  std::string base_failure;  ///< why the uncalibrated model could not be (its solver's failure)
};

struct CalibrationStudy {
  Calibration calibration;
  std::vector<CalibrationCaseResult> cases;
  double fit_seconds = 0.0;  ///< the L-BFGS fit alone
  std::string model_detail;
};

/// Fits and evaluates. InputError for an unknown model name, a FEM model, ν or a level the scene
/// cannot give, or granularity per_spring with other vessels (reported as such, not silently).
CalibrationStudy calibrate_scene(const Scene& scene, const CalibrateOptions& options);

/// The study as a JSON document (schema "vesselverify.calibrate", version 1;
/// calibrate.schema.json beside this header): the model and its mesh, the fit (its factors by
/// name for the class granularities, their range always), and every case's P1, base and
/// calibrated relative L2 errors and times. `calibration_file` names the calibration file written
/// from study.calibration (write_calibration). reports::calibration_markdown renders it.
std::string calibration_study_json(const CalibrationStudy& study, const std::string& command,
                                   const std::string& calibration_file);
/// The same, written atomically to `path` (InputError if it cannot).
void write_calibration_study(const std::filesystem::path& path, const CalibrationStudy& study,
                             const std::string& command, const std::string& calibration_file);

}  // namespace vessel
