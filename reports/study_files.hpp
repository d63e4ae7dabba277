#pragma once
/// The studies' JSON documents read back into plain structs for the report, like results.json:
/// stability.json of `vesselverify stability`, recommend.json of `vesselverify recommend`,
/// validity.json of `vesselverify validity` and the calibration study of `vesselverify calibrate`
/// (each "vesselverify.<study>", version 1, with its JSON Schema in its study's folder,
/// verification/studies/<study>/<study>.schema.json). Only what the report shows is read.
#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vessel::reports {

/// One row of the critical-step table (times in s, angular frequencies in rad/s).
struct CriticalStepEntry {
  std::string model, integrator;
  double zeta = 0.0;
  int level = 0, nodes = 0;
  double omega_max = 0.0, omega_gershgorin = 0.0;
  double predicted_dt = 0.0, found_dt = 0.0;
  std::optional<double> guaranteed_dt;  ///< none where no stable step is proven (damped Verlet)
};

/// dt ∝ h^p over the levels: the found and the predicted exponent.
struct RefinementEntry {
  std::string model, integrator;
  double zeta = 0.0;
  std::vector<int> levels;
  double found_exponent = 0.0, predicted_exponent = 0.0;
};

/// One row of the guidewire's critical steps (s): closed forms, and the explicit rows' found step
/// or the implicit rows' steps tried with whether each stayed bounded.
struct RodStepEntry {
  std::string model, integrator, failure;
  int segments = 0;
  double h = 0.0, axial_dt = 0.0, twist_dt = 0.0, bending_dt = 0.0, closed_form_dt = 0.0;
  std::optional<double> predicted_dt, found_dt;
  std::vector<double> steps_tried;
  std::vector<bool> bounded;
};

/// One row of corotational P1's and XPBD FEM's critical steps (s): the estimate 2/ω_max (Lanczos,
/// power iteration) and the found step, or the implicit rows' steps tried under a load.
struct TetStepEntry {
  std::string model, integrator, failure;
  int level = 0, nodes = 0;
  double nu = 0.0, load = 0.0;
  std::optional<double> predicted_dt, power_dt, found_dt, unstable_dt;
  std::vector<double> steps_tried;
  std::vector<bool> bounded;
};

/// The wire the rod rows are for (SI).
struct RodWireEntry {
  double length = 0.0, diameter = 0.0, young = 0.0, shear = 0.0, density = 0.0;
};

struct HardCaseOutcomeEntry {
  std::string model;
  bool finished = false;
  std::optional<bool> converged, bounded;  ///< none where not applicable
  std::string reported;
};

struct HardCaseEntry {
  std::string id, title, setup;
  double seconds = 0.0;
  std::vector<HardCaseOutcomeEntry> outcomes;
};

struct StabilityFile {
  std::filesystem::path path;
  std::string command;
  bool quick = false;
  int steps_per_trial = 0;
  double total_seconds = 0.0;
  std::vector<CriticalStepEntry> critical_steps;
  std::vector<RefinementEntry> refinement;
  std::vector<HardCaseEntry> hard_cases;
  std::optional<RodWireEntry> rod_wire;  ///< absent in files without the rod's rows
  std::vector<RodStepEntry> rod_steps;
  std::vector<TetStepEntry> tet_steps;  ///< empty in files without them
  int hard_cases_at_a_time = 1;         ///< how many hard cases ran at once (1 in older files)
  /// Which rows' and hard cases' timings came from the model outcome cache
  /// (timing_provenance_line); empty in a file without that record.
  std::string timing_provenance;
};

/// One candidate of a recommendation. error and update_seconds are present when it finished
/// (error absent also where not computable); failure when it did not.
struct CandidateEntry {
  std::string name, detail;
  std::size_t unknowns = 0;
  bool ok = false, pareto = false;
  std::string verdict, reason, failure;
  std::optional<double> error, update_seconds;
  std::optional<double> setup_seconds;  ///< absent in files written before set-up was reported
  std::optional<double> roi_radius_mm;  ///< the region of interest; absent: the whole vessel
};

/// The load the budget applies at for one Poisson's ratio (scene's load unit).
struct BudgetLoadEntry {
  double poisson_ratio = 0.0;
  double magnitude = 0.0;
  /// The reference's element: from recommend.json, else the run's results.json (attach_run);
  /// "" if unknown.
  std::string reference_element;
};

/// One rod model of a guidewire scene's wire candidates (recommend.json's "wire").
struct WireCandidateEntry {
  std::string name, verdict, reason, failure;
  bool ok = false;
  double force_error_mN = 0.0, contact_error_mm = 0.0, update_seconds = 0.0, setup_seconds = 0.0;
};
struct WireEntry {
  std::string reference;  ///< the continuum wire; empty when there is none
  std::string no_reference;
  double reference_force_N = 0.0;
  std::optional<std::string> recommended;
  std::vector<WireCandidateEntry> candidates;
};

/// One wire–vessel pair of a guidewire scene's recommendation (recommend.json's "pairs").
struct PairCandidateEntry {
  std::string name, wire, vessel, verdict, reason;
  std::optional<double> error;  ///< absent where the vessel's is not computable
  double update_seconds = 0.0, setup_seconds = 0.0;
  bool pareto = false;
};
struct PairsEntry {
  std::optional<std::string> recommended, closest;
  std::vector<PairCandidateEntry> pairs;
};

struct RecommendFile {
  std::filesystem::path path;
  std::string command, scene;
  std::vector<int> model_levels;
  int reference_level = 0;
  // The budget: quantity (contact_point | patch | field | reaction | contact_force) and its unit
  // (mm or mN).
  std::string quantity, unit;
  double tolerance = 0.0, seconds_per_update = 0.0;
  std::optional<double> rate_hz, radius_mm;
  std::vector<BudgetLoadEntry> loads;
  /// N, Pa or g: from recommend.json, else the run's results.json (attach_run); "" if unknown.
  std::string load_unit;
  /// Which of the candidates' timings came from the model outcome cache (timing_provenance_line
  /// over the run's outcomes, attach_run); "" if all were measured or unknown.
  std::string timing_provenance;
  std::optional<std::string> recommended, closest;  ///< candidate names
  /// The candidates' results.json: the file's "results" (relative to its folder), else the
  /// results.json beside it (files written before "results" existed).
  std::filesystem::path results;
  /// The cheapest whole-vessel candidate meeting the budget (absent in older files, or none).
  std::optional<std::string> whole_vessel;
  bool whole_vessel_reported = false;       ///< the file has "whole_vessel" (null: none meets it)
  double reference_contact_point_mm = 0.0;  ///< the reference's largest QoI displacement
  std::vector<CandidateEntry> candidates;
  std::optional<WireEntry> wire;    ///< guidewire scenes only
  std::optional<PairsEntry> pairs;  ///< guidewire scenes with a continuum wire only
};

/// validity.json of `vesselverify validity` (schema "vesselverify.validity", version 1;
/// verification/studies/validity/validity.hpp says what each field means).
struct ValidityCrossingEntry {
  double threshold = 0.0;
  std::string status;  ///< interpolated | below_ladder | not_reached
  std::optional<double> load;
  double lower = 0.0, upper = 0.0;
};

struct ValidityModelEntry {
  std::string model;
  bool ok = false;
  std::string failure;
  double relative_l2 = 0.0, max_error_mm = 0.0, qoi_error_mm = 0.0, qoi_relative = 0.0;
  /// Its fields' VTU against the finite-strain reference, relative to the validity file's
  /// folder (the largest load reached only); empty when none was written.
  std::string fields;
};

struct ValidityRowEntry {
  double magnitude = 0.0, linear_qoi_mm = 0.0, finite_qoi_mm = 0.0;
  double qoi_difference = 0.0, l2_difference = 0.0, linear_strain = 0.0;
  std::optional<double> wall_gap_mm;  ///< the inner wall's closest approach across the lumen
  int newton_iterations = 0, load_steps = 0;
  double finite_seconds = 0.0;
  std::vector<ValidityModelEntry> models;
};

struct ValiditySceneEntry {
  std::string scene, load_kind, load_unit, element;
  double poisson_ratio = 0.0;
  int reference_level = 0, model_level = 0;
  std::size_t dofs = 0;
  std::vector<double> ladder;
  std::vector<std::string> models;  ///< model names
  bool completed = false;
  double largest_load = 0.0;
  std::string stop_reason;
  bool self_contact = false;  ///< stopped where the wall would pass through itself
  int load_steps = 0, rejected_steps = 0, newton_iterations = 0;
  double solve_seconds = 0.0;
  bool from_cache = false;
  std::vector<ValidityCrossingEntry> qoi_limits, l2_limits;
  std::vector<ValidityRowEntry> rows;
  std::optional<std::vector<double>> qoi_point_mm;  ///< absent from older files
};

/// The slot report.html fills with a validity scene's 3D view ("view:validity-<scene>").
std::string validity_view_slot(const std::string& scene);

struct ValidityFile {
  std::filesystem::path path;
  std::string command;
  bool full = false;
  double total_seconds = 0.0;
  std::vector<ValiditySceneEntry> scenes;
};

/// The calibration study of `vesselverify calibrate` (schema "vesselverify.calibrate", version 1;
/// verification/studies/calibrate/calibrate.schema.json): the fit and every case's errors.
struct CalibrationParameterEntry {
  std::string name;
  double factor = 1.0;
};

struct CalibrationCaseEntry {
  std::string scene, name, holds_out;
  bool training = false;
  std::string load_kind, load_unit;  ///< contact | pressure | gravity; N, Pa or g
  double magnitude = 0.0;
  int level = 0;
  double p1_relative_l2 = 0.0, p1_solve_seconds = 0.0, max_strain_reference = 0.0;
  /// Absent where that model could not be evaluated (failure, base_failure say why).
  std::optional<double> base_relative_l2, base_update_seconds;
  std::optional<double> calibrated_relative_l2, calibrated_update_seconds;
  std::string failure, base_failure;
};

struct CalibrateFile {
  std::filesystem::path path;
  std::string command, calibration_file;  ///< the calibration file written, as given
  std::string scene, model, model_detail, granularity, vessel, mesh_hash;
  double poisson_ratio = 0.0;
  std::size_t nodes = 0, springs = 0;
  std::string method, stop_reason;
  int iterations = 0;
  double fit_seconds = 0.0, objective_before = 0.0, objective_after = 0.0;
  std::size_t parameter_count = 0;
  double factor_min = 1.0, factor_median = 1.0, factor_max = 1.0;
  /// Every factor by name for the class granularities; empty for per-spring ones (their
  /// factors are in the calibration file).
  std::vector<CalibrationParameterEntry> parameters;
  std::vector<CalibrationCaseEntry> cases;
};

/// The insertion of `vesselverify insertion --json` (schema "vesselverify.insertion", version 1;
/// verification/harness/contact_insertion.schema.json): per wire stiffness, each step's contact
/// forces and zones and the hub's forces, SI units.
struct InsertionZoneEntry {
  double force = 0.0;                ///< N
  std::array<double, 3> centroid{};  ///< m
  double extent = 0.0;               ///< m
  int nodes = 0;
};

struct InsertionStepEntry {
  double insertion = 0.0;  ///< m
  bool converged = false;
  std::string failure;
  double force = 0.0;  ///< N
  int pressed = 0;
  std::vector<InsertionZoneEntry> zones;
  double clamp_axial = 0.0;              ///< R·t, N
  double push = 0.0;                     ///< R·t − M²/(2EI), N
  std::optional<double> push_by_energy;  ///< dΠ/dL, N (none next to a failed step)
  std::array<double, 3> tip{};           ///< m
  double dent = 0.0;                     ///< m
  std::vector<double> centreline;        ///< the wire's nodes, x, y, z each, m (may be empty)
  int newton_steps = 0;
  double seconds = 0.0;
};

/// The inner wall near the wire at one step (the insertion's view).
struct InsertionViewEntry {
  int step = 0;                            ///< index into the entry's steps
  std::vector<int> nodes;                  ///< mesh indices
  std::vector<double> rest, displacement;  ///< x, y, z per node, m
  std::vector<double> force;               ///< N per node
  std::vector<int> triangles;              ///< three indices into nodes each
};

struct InsertionEntry {
  std::string scene, wall;
  std::string model, model_detail;  ///< "reference" (deal.II's FEM) or one of the scene's models
  double bending_stiffness = 0.0;  ///< EI, N·m²
  int mesh_nodes = 0, refined_balls = 0;
  double mesh_seconds = 0.0;
  std::string cached_from;  ///< when it was computed, if read from the cache (else empty)
  double wire_radius = 0.0;  ///< m (0: not given)
  std::vector<InsertionStepEntry> steps;
  std::optional<InsertionViewEntry> view;
};

struct InsertionFile {
  std::filesystem::path path;
  std::string command;
  double total_seconds = 0.0;
  std::vector<InsertionEntry> insertions;
};

/// Reads and checks a stability file; InputError naming the file and what is wrong (missing file,
/// not JSON, another schema or version, a missing field).
StabilityFile read_stability(const std::filesystem::path& path);
StabilityFile parse_stability(const std::string& text, const std::filesystem::path& source);

/// Reads and checks a recommend file; InputError as read_stability.
RecommendFile read_recommend(const std::filesystem::path& path);
RecommendFile parse_recommend(const std::string& text, const std::filesystem::path& source);

/// Reads and checks a validity file; InputError as read_stability.
ValidityFile read_validity(const std::filesystem::path& path);
ValidityFile parse_validity(const std::string& text, const std::filesystem::path& source);

/// Reads and checks a calibration study; InputError as read_stability.
CalibrateFile read_calibrate(const std::filesystem::path& path);
CalibrateFile parse_calibrate(const std::string& text, const std::filesystem::path& source);

/// Reads and checks an insertion file; InputError as read_stability.
InsertionFile read_insertion(const std::filesystem::path& path);
InsertionFile parse_insertion(const std::string& text, const std::filesystem::path& source);

}  // namespace vessel::reports
