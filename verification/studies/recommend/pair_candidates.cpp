#include "verification/studies/recommend/pair_candidates.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

namespace vessel {

PairCandidates pair_candidates(const std::vector<WireCandidate>& wires,
                               const std::vector<Candidate>& vessels, const Budget& budget) {
  PairCandidates out;
  for (std::size_t w = 0; w < wires.size(); ++w) {
    if (!wires[w].ok) continue;
    for (std::size_t v = 0; v < vessels.size(); ++v) {
      const Candidate& vessel = vessels[v];
      if (!vessel.ok) continue;
      Candidate c;
      c.name = wires[w].name + " + " + vessel.name;
      c.model = vessel.model;
      c.detail = vessel.detail;
      c.level = vessel.level;
      c.roi_radius = vessel.roi_radius;
      c.unknowns = vessel.unknowns;
      c.ok = true;
      c.error = wires[w].error + vessel.error;  // NaN (not computable) stays NaN
      c.update_seconds = wires[w].update_seconds + vessel.update_seconds;
      c.setup_seconds = wires[w].setup_seconds + vessel.setup_seconds;
      out.pairs.push_back(c);
      out.parts.emplace_back(w, v);
    }
  }
  out.selection = select_model(out.pairs, budget.tolerance, budget.seconds_per_update(),
                               budget_unit(budget.quantity));
  return out;
}

nlohmann::json pair_recommendation_json(const PairCandidates& p,
                                        const std::vector<WireCandidate>& wires,
                                        const std::vector<Candidate>& vessels) {
  const Selection& sel = p.selection;
  nlohmann::json pairs = nlohmann::json::array();
  for (std::size_t i = 0; i < p.pairs.size(); ++i) {
    const Candidate& c = p.pairs[i];
    pairs.push_back(
        {{"name", c.name},
         {"wire", wires.at(p.parts[i].first).name},
         {"vessel", vessels.at(p.parts[i].second).name},
         {"error", std::isfinite(c.error) ? nlohmann::json(c.error) : nlohmann::json(nullptr)},
         {"update_seconds", c.update_seconds},
         {"setup_seconds", c.setup_seconds},
         {"pareto", std::find(sel.pareto.begin(), sel.pareto.end(), i) != sel.pareto.end()},
         {"verdict", to_string(sel.verdicts[i])},
         {"reason", sel.reasons[i]}});
  }
  const auto name_of = [&](const std::optional<std::size_t>& i) {
    return i ? nlohmann::json(p.pairs[*i].name) : nlohmann::json(nullptr);
  };
  return {{"recommended", name_of(sel.recommended)},
          {"closest", name_of(sel.closest)},
          {"pairs", pairs}};
}

}  // namespace vessel
