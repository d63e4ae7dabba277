#pragma once
/// `vesselverify report`: results.json (and the stability section, if run) → report.md with its
/// figures as .svg files, and report.html, self-contained with the same figures inline.
#include <filesystem>
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

/// Seed 000's Hooke line: its vessel's spring constant k = E·A/h₀ = 41.106 N/m (seed 000 eq. 4.2
/// and §IV), so x = F/k; the seed compared its mass-spring model against this line (its Fig. 5).
inline constexpr double kSeed000HookeStiffness = 41.106;  // N/m

struct ReportOptions {
  std::filesystem::path results;           ///< results.json of `vesselverify run`
  std::filesystem::path stability_markdown;  ///< stability.md of `vesselverify stability` (optional)
  /// recommend.md files of `vesselverify recommend`, each embedded as a section (optional).
  std::vector<std::filesystem::path> recommend_markdown;
  std::filesystem::path output_dir;        ///< report.md, report.html, figures/
  std::string command;                     ///< the command line that makes the report
};

/// The report's content. `stability_markdown` is embedded verbatim (empty: a note says it was
/// not run), and so is each of `recommendations` (recommend.md sections), after the scenes.
Document build_report(const ResultsFile& results, const std::string& stability_markdown,
                      const std::string& command,
                      const std::vector<std::string>& recommendations = {});

/// Reads the inputs, builds the report and writes report.md, report.html and figures/*.svg, each
/// atomically. InputError for a missing or malformed input or an unwritable output directory.
void write_report(const ReportOptions& options);

/// The load magnitude a scene's summary and figures are drawn at: representative_load
/// (reports/representative_load.hpp) of the outcomes' magnitudes, at the first reference's strain,
/// with the budget's magnitude when the scene sets one and the run has that load.
double representative_load(const SceneRows& scene);

}  // namespace vessel::reports
