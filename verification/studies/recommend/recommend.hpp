#pragma once
/// `vesselverify recommend`: the cheapest model that meets a scene's budget. Candidate
/// models are generated from the msm library's own lists (every stiffness rule, surface and
/// volume, static solvers or integrators, mesh levels, region-of-interest radii, plus FEM P1), run
/// against the FEM reference at the budget's load, and judged on the budget's quantity and on the
/// compute time per update at its rate.
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// One candidate's evidence: its worst case over the scene's Poisson's ratios at the budget's load.
struct Candidate {
  std::string name;    ///< model name and level, e.g. "volume/lloyd/static @ L1"
  std::string model;   ///< the ModelSpec name in the results
  std::string detail;  ///< topology, rules, solver
  int level = 0;
  double roi_radius = 0.0;  ///< m; 0: whole vessel
  std::size_t unknowns = 0;
  bool ok = false;
  std::string failure;  ///< why it did not finish (ok false)
  double error = 0.0;   ///< on the budget's quantity (mm, or mN for reaction); NaN: not computable
  double update_seconds = 0.0;  ///< compute time per update at the budget's rate (judged)
  double setup_seconds = 0.0;   ///< done once: build, assembly and factorisation (not judged)
};

enum class Verdict {
  recommended,   ///< meets both, and the cheapest that does
  meets_budget,  ///< meets both, but costs more time per update than the recommended one
  too_slow,
  too_inaccurate,
  too_slow_and_inaccurate,
  failed,  ///< diverged, did not converge, or its error is not computable
};
std::string to_string(Verdict verdict);

struct Selection {
  std::optional<std::size_t> recommended;  ///< the cheapest candidate meeting both
  /// When none meets the budget: the candidate needing the smallest relaxation of it, i.e. the
  /// least max(error / tolerance, time / time budget); ties go to the faster.
  std::optional<std::size_t> closest;
  /// The cheapest candidate meeting both among the whole-vessel ones (no region of interest), by
  /// the same rule as `recommended` (the same candidate when that one is whole-vessel).
  std::optional<std::size_t> whole_vessel;
  std::vector<Verdict> verdicts;     ///< per candidate
  std::vector<std::string> reasons;  ///< per candidate, why it won or lost, with its numbers
  std::vector<std::size_t> pareto;   ///< finished candidates on the (time, error) Pareto front
};

/// Times per update within this fraction of the fastest passing candidate's are a tie.
inline constexpr double kTimingTie = 0.05;

/// Judges the candidates against `tolerance` (the quantity's unit, named by `unit`) and
/// `seconds_per_update`. The cheapest is the least time per update; ties (times within
/// kTimingTie of the least) go to the smaller error, then to the earlier candidate. A candidate
/// that failed or whose error is not finite can win nothing.
Selection select_model(const std::vector<Candidate>& candidates, double tolerance,
                       double seconds_per_update, const std::string& unit = "mm");

struct RecommendOptions {
  bool quick = false;             ///< models at level 0 only, reference at level ≤ 1
  std::vector<int> levels;        ///< model levels (empty: 0 and 1; quick: 0)
  int reference_level = -1;       ///< the reference's level (−1: the scene's)
  std::vector<double> roi_radii;  ///< m (empty: 2, 4, 8, 16 mm; quick: 4, 8 mm)
  HarnessOptions harness;
};

/// The candidate models of a scene. Static scenes: FEM P1; surface (mid-surface, the mesh's
/// topology) and volume networks with every stiffness rule (msm::kAllStiffnessRules), and the
/// hybrid volume model ("volume/hybrid-volume/...": van-gelder springs + volume term) and the
/// Discrete Shells surface model ("surface/discrete-shells/...": van-gelder membrane + hinges),
/// each with the static Newton solver and the linearised model; with contact loads also the Newton
/// solver on each region-of-interest radius. Dynamic scenes (a scene model uses an integrator):
/// every integrator (msm::kAllIntegrators) at the time steps the scene uses for that family of
/// integrator (explicit or implicit; all of the scene's if it has none of that family), over the
/// scene's longest simulated time, with the scene's point damping, and the local–global implicit
/// Euler (Liu et al. 2013, its default iterations per step) at the implicit family's time steps
/// on the plain spring networks. Static scenes also get each calibrated mass-spring model of the
/// scene (`calibration = "file.json"`) under both static solvers ("volume/calibrated-<file>/...").
std::vector<ModelSpec> candidate_models(const Scene& scene, const std::vector<double>& roi_radii);

/// Candidates' evidence from a run: per (model, level) the worst error and time over ν at the
/// budget's load (SceneResult run with budget_load_only).
std::vector<Candidate> collect_candidates(const SceneResult& result);

/// Budget quantity contact_force: each candidate's error is its wall's in the run's wire–wall
/// contact solve (worst_contact_force_error_mN, guidewire_contact.hpp; every level of a model
/// alike, the solve having its own mesh); a candidate it cannot judge fails with its reason.
void judge_by_contact_force(const GuidewireContact& contact, std::vector<Candidate>& candidates);

struct WireRecommendation;  // wire_candidates.hpp
struct PairCandidates;      // pair_candidates.hpp

struct Recommendation {
  Scene scene;  ///< as run (budget, candidate models, levels)
  SceneResult result;
  std::vector<Candidate> candidates;
  Selection selection;
  /// A guidewire scene's wire candidates (wire_candidates.hpp), judged apart: null otherwise.
  std::shared_ptr<const WireRecommendation> wire;
  /// With a wire's continuum reference: every finished wire with every finished vessel candidate
  /// (pair_candidates.hpp), judged apart: null otherwise.
  std::shared_ptr<const PairCandidates> pairs;
  /// Where the candidates' run wrote results.json (a rate judged again shares the first's).
  std::filesystem::path results_dir;
};

/// Runs the candidates of `scene` (whose budget must be stated) against the reference and writes
/// results.json/csv/summary.md, recommend.md and recommend.json into `output_dir` (checked
/// writable before anything runs). `command` is recorded.
Recommendation recommend(const Scene& scene, const RecommendOptions& options,
                         const std::filesystem::path& output_dir, const std::string& command);

/// True when every candidate's time per update is the same at any rate: no integrator candidates
/// (static and linear models are timed per update; an integrator's update is ⌈period/dt⌉ steps).
bool rate_independent(const Recommendation& r);

/// The same candidates judged against another rate (time per update 1/rate_hz), without running
/// them again. std::logic_error unless rate_independent(r).
Recommendation rejudged(const Recommendation& r, double rate_hz);

/// recommend.json into `output_dir`, and recommend.md: the report's section drawn from that
/// JSON (reports::recommendation_markdown: the budget, the answer, and every candidate's error
/// and time, Pareto front, verdict and reason).
void write_recommendation(const Recommendation& r, const std::filesystem::path& output_dir,
                          const std::string& command);
/// recommend.json (schema "vesselverify.recommend", version 1) as written into `output_dir`: its
/// optional "results" names the candidates' results.json relative to that folder.
std::string recommendation_json(const Recommendation& r, const std::string& command,
                                const std::filesystem::path& output_dir);

}  // namespace vessel
