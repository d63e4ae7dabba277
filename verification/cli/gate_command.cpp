/// `vesselverify gate`: the CI gate of model changes. Runs the gate scenes (quick variants: coarse
/// levels, smallest and largest load) and compares with a committed baseline; fails with a table
/// of what changed when a model's error grows, a model that finished now fails, or a normalised
/// solve time regresses.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "reports/gate.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/harness/harness.hpp"
#include "verification/harness/results.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::cli {

namespace {

/// The shipped scenes the gate runs (quick variants), resolved in --scenes-dir.
const std::vector<std::string> kGateScenes{"contact_straight.toml", "pressure_lame.toml",
                                           "gravity_sag.toml", "guidewire_straight.toml"};

struct GateOptions {
  std::filesystem::path baseline;
  std::filesystem::path current;  ///< compare this results file instead of running the scenes
  std::filesystem::path scenes_dir = VESSELVERIFY_SCENES_DIR;
  /// The user's own scenes (files, or folders of *.toml) instead of the shipped gate scenes; run
  /// as written unless `quick`.
  std::vector<std::filesystem::path> scenes;
  bool quick = false;
  std::filesystem::path output_dir = "gate-results";
  CacheOptions cache;
  int jobs = 1;
  bool update_baseline = false;
  reports::GateTolerances tolerances;
  std::string command;
};

/// Thrown when the gate finds a regression: main() prints it and exits 1.
class GateFailed : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The scene files named: files as given, folders as their *.toml files (sorted by name).
std::vector<std::filesystem::path> scene_files(const std::vector<std::filesystem::path>& given) {
  std::vector<std::filesystem::path> files;
  for (const auto& p : given) {
    if (!std::filesystem::is_directory(p)) {
      files.push_back(p);  // read_scene says if it is missing
      continue;
    }
    std::vector<std::filesystem::path> in_dir;
    for (const auto& e : std::filesystem::directory_iterator(p)) {
      if (e.is_regular_file() && e.path().extension() == ".toml") in_dir.push_back(e.path());
    }
    if (in_dir.empty()) {
      throw InputError(p.string() + ": no *.toml scene files in this folder; expected at least one");
    }
    std::sort(in_dir.begin(), in_dir.end());
    files.insert(files.end(), in_dir.begin(), in_dir.end());
  }
  return files;
}

void gate(const GateOptions& o) {
  std::filesystem::path results_path = o.current;
  if (results_path.empty()) {
    std::vector<Scene> scenes;
    if (o.scenes.empty()) {
      for (const auto& name : kGateScenes) {
        scenes.push_back(quick_variant(read_scene(o.scenes_dir / name)));
      }
    } else {
      for (const auto& file : scene_files(o.scenes)) {
        Scene s = read_scene(file);  // every scene validated before anything runs
        scenes.push_back(o.quick ? quick_variant(std::move(s)) : std::move(s));
      }
    }
    for (Scene& s : scenes) solve_guidewire_load(s);  // every wire before anything runs
    HarnessOptions h;
    h.cache_dir = o.cache.mesh_dir();
    const auto solution_cache = o.cache.solution_cache(std::cout);
    h.solution_cache = solution_cache.get();
    h.log = &std::cout;
    h.jobs = o.jobs;
    h.repeats = 3;  // medians: the gate compares times
    h.exchange_dir = o.output_dir / "exchange";  // external models' case folders
    run_and_write(scenes, h, o.output_dir, o.command);
    std::cout << solution_cache->summary() << "\n";
    results_path = o.output_dir / "results.json";
  }
  const reports::ResultsFile current = reports::read_results(results_path);
  if (o.update_baseline) {
    std::ifstream in(results_path);
    write_file_atomically(o.baseline, [&](std::ostream& out) { out << in.rdbuf(); });
    std::cout << "baseline updated: " << o.baseline.string() << " (from "
              << results_path.string() << ")\n";
    return;
  }
  if (!std::filesystem::exists(o.baseline)) {
    throw InputError(o.baseline.string() +
                     ": baseline not found; create it with `vesselverify gate --baseline " +
                     o.baseline.string() + " --update-baseline`");
  }
  const reports::ResultsFile baseline = reports::read_results(o.baseline);
  const reports::GateOutcome outcome = reports::compare_with_baseline(baseline, current, o.tolerances);
  reports::Document doc;
  doc.heading(1, std::string("Gate ") + (outcome.passed() ? "passed" : "FAILED"));
  std::ostringstream summary;  // default stream precision: "+2 %", not "+2.000000 %"
  summary << "Compared " << outcome.compared << " cases of `" << results_path.string()
          << "` with the baseline `" << o.baseline.string() << "` (error tolerance +"
          << o.tolerances.error_relative * 100.0 << " %, timing ratio "
          << o.tolerances.timing_ratio
          << " on solve times normalised by the reference kernel: per update for static and "
             "linear mass-spring models, the run's steps for integrators, set-up not gated).";
  doc.paragraph(summary.str());
  if (!outcome.findings.empty()) doc.table(reports::gate_table(outcome));
  const std::string text = doc.markdown_text(".");
  std::cout << text;
  std::error_code ec;
  std::filesystem::create_directories(o.output_dir, ec);
  if (!ec) write_file_atomically(o.output_dir / "gate.md", [&](std::ostream& out) { out << text; });
  if (!outcome.passed()) {
    throw GateFailed("gate failed: a model's error, stability or speed regressed (table above); "
                     "if the change is intended, rerun with --update-baseline and commit the "
                     "baseline");
  }
}

}  // namespace

void add_gate_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<GateOptions>();
  o->command = command_line;
  CLI::App* cmd = app.add_subcommand(
      "gate",
      "CI gate of model changes: run the gate scenes (quick variants of contact_straight, "
      "pressure_lame, gravity_sag and guidewire_straight) and compare with a committed baseline. "
      "Fails (exit 1) with a table of what changed if any model's error grows beyond the "
      "tolerance (in a guidewire scene also the wire's force error against the continuum wire and "
      "each model's coupled contact-force error), a model that "
      "finished now fails, or a solve time normalised by a reference kernel grows beyond the "
      "timing ratio.\n"
      "Examples:\n"
      "  vesselverify gate --baseline reports/baseline.json\n"
      "  vesselverify gate --baseline reports/baseline.json --update-baseline\n"
      "  vesselverify gate --baseline reports/baseline.json --current results/results.json\n"
      "  vesselverify gate --scenes my_scenes/ --baseline my_baseline.json --update-baseline\n"
      "  vesselverify gate --scenes my_scenes/ --baseline my_baseline.json");
  cmd->add_option("--baseline", o->baseline, "Baseline results file (committed)")->required();
  cmd->add_flag("--update-baseline", o->update_baseline,
                "Rewrite the baseline with this run's results instead of comparing");
  cmd->add_option("--current", o->current,
                  "Compare this results file (same gate scenes) instead of running the scenes")
      ->check(CLI::ExistingFile);
  cmd->add_option("--scenes-dir", o->scenes_dir, "Where the gate scenes are")->capture_default_str();
  cmd->add_option("--scenes", o->scenes,
                  "Your own scenes instead of the shipped gate scenes: scene files, or folders "
                  "whose *.toml files are taken (their external models are run too), run as "
                  "written (see --quick); compare against your own --baseline")
      ->expected(1, -1);
  cmd->add_flag("--quick", o->quick,
                "With --scenes: run their quick variants (models at level 0, smallest and "
                "largest load), as the shipped gate scenes are");
  cmd->add_option("--output-dir", o->output_dir, "Where this run's results and gate.md go")
      ->capture_default_str();
  add_cache_options(*cmd, o->cache);
  add_jobs_option(*cmd, o->jobs, kReferencesAtATime);
  cmd->add_option("--error-tolerance", o->tolerances.error_relative,
                  "Relative growth of a max or RMS error that fails the gate")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_option("--timing-ratio", o->tolerances.timing_ratio,
                  "Growth factor of a normalised solve time that fails the gate")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd->callback([o] { gate(*o); });
}

}  // namespace vessel::cli
