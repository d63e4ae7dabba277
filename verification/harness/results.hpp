#pragma once
/// What a harness run writes: results.json (schema "vesselverify.results", version 1;
/// verification/results.schema.json), results.csv (one row per model, ν and magnitude) and
/// summary.md; each written atomically.
#include <filesystem>
#include <string>
#include <vector>

#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"

namespace vessel {

/// run_scenes, then writes results.json (with reference_kernel_seconds() timed first), results.csv and summary.md into
/// `output_dir`, which is created and checked writable before anything runs (InputError).
std::vector<SceneResult> run_and_write(const std::vector<Scene>& scenes,
                                       const HarnessOptions& options,
                                       const std::filesystem::path& output_dir,
                                       const std::string& command);

/// Results as versioned JSON (schema "vesselverify.results", version 1; see
/// verification/results.schema.json), CSV (one row per model, ν and magnitude) and a Markdown
/// summary table; each written atomically.
/// `reference_kernel_seconds` (reference_kernel_seconds() of the same run, for the gate's
/// normalised timings) is written when positive.
void write_results_json(const std::filesystem::path& path, const std::vector<SceneResult>& results,
                        const std::string& command, double reference_kernel_seconds = 0.0);
void write_results_csv(const std::filesystem::path& path, const std::vector<SceneResult>& results);
void write_summary_markdown(const std::filesystem::path& path,
                            const std::vector<SceneResult>& results, const std::string& command);

}  // namespace vessel
