#pragma once
/// A guidewire scene's wire–vessel pairs in `vesselverify recommend`: what a simulator runs is a
/// rod model and a vessel model together, so every finished wire candidate (wire_candidates.hpp)
/// is paired with every finished vessel candidate (recommend.hpp) and the pairs are judged against
/// the same budget. A pair's error is the sum of its two errors in the budget's unit, each measured
/// against its own reference (the wire against the continuum wire in the rigid lumen; the vessel
/// against the FEM reference under the wire's load): the triangle inequality's bound on the pair's
/// error as long as the wire's error does not change with the wall's compliance (an estimate, not
/// a solve of the pair). Its time per update is the sum of the two (solved one after the other);
/// the exchange of the contact force between them is not timed.
#include <nlohmann/json_fwd.hpp>
#include <utility>
#include <vector>

#include "verification/studies/recommend/recommend.hpp"
#include "verification/studies/recommend/wire_candidates.hpp"

namespace vessel {

struct PairCandidates {
  /// Per pair: "<wire> + <vessel>", error and times as above (ok: both parts finished).
  std::vector<Candidate> pairs;
  /// Per pair: its wire's index among the wire candidates and its vessel's among the vessel ones.
  std::vector<std::pair<std::size_t, std::size_t>> parts;
  Selection selection;  ///< select_model on the pairs
};

/// Every finished wire with every finished vessel candidate, judged against `budget`. Failed
/// candidates make no pair (their own tables say why).
PairCandidates pair_candidates(const std::vector<WireCandidate>& wires,
                               const std::vector<Candidate>& vessels, const Budget& budget);

/// recommend.json's "pairs" object: the recommended and closest pairs, and every pair with its
/// wire's and vessel's names (`wires` and `vessels` those it was made from).
nlohmann::json pair_recommendation_json(const PairCandidates& p,
                                        const std::vector<WireCandidate>& wires,
                                        const std::vector<Candidate>& vessels);

}  // namespace vessel
