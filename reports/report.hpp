#pragma once
/// `vesselverify report`: results.json (and stability.json, recommend.json, if run) → report.md
/// with its figures as .svg files, and report.html, self-contained with the same figures inline.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/results_file.hpp"
#include "reports/study_files.hpp"

namespace vessel::reports {

/// Seed 000's Hooke line: its vessel's spring constant k = E·A/h₀ = 41.106 N/m (seed 000 eq. 4.2
/// and §IV), so x = F/k; the seed compared its mass-spring model against this line (its Fig. 5).
inline constexpr double kSeed000HookeStiffness = 41.106;  // N/m

struct ReportOptions {
  std::filesystem::path results;    ///< results.json of `vesselverify run`
  std::filesystem::path stability;  ///< stability.json of `vesselverify stability` (optional)
  /// recommend.json files of `vesselverify recommend`, each drawn as a section (optional); the
  /// results.json its run wrote beside it, when there, names the load unit and the reference.
  std::vector<std::filesystem::path> recommend;
  std::filesystem::path validity;  ///< validity.json of `vesselverify validity` (optional)
  std::filesystem::path insertion;   ///< of `vesselverify insertion --json` (optional)
  std::filesystem::path output_dir;  ///< report.md, report.html, figures/
  std::string command;               ///< the command line that makes the report
};

/// The report's content: the summary and every scene of `results`, the guidewire's insertion, a
/// section per recommendation, the validity study, then the stability section (absent: a note
/// says it was not run).
Document build_report(const ResultsFile& results, const std::optional<StabilityFile>& stability,
                      const std::string& command,
                      const std::vector<RecommendFile>& recommendations = {},
                      const std::optional<ValidityFile>& validity = std::nullopt,
                      const std::optional<InsertionFile>& insertion = std::nullopt);

/// Fills in what recommend.json leaves to its run's results.json: the scene's load unit and the
/// reference element at each Poisson's ratio (matched by scene name and ν).
void attach_run(RecommendFile& recommendation, const ResultsFile& run);

/// Reads the inputs, builds the report and writes report.md, report.html and figures/*.svg, each
/// atomically. InputError for a missing or malformed input or an unwritable output directory.
void write_report(const ReportOptions& options);

/// The load magnitude a scene's summary and figures are drawn at: representative_load
/// (reports/representative_load.hpp) of the outcomes' magnitudes, at the first reference's strain,
/// with the budget's magnitude when the scene sets one and the run has that load.
double representative_load(const SceneRows& scene);

}  // namespace vessel::reports
