#pragma once
/// What a harness run writes: results.json (schema "vesselverify.results", version 1;
/// verification/results.schema.json), results.csv (one row per model, ν and magnitude) and
/// summary.md; each written atomically.
#include <filesystem>
#include <nlohmann/json.hpp>
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
/// One end of a lumen: {group, centre_mm, radius_mm, normal, area_mm2} (results.json's and
/// `mesh --stats-json`'s lumen_ends).
nlohmann::json lumen_end_json(const std::string& group, const LumenEnd& end);
/// A mesh's {min_dihedral_deg, max_dihedral_deg, sliver_count, worst_at} (worst_at: the worst
/// sliver's centroid_mm and its min/max dihedral angles, null without slivers).
nlohmann::json mesh_quality_json(const SliverReport& slivers);

void write_results_csv(const std::filesystem::path& path, const std::vector<SceneResult>& results);
void write_summary_markdown(const std::filesystem::path& path,
                            const std::vector<SceneResult>& results, const std::string& command);

}  // namespace vessel
