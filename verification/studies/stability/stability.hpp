#pragma once
/// Numerical stability study (`vesselverify stability`, issue 6): predicted vs found critical
/// time steps of the explicit integrators per model, integrator and mesh level, their shrinking
/// with refinement, and the hard cases (near-incompressible ν, stiff and soft E at a fixed step,
/// sliver tets, a refined contact patch, an inverting load, a long run, a tight arch bend,
/// zero-length springs and coincident nodes), each with what every model did.
/// Results: stability.json (schema verification/studies/stability/stability.schema.json) and
/// stability.md. One file per hard case (case_<id>.cpp); study_models.hpp has their shared pieces.
#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel {

class OutcomeCache;  // verification/harness/outcome_cache.hpp

/// The guidewire of the rod rows: a metal wire (nitinol-like), clamped at one end.
struct RodWire {
  double length = 0.1;         ///< m
  double diameter = 0.356e-3;  ///< m (0.014")
  double young = 60e9;         ///< E, Pa
  double shear = 60e9 / 2.66;  ///< G = E/(2(1 + ν)), ν = 0.33, Pa
  double density = 6450.0;     ///< kg/m³
  std::vector<int> segments{50, 200};
};

struct StabilityOptions {
  bool quick = true;  ///< levels 0..1 and a scaled-down long run; else levels 0..2 and 10⁶ steps
  std::filesystem::path cache_dir;  ///< mesh cache ("" disables it)
  std::ostream* log = nullptr;      ///< progress
  std::string command_line;         ///< recorded in the results
  /// Overrides (0: the mode's default): steps per stability trial, steps of the long run,
  /// highest mesh level of the step table.
  int trial_steps = 0;
  long long long_run_steps = 0;
  int max_level = -1;
  bool hard_cases = true;  ///< false: only the critical-step table
  bool rod_steps = true;   ///< the guidewire's critical steps (rod_steps.hpp)
  /// Corotational P1's and XPBD FEM's critical steps (tet_steps.hpp), at levels
  /// 0..min(max level, tet_max_level).
  bool tet_steps = true;
  int tet_max_level = 0;
  RodWire rod_wire;
  /// Rows of the critical-step table, and hard cases without a measured time, computed at a time
  /// (each on its own thread); the timed hard case (the long run) runs alone after them.
  int jobs = 1;
  /// Ids of the hard cases to run (poisson, youngs_modulus, sliver, refined_patch,
  /// inverting_load, long_run, tight_bend, zero_length); empty: all of them.
  std::vector<std::string> only_cases;
  /// The step table's rows (per level and model) and each hard case kept on disk, keyed by the
  /// options that shape them, the executable and the machine (their times are part of them);
  /// nullptr: all computed.
  OutcomeCache* outcome_cache = nullptr;
};

/// The hard cases' ids, in the order they run.
inline constexpr std::array<std::string_view, 8> kHardCaseIds{
    "poisson",        "youngs_modulus", "sliver",     "refined_patch",
    "inverting_load", "long_run",       "tight_bend", "zero_length"};

/// One row of the critical-step table.
struct CriticalStepRow {
  std::string model;           ///< e.g. "volume / seed001"
  std::string integrator;      ///< explicit-euler | symplectic-euler | verlet
  double zeta = 0.0;           ///< target damping ratio of the top mode (c = 2ζω_max·mean mass)
  double point_damping = 0.0;  ///< c, N·s/m per node (seed 000 eq. 3.3)
  int level = 0;
  int nodes = 0;
  int springs = 0;
  double h_nominal = 0.0;  ///< the mesh's nominal element size, m
  double omega_max = 0.0;  ///< rad/s (Lanczos)
  double omega_gershgorin = 0.0;
  double omega_min = 0.0;
  double gamma_max = 0.0;     ///< damping rate of the top mode, 1/s
  double predicted_dt = 0.0;  ///< modal estimate (exact undamped; may over-predict when damped)
  /// Proven stable step (msm::guaranteed_critical_step), s; NaN where none is proven.
  double guaranteed_dt = 0.0;
  double found_dt = 0.0;     ///< largest step found stable, s
  double unstable_dt = 0.0;  ///< smallest step found unstable, s
  int trials = 0;
  int steps_per_trial = 0;
  double seconds = 0.0;
};

/// How the found step shrinks with refinement: dt ∝ h^exponent (least squares over the levels).
struct RefinementFit {
  std::string model;
  std::string integrator;
  double zeta = 0.0;
  std::vector<int> levels;
  double exponent = 0.0;  ///< of the found step
  double predicted_exponent = 0.0;
};

/// One row of the rod's critical-step table (verification/studies/stability/rod_steps.hpp).
struct RodStepRow {
  std::string model;       ///< der | corde | xpbd
  std::string integrator;  ///< symplectic-euler | verlet | implicit-euler | xpbd
  int segments = 0;
  double h = 0.0;  ///< segment length, m
  /// Closed forms of the straight discrete rod, s (the smallest: closed_form_dt).
  double axial_dt = 0.0, twist_dt = 0.0, bending_dt = 0.0, closed_form_dt = 0.0;
  /// Explicit rows: 2/ω_max (Lanczos on the rod at rest), the bisection's stable and unstable
  /// steps, s; NaN on the implicit rows.
  double omega_max = 0.0, predicted_dt = 0.0, found_dt = 0.0, unstable_dt = 0.0;
  /// Implicit rows: the steps tried (s), whether each stayed bounded, and why one did not.
  std::vector<double> steps_tried;
  std::vector<bool> bounded;
  std::string failure;
  int steps_per_trial = 0;
  int trials = 0;
  double seconds = 0.0;
};

/// One row of the P1 tet models' critical-step table
/// (verification/studies/stability/tet_steps.hpp).
struct TetStepRow {
  std::string model;  ///< corotational-p1 | xpbd-fem
  std::string
      integrator;  ///< symplectic-euler | verlet | implicit-euler | implicit-euler-rest | xpbd
  int level = 0;
  int nodes = 0;
  int tets = 0;
  double nu = 0.0;    ///< Poisson's ratio
  double load = 0.0;  ///< N: the trials' contact load (0: from rest with a small random velocity)
  /// The independent estimate, 2/ω_max with ω_max of M⁻¹K (K: corotational P1's Hessian at rest;
  /// XPBD: the shear stiffness its carried multipliers integrate explicitly) by Lanczos and by
  /// power iteration, rad/s and s; NaN on the implicit rows.
  double omega_lanczos = 0.0, omega_power = 0.0, predicted_dt = 0.0, power_dt = 0.0;
  /// Largest step found bounded and smallest found unbounded by bisection, s; NaN where no
  /// bisection ran (bounded at every step of the ladder).
  double found_dt = 0.0, unstable_dt = 0.0;
  /// Implicit rows: the ladder's steps (s), whether each stayed bounded, and why one did not.
  std::vector<double> steps_tried;
  std::vector<bool> bounded;
  std::string failure;
  int steps_per_trial = 0;
  int trials = 0;
  double seconds = 0.0;
};

/// What one model did on a hard case.
struct HardCaseOutcome {
  std::string model;
  bool finished = false;          ///< returned a result (no exception)
  std::optional<bool> converged;  ///< solver converged (static / linear solve), if applicable
  std::optional<bool> bounded;    ///< energy stayed bounded (dynamic runs), if applicable
  std::string reported;           ///< what it reported (numbers in mm, mN, s), or its error
  std::map<std::string, double> values;  ///< the main figures, SI unless the key says mm
};

struct HardCase {
  std::string id;
  std::string title;
  std::string setup;  ///< what was run
  std::vector<HardCaseOutcome> outcomes;
  double seconds = 0.0;
};

struct StabilityReport {
  bool quick = true;
  std::string command_line;
  int trial_steps = 0;
  std::vector<CriticalStepRow> rows;
  std::vector<RefinementFit> fits;
  std::vector<HardCase> hard_cases;
  RodWire rod_wire;
  std::vector<RodStepRow> rod_rows;  ///< empty when the options leave the rod out
  /// Corotational P1 and XPBD FEM (tet_steps.hpp); empty when the options leave them out.
  std::vector<TetStepRow> tet_rows;
  /// Hard cases run side by side (their seconds are wall times on a shared machine); the long run
  /// ran alone.
  int hard_cases_at_a_time = 1;
  double seconds = 0.0;
  /// Items timed (each level's model rows, each hard case) and the measurement times of those
  /// read from the outcome cache.
  std::size_t timed_items = 0;
  std::vector<std::string> cached_at;
};

/// Runs the study. Throws InputError for bad options.
StabilityReport run_stability(const StabilityOptions& options);

/// The versioned JSON (schema "vesselverify.stability", version 1) as text.
std::string stability_json(const StabilityReport& report);
/// Writes stability.json and stability.md (the report's section drawn from that JSON,
/// reports::stability_markdown) into `dir` atomically (InputError if it cannot).
void write_stability(const std::filesystem::path& dir, const StabilityReport& report);

/// Least-squares slope of log(y) against log(x) (InputError unless ≥ 2 positive pairs).
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace vessel
