/// `vesselverify recommend`: the cheapest model that meets a scene's accuracy and rate budget.
#include <iomanip>
#include <iostream>

#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/studies/recommend.hpp"

namespace vessel::cli {

namespace {

struct Options {
  std::string scene;
  double rate_hz = 0.0;
  double time_budget_s = 0.0;
  double tolerance = 0.0;
  std::filesystem::path output_dir = "recommend";
  CacheOptions cache;
  bool quick = false;
  int repeats = 3;
  int updates = kRampUpdates;  ///< static and linear models: updates of the timed load ramp
  std::vector<int> levels;
  int reference_level = -1;
  std::vector<double> roi_radii;
  std::string command;
};

void run(const Options& o) {
  Scene s = read_scene(o.scene);
  if (!s.budget.stated) {
    // No [budget]: the defaults of issue #7 (contact point, the scene's tolerance, 30 Hz visual).
    s.budget.stated = true;
    s.budget.tolerance = s.tolerances.max_error_mm;
    if (o.rate_hz == 0.0 && o.time_budget_s == 0.0) {
      s.budget.rate_hz = 30.0;
      std::cout << "note: " << s.name << " states no [budget]; using the contact point's error ≤ "
                << s.budget.tolerance << " mm at 30 Hz\n";
    }
  }
  if (o.rate_hz > 0.0) {
    s.budget.rate_hz = o.rate_hz;
    s.budget.time_budget_s = 0.0;
  }
  if (o.time_budget_s > 0.0) s.budget.time_budget_s = o.time_budget_s;
  if (o.tolerance > 0.0) s.budget.tolerance = o.tolerance;
  RecommendOptions r;
  r.quick = o.quick;
  r.levels = o.levels;
  r.reference_level = o.reference_level;
  r.roi_radii = o.roi_radii;
  r.harness.cache_dir = o.cache.mesh_dir();
  const auto solution_cache = o.cache.solution_cache(std::cout);
  r.harness.solution_cache = solution_cache.get();
  r.harness.log = &std::cout;
  r.harness.repeats = o.repeats;
  r.harness.ramp_updates = o.updates;
  const Recommendation rec = recommend(s, r, o.output_dir, o.command);
  const Selection& sel = rec.selection;
  std::cout << std::defaultfloat << std::setprecision(3);  // the progress log may have changed it
  const char* unit = budget_unit(rec.scene.budget.quantity);
  if (sel.recommended) {
    const Candidate& c = rec.candidates[*sel.recommended];
    std::cout << "recommended: " << c.name << " (" << c.detail << "): error " << c.error << " "
              << unit << ", " << c.update_seconds * 1e3 << " ms per update ("
              << c.setup_seconds * 1e3 << " ms set-up, once)\n";
  } else if (sel.closest) {
    const Candidate& c = rec.candidates[*sel.closest];
    std::cout << "no candidate meets the budget; closest: " << c.name << ": "
              << sel.reasons[*sel.closest] << "\n";
  } else {
    std::cout << "no candidate meets the budget, and none finished\n";
  }
  if (sel.whole_vessel) {
    const Candidate& c = rec.candidates[*sel.whole_vessel];
    std::cout << "whole vessel (no region of interest): " << c.name << ": error " << c.error
              << " " << unit << ", " << c.update_seconds * 1e3 << " ms per update, "
              << c.setup_seconds * 1e3 << " ms set-up\n";
  } else {
    std::cout << "no whole-vessel candidate (without a region of interest) meets the budget\n";
  }
  std::cout << "wrote " << (o.output_dir / "recommend.md").string()
            << ", recommend.json and the candidates' results.json\n";
  std::cout << solution_cache->summary() << "\n";
}

}  // namespace

void add_recommend_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<Options>();
  o->command = command_line;
  CLI::App* cmd = app.add_subcommand(
      "recommend",
      "Name the cheapest model that meets a scene's budget ([budget]: the error on a quantity "
      "and a rate or time per update). Runs generated candidates (FEM P1; surface and volume "
      "mass-spring models with every stiffness rule, static Newton and linearised solvers or, "
      "for dynamic scenes, every integrator; mesh levels 0-1; region-of-interest radii) against "
      "the FEM reference at the budget's load; writes recommend.md (a report section), "
      "recommend.json and the candidates' results.json.\n"
      "Examples:\n"
      "  vesselverify recommend verification/scenes/contact_straight.toml --rate 1000\n"
      "  vesselverify recommend --quick --time-budget 0.005 --tolerance 0.05 SCENE");
  cmd->add_option("scene", o->scene, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
  auto* rate = cmd->add_option("--rate", o->rate_hz,
                               "Update rate, Hz (30 visual, 1000 haptic); replaces the scene's")
                   ->check(CLI::PositiveNumber);
  cmd->add_option("--time-budget", o->time_budget_s,
                  "Compute time allowed per update, s; replaces the scene's")
      ->check(CLI::PositiveNumber)
      ->excludes(rate);
  cmd->add_option("--tolerance", o->tolerance,
                  "Error tolerance in the budget quantity's unit (mm; mN for reaction)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--output-dir", o->output_dir, "Where the outputs go")->capture_default_str();
  add_cache_options(*cmd, o->cache);
  cmd->add_flag("--quick", o->quick,
                "Candidates at level 0 only (reference at level <= 1), ROI radii 4 and 8 mm");
  cmd->add_option("--repeats", o->repeats, "Timed repeats per solve (median)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--updates", o->updates,
                  "Static and linear mass-spring models: timed as a simulator runs them, set-up "
                  "(assembly, factorisation at rest) apart, then this many warm-started updates "
                  "ramping the load to each case's magnitude; the time per update is their median")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--levels", o->levels, "Model levels instead of 0,1 (quick: 0)")
      ->delimiter(',')
      ->check(CLI::Range(0, kMaxMeshLevel));
  cmd->add_option("--reference-level", o->reference_level,
                  "Level of the P2 reference instead of the scene's (at least the finest model "
                  "level)")
      ->check(CLI::Range(0, kMaxMeshLevel));
  cmd->add_option("--roi-radii", o->roi_radii,
                  "Region-of-interest radii, m, instead of 0.002,0.004,0.008,0.016 (quick: "
                  "0.004,0.008)")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
