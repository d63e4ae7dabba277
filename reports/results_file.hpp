#pragma once
/// results.json (schema "vesselverify.results", version 2; verification/results.schema.json) read
/// back into plain structs, for the report generator and the gate. Only what they use is read.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vessel::reports {

struct OutcomeRow {
  std::string model, kind, detail;
  double poisson_ratio = 0.0;
  double magnitude = 0.0;
  int level = 0;
  bool ok = false;
  std::string failure;
  std::size_t nodes = 0, unknowns = 0;
  double setup_seconds = 0.0, solve_seconds = 0.0, memory_mib = 0.0;
  /// Models outside the suite: "simulator" (their own times), "process" (their process's wall
  /// time), "none"; empty for the suite's own models.
  std::string timing_source;
  /// The suite's own models: their times read from the model outcome cache (else measured in the
  /// run), and when they were measured (UTC; empty in files written before it was recorded).
  bool timing_cached = false;
  std::string timing_measured_at;
  // Present when ok:
  double max_mm = 0.0, mean_mm = 0.0, stddev_mm = 0.0, rms_mm = 0.0, relative_l2 = 0.0;
  std::optional<double> reference_uncertainty_max_mm;
  double qoi_mm = 0.0, qoi_reference_mm = 0.0, max_strain = 0.0;
  bool beyond_linear_regime = false;
  std::vector<double> profile_s_mm, profile_model_mm, profile_reference_mm;
  std::vector<double> history_time_s, history_model_mm, history_reference_mm;
  double history_max_error_mm = 0.0, simulated_s = 0.0, mass_damping_per_s = 0.0;
  std::optional<int> history_reference_level;  ///< the FEM transient's mesh level (older files: none)
  long steps = 0;
  /// Scenes with a budget: the error on the budget's quantity (its unit) and the compute time per
  /// update at its rate (s); nullopt without a budget.
  std::optional<double> budget_error, update_seconds;
  /// The VTU of the case's fields, relative to the results file's folder; empty when the run
  /// wrote none.
  std::string fields;
};

/// Where a contact load acts (results.json's contact_patch), mm.
struct ContactPatchRow {
  std::vector<double> point_mm;
  double radius_mm = 0.0;
  std::vector<double> outward_normal;  ///< the wall's, unit
};

/// One mesh a scene ran on (results.json's mesh_quality): its dihedral extremes and slivers.
struct MeshQualityRow {
  int level = 0;
  double min_dihedral_deg = 0.0, max_dihedral_deg = 0.0;
  std::size_t sliver_count = 0;
  std::vector<double> worst_centroid_mm;  ///< empty without slivers
  double worst_min_dihedral_deg = 0.0, worst_max_dihedral_deg = 0.0;
};

/// One end of a lumen (results.json's lumen_ends), mm.
struct LumenEndRow {
  std::string group;
  std::vector<double> centre_mm;
  double radius_mm = 0.0;
};

/// A scene's [budget] as results.json states it.
struct BudgetRow {
  std::string quantity;  ///< contact_point | patch | field | reaction
  std::string unit;      ///< mm, or mN for reaction
  double tolerance = 0.0;
  std::optional<double> rate_hz;
  double seconds_per_update = 0.0;
};

struct ReferenceRow {
  double poisson_ratio = 0.0;
  std::string element;
  int level = 0;
  std::size_t dofs = 0;
  double solve_seconds = 0.0;
  double max_abs_strain_at_unit_load = 0.0;
  /// The Richardson/GCI order used for the reference's uncertainty, as text ("1 (assumed, Fs 3)",
  /// "1.87 (observed, Fs 1.25)", "none"); empty in files written before it was recorded. The
  /// finite-strain reference's, where the scene uses it; else empty.
  std::string gci_linear, gci_finite;
};

/// One model's (or the modal reference's) lowest natural frequencies at one ν and level (the
/// scene's "modes" block; verification/harness/harness.hpp ModalOutcome).
struct ModalRow {
  std::string model, kind, detail;
  double poisson_ratio = 0.0;
  int level = 0;
  bool ok = false;
  std::string failure;
  std::vector<double> frequencies_hz;
  std::vector<double> ratio_to_reference;  ///< f/f_reference mode by mode (models only)
  int mechanisms = 0;
  std::size_t dofs = 0;
  double seconds = 0.0;
};

/// A guidewire load (results.json's guidewire): the wire against the rigid lumen at each
/// bending stiffness, and each model's contact force coupled through its wall compliance.
struct GuidewireRigidRow {
  double bending_stiffness = 0.0;  ///< N·m²
  double force_mN = 0.0;
  std::optional<double> wire_compliance;  ///< m/N, compliant coupling only
  /// The wire's centreline against the rigid lumen, clamp to tip, mm (empty in files without it).
  std::vector<std::array<double, 3>> centreline_mm;
  /// Compliant coupling: the wire coupled with the reference's wall, mm (empty without one).
  std::vector<std::array<double, 3>> reference_centreline_mm;
  std::string reference_row;  ///< the coupling row whose loaded nodes C_ref was read on
  /// |F − F_continuum| (mN): the rod model's error; absent without a continuum wire.
  std::optional<double> force_error_mN;
};
struct GuidewireCoupledRow {
  std::string model, failure;
  double poisson_ratio = 0.0, bending_stiffness = 0.0;
  int level = 0;
  bool ok = false, within_patch = true;
  /// The series springs dent the reference's wall no deeper than it is thick (true in results
  /// files from before the field).
  bool reference_within_wall = true;
  double force_mN = 0.0, reference_force_mN = 0.0;
  double displacement_mm = 0.0, reference_displacement_mm = 0.0, slide_mm = 0.0;
  /// The field's relative L2 error at the rigid wire's force and at each wall's coupled force.
  std::optional<double> field_relative_l2_rigid, field_relative_l2;
};
/// One wall in the wire–wall contact solve at one EI (coupling = "contact").
struct ContactWallRow {
  std::string model, wall, failure;
  bool ok = false;
  double force_mN = 0.0;
  std::optional<double> force_error_mN, force_error_percent, tip_error_mm;  ///< vs the reference
  int pressed = 0;
  double axial_extent_mm = 0.0, circumferential_extent_mm = 0.0, dent_mm = 0.0;
  double largest_strain = 0.0, setup_seconds = 0.0, solve_seconds = 0.0;
};
/// A force a simulator uses instead of the contact solve's, against the reference's.
struct ContactShortcutRow {
  std::string name;
  double force_mN = 0.0;
  std::optional<double> force_error_percent;
};
struct ContactRun {
  double bending_stiffness = 0.0, rigid_force_mN = 0.0;
  bool within_linear_validity = true;
  ContactWallRow reference;
  std::vector<ContactWallRow> models;
  std::vector<ContactShortcutRow> shortcuts;
};
struct GuidewireContactRows {
  double poisson_ratio = 0.0, fine_size_mm = 0.0, fine_radius_mm = 0.0, strain_limit = 0.0;
  int mesh_nodes = 0, reference_degree = 2;
  std::string wall = "linear";  ///< linear | neo-Hookean (linear in files without it)
  std::vector<ContactRun> runs;
};
struct GuidewireRows {
  std::string model, coupling;  ///< the wire's rod model; rigid | compliant | contact
  double diameter_mm = 0.0;     ///< 0 in files without it
  std::vector<GuidewireRigidRow> rigid;
  std::vector<GuidewireCoupledRow> coupled;
  std::optional<GuidewireContactRows> contact;  ///< coupling = "contact"
};

struct SceneRows {
  std::string name, description, vessel, load, load_unit;
  std::vector<int> model_levels;
  int reference_level = 0;
  double tolerance_mm = 0.1;
  double seconds = 0.0;
  /// The load the scene's [budget] applies at (scene's load unit); nullopt without a budget, or
  /// when the budget leaves it to the representative load.
  std::optional<double> budget_magnitude;
  std::optional<BudgetRow> budget;
  /// The QoI point (for contact loads the contact point), mm; nullopt in files without it.
  std::optional<std::vector<double>> qoi_point_mm;
  std::optional<ContactPatchRow> contact_patch;  ///< contact loads only
  std::optional<GuidewireRows> guidewire;         ///< guidewire loads only
  std::vector<MeshQualityRow> mesh_quality;       ///< absent from older files: empty
  std::vector<LumenEndRow> lumen_ends;            ///< vessels from lumen files only
  std::vector<ReferenceRow> references;
  std::vector<OutcomeRow> outcomes;
  /// Natural frequencies (absent from runs without [modes]): the reference per ν, the models.
  std::vector<ModalRow> reference_modes, model_modes;
};

struct ResultsFile {
  std::filesystem::path path;
  int schema_version = 0;
  std::string date, command, host, compiler;
  unsigned hardware_threads = 0;
  std::optional<double> reference_kernel_seconds;
  std::vector<SceneRows> scenes;
};

/// Reads and checks a results file; InputError naming the file and what is wrong (missing file,
/// not JSON, another schema or version, a missing field).
ResultsFile read_results(const std::filesystem::path& path);

/// "n of m timings from the cache, measured <first date>[ to <last date>] by the same executable
/// on this machine; --retime to measure again" over outcomes with a recorded measurement time
/// (`cached_at`: the measurement times of those read from the cache); "" when none was. The
/// report's and summary.md's line beside their timing columns.
std::string timing_provenance_line(std::size_t total, std::vector<std::string> cached_at);
/// Same from text; `source` names it in messages.
ResultsFile parse_results(const std::string& text, const std::filesystem::path& source);

}  // namespace vessel::reports
