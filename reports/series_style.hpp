#pragma once
/// One colour and marker per model across every plot of a report, and the reference's own: a
/// model keeps its style whichever plot, level or ν it appears in.
#include <map>
#include <string>

#include "reports/results_file.hpp"
#include "reports/svg_plot.hpp"

namespace vessel::reports {

/// The FEM reference in every plot: black, thicker, no model uses it.
inline constexpr const char* kReferenceColour = "#000000";
/// The Pareto front of the speed–error plots.
inline constexpr const char* kParetoColour = "#6a3d9a";

class SeriesStyles {
 public:
  SeriesStyles() = default;
  /// Models numbered in order of first appearance over the scenes' outcomes and modal rows.
  explicit SeriesStyles(const ResultsFile& results);
  /// Sets the series' colour and marker to the model's (a model not seen before gets the next).
  void apply(Series& series, const std::string& model);

 private:
  std::map<std::string, std::size_t> index_;
};

}  // namespace vessel::reports
