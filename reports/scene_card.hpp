#pragma once
/// The answer a reader came for, one card per scene: the recommended model (the fastest that meets
/// the scene's budget, else its tolerance), the best mass-spring model, their error beside P1's and
/// time per update, and each model that failed with a one-line reason. From results.json alone.
#include <optional>
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

struct CardModel {
  OutcomeRow outcome;
  bool passes = false;                ///< meets the budget (or, without one, the tolerance)
  double update_seconds = 0.0;        ///< the budget's time per update, else solve_seconds
  std::optional<double> ratio_to_p1;  ///< relative L2 over P1's on the same level, ν and load
};

struct CardFailure {
  std::string model;
  int level = 0;
  std::string reason;   ///< the message's first sentence
  std::string message;  ///< the whole message
};

struct SceneCard {
  std::string scene, description, vessel, load;
  double magnitude = 0.0, poisson_ratio = 0.0;
  std::string load_text;  ///< the magnitude with its unit (mN for forces)
  double tolerance_mm = 0.1;
  std::optional<BudgetRow> budget;
  /// The fastest finished model that passes; nullopt when none does.
  std::optional<CardModel> recommended;
  /// The mass-spring model with the lowest relative L2 error (best_model.hpp) on the finest level.
  std::optional<CardModel> best_spring;
  std::vector<CardFailure> failures;
};

/// Whether an outcome meets its scene's budget (error on the budget's quantity and time per
/// update) or, without a budget, the scene's max-error tolerance.
bool passes(const SceneRows& scene, const OutcomeRow& outcome);

/// A failure message's first sentence (up to the first ". ", "; " or line break, at most 140
/// characters, "…" when cut).
std::string first_sentence(const std::string& message);

/// One card per scene at its representative load and first Poisson's ratio.
std::vector<SceneCard> scene_cards(const ResultsFile& results);

/// The cards as a table, for report.md and the page without scripts.
Table scene_card_table(const std::vector<SceneCard>& cards);

}  // namespace vessel::reports
