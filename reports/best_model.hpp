#pragma once
/// The report's answer, per scene and Poisson's ratio, to which mass-spring model is best (the
/// lowest relative L2 error), how its error compares with P1 FEM's on the same mesh level, and how
/// its speed compares with P1's. Computed from results.json data alone.
#include <optional>
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

/// One scene, ν and mesh level at the scene's representative load (report.hpp's
/// representative_load).
struct BestModelRow {
  std::string scene;
  double poisson_ratio = 0.0;
  int level = 0;
  double magnitude = 0.0;
  std::string load_unit;
  /// The mass-spring model (kind other than fem) that finished with the lowest relative L2 error
  /// (ties: the faster); empty when none finished. Edge-pair models (P1 FEM written on the tets'
  /// edges, msm/terms/edge_pair_term.hpp) are not candidates: they are the bound a spring model
  /// is measured against, shown apart in edge_pair_*.
  std::string best_model;
  double best_relative_l2 = 0.0;
  /// solve_seconds: for static and linear mass-spring models the time per update (after set-up),
  /// for integrators the run's steps.
  double best_solve_seconds = 0.0;
  /// P1 FEM (kind fem, element P1) on the same level, ν and load, when it ran and finished.
  std::optional<std::string> p1_model;
  double p1_relative_l2 = 0.0;
  double p1_solve_seconds = 0.0;  ///< P1's median update, prepared as linear models are
  /// best / P1 (nullopt without a finished P1 or a best model): error ratio ≤ 1 means as
  /// accurate as P1; time ratio < 1 means faster than P1.
  std::optional<double> error_ratio, time_ratio;
  /// The best edge-pair model on the same case, its error and time over P1's (when both ran).
  std::string edge_pair_model;
  std::optional<double> edge_pair_error_ratio, edge_pair_time_ratio;
};

/// One row per scene, ν and model level that has outcomes at the scene's representative load, in
/// file order (scenes), ascending ν and level.
std::vector<BestModelRow> best_model_rows(const ResultsFile& results);

/// The rows as the report's table.
Table best_model_table(const std::vector<BestModelRow>& rows);

/// Heading, explanation and table in the report.
void best_model_section(Document& doc, const ResultsFile& results);

}  // namespace vessel::reports
