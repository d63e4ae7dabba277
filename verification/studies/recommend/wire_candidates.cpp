#include "verification/studies/recommend/wire_candidates.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "verification/guidewire/guidewire_load.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

namespace {

constexpr double kWireSpeed = 10e-3;  ///< m/s: how fast the timed updates move the wire
constexpr int kTimedUpdates = 10;

std::vector<Candidate> as_candidates(const std::vector<WireCandidate>& wires) {
  std::vector<Candidate> out;
  for (const WireCandidate& w : wires) {
    Candidate c;
    c.name = w.name;
    c.model = w.model;
    c.ok = w.ok;
    c.failure = w.failure;
    c.error = w.error;
    c.update_seconds = w.update_seconds;
    c.setup_seconds = w.setup_seconds;
    out.push_back(c);
  }
  return out;
}

/// One candidate: the wire inserted (set-up), its error at the scene's insertion, then the timed
/// updates (withdrawn by one update's travel each, from the last equilibrium).
WireCandidate run_candidate(const Scene& scene, const WireReference& ref, WireModel model,
                            int segments) {
  WireCandidate c;
  c.model = to_string(model);
  c.segments = segments;
  c.name = "wire/" + c.model + " @ N" + std::to_string(segments);
  GuidewireSpec spec = *scene.load.guidewire;
  spec.model = model;
  spec.segments = segments;
  try {
    GuidewireSolver solver(scene.vessel, spec);
    Stopwatch setup;
    const GuidewireSolution s = solver.solve_rigid();
    c.setup_seconds = setup.seconds();
    c.force = s.force;
    c.force_error_mN = std::abs(s.force - ref.force) * 1e3;
    c.contact_error_mm = (s.contact_point - ref.contact_point).norm() * 1e3;
    c.error = std::string(budget_unit(scene.budget.quantity)) == "mN" ? c.force_error_mN
                                                                       : c.contact_error_mm;
    const double period = scene.budget.update_period();
    const bool dynamic = model == WireModel::xpbd;
    c.update = dynamic ? "one XPBD step of the update period"
                       : "a static re-solve after one update's travel at 10 mm/s";
    std::vector<double> times;
    for (int k = 1; k <= kTimedUpdates; ++k) {
      Stopwatch update;
      if (dynamic) {
        (void)solver.step(period);
      } else {
        (void)solver.solve_at_insertion(spec.insertion - k * kWireSpeed * period);
      }
      times.push_back(update.seconds());
    }
    // A step that does not hold the wire at rest would make its steady state's error a promise
    // the simulator does not keep.
    if (dynamic && std::abs(solver.last().force / s.force - 1.0) > 1e-6) {
      throw std::runtime_error("XPBD's step of " + std::to_string(period) +
                               " s does not hold the wire at rest (contact force " +
                               std::to_string(solver.last().force) + " N after " +
                               std::to_string(kTimedUpdates) + " steps, " +
                               std::to_string(s.force) + " N at rest)");
    }
    std::nth_element(times.begin(), times.begin() + kTimedUpdates / 2, times.end());
    c.update_seconds = times[kTimedUpdates / 2];
    c.ok = true;
  } catch (const std::exception& e) {
    c.failure = e.what();
  }
  return c;
}

}  // namespace

std::optional<WireReference> continuum_wire(const Scene& scene, std::string& why) {
  if (!scene.load.guidewire) {
    why = "the scene's load is not a guidewire";
    return std::nullopt;
  }
  return continuum_wire(scene.vessel, *scene.load.guidewire, why);
}

Selection judge_wire(const std::vector<WireCandidate>& candidates, const Budget& budget) {
  return select_model(as_candidates(candidates), budget.tolerance, budget.seconds_per_update(),
                      budget_unit(budget.quantity));
}

WireRecommendation recommend_wire(const Scene& scene, const std::vector<WireModel>& models,
                                  const std::vector<int>& segments) {
  WireRecommendation w;
  w.reference = continuum_wire(scene, w.no_reference);
  if (!w.reference) return w;
  for (const WireModel m : models) {
    for (const int n : segments) w.candidates.push_back(run_candidate(scene, *w.reference, m, n));
  }
  w.selection = judge_wire(w.candidates, scene.budget);
  return w;
}

nlohmann::json wire_recommendation_json(const WireRecommendation& w) {
  if (!w.reference) return {{"reference", nullptr}, {"no_reference", w.no_reference}};
  nlohmann::json candidates = nlohmann::json::array();
  for (std::size_t i = 0; i < w.candidates.size(); ++i) {
    const WireCandidate& c = w.candidates[i];
    nlohmann::json j{{"name", c.name},
                     {"model", c.model},
                     {"segments", c.segments},
                     {"ok", c.ok},
                     {"verdict", to_string(w.selection.verdicts[i])},
                     {"reason", w.selection.reasons[i]}};
    if (c.ok) {
      j["contact_force_N"] = c.force;
      j["force_error_mN"] = c.force_error_mN;
      j["contact_point_error_mm"] = c.contact_error_mm;
      j["error"] = c.error;
      j["update_seconds"] = c.update_seconds;
      j["update"] = c.update;
      j["setup_seconds"] = c.setup_seconds;
    } else {
      j["failure"] = c.failure;
    }
    candidates.push_back(j);
  }
  const Vec3& p = w.reference->contact_point;
  return {{"reference",
           {{"what", w.reference->what},
            {"contact_force_N", w.reference->force},
            {"contact_point_mm", {p.x() * 1e3, p.y() * 1e3, p.z() * 1e3}}}},
          {"recommended", w.selection.recommended
                              ? nlohmann::json(w.candidates[*w.selection.recommended].name)
                              : nlohmann::json(nullptr)},
          {"candidates", candidates}};
}

}  // namespace vessel
