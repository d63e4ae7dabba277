/// `vesselverify recommend`: the cheapest model that meets a scene's accuracy and rate budget.
#include <iomanip>
#include <iostream>

#include "reports/document.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/scene_problems.hpp"
#include "verification/studies/recommend/pair_candidates.hpp"
#include "verification/studies/recommend/recommend.hpp"

namespace vessel::cli {

namespace {

using reports::significant;

struct Options {
  std::string scene;
  std::vector<double> rates_hz;  ///< several: one recommendation per rate, in <output-dir>/<rate>hz
  double time_budget_s = 0.0;
  double tolerance = 0.0;
  std::filesystem::path output_dir = "recommend";
  CacheOptions cache;
  int jobs = 1;
  bool quick = false;
  int repeats = 3;
  int updates = kRampUpdates;  ///< static and linear models: updates of the timed load ramp
  std::vector<int> levels;
  int reference_level = -1;
  std::vector<double> roi_radii;
  std::string command;
};

/// The answer on the terminal: the recommended (or closest) candidate and the whole-vessel one.
void print_recommendation(const Recommendation& rec, const std::filesystem::path& dir) {
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
  if (rec.pairs) {
    const Selection& p = rec.pairs->selection;
    if (p.recommended) {
      const Candidate& c = rec.pairs->pairs[*p.recommended];
      std::cout << "wire and vessel together: " << c.name << ": error " << c.error << " " << unit
                << " (the sum of theirs), " << c.update_seconds * 1e3 << " ms per update\n";
    } else {
      std::cout << "no wire-vessel pair meets the budget"
                << (p.closest ? "; closest: " + rec.pairs->pairs[*p.closest].name + ": " +
                                    p.reasons[*p.closest]
                              : std::string())
                << "\n";
    }
  }
  std::cout << "wrote " << (dir / "recommend.md").string()
            << ", recommend.json and the candidates' results.json\n";
}

/// Where one rate's recommendation goes: the output directory, or with several rates its
/// <rate>hz subdirectory.
std::filesystem::path rate_dir(const Options& o, double rate_hz) {
  if (o.rates_hz.size() <= 1) return o.output_dir;
  return o.output_dir / (significant(rate_hz, 6) + "hz");
}

void run(const Options& o) {
  Scene s = read_scene(o.scene);
  solve_guidewire_load(s);
  if (!s.budget.stated) {
    // No [budget]: the defaults of issue #7 (contact point, the scene's tolerance, 30 Hz visual).
    s.budget.stated = true;
    s.budget.tolerance = s.tolerances.max_error_mm;
    if (o.rates_hz.empty() && o.time_budget_s == 0.0) {
      s.budget.rate_hz = 30.0;
      std::cout << "note: " << s.name << " states no [budget]; using the contact point's error ≤ "
                << s.budget.tolerance << " mm at 30 Hz\n";
    }
  }
  if (!o.rates_hz.empty()) {
    s.budget.rate_hz = o.rates_hz.front();
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
  const auto outcome_cache = o.cache.outcome_cache(std::cout);
  r.harness.outcome_cache = outcome_cache.get();
  r.harness.log = &std::cout;
  r.harness.jobs = o.jobs;
  r.harness.repeats = o.repeats;
  r.harness.ramp_updates = o.updates;
  const Recommendation first = recommend(s, r, rate_dir(o, s.budget.rate_hz), o.command);
  print_recommendation(first, rate_dir(o, s.budget.rate_hz));
  for (std::size_t k = 1; k < o.rates_hz.size(); ++k) {
    const double rate = o.rates_hz[k];
    std::cout << "\n== " << significant(rate, 6) << " Hz ==\n";
    if (rate_independent(first)) {
      // Static and linear candidates cost the same per update at any rate: judged again, not run.
      const Recommendation rec = rejudged(first, rate);
      const std::filesystem::path dir = rate_dir(o, rate);
      std::filesystem::create_directories(dir);
      write_recommendation(rec, dir, o.command);  // names the first rate's results.json
      print_recommendation(rec, rate_dir(o, rate));
    } else {
      Scene at_rate = s;
      at_rate.budget.rate_hz = rate;
      print_recommendation(recommend(at_rate, r, rate_dir(o, rate), o.command), rate_dir(o, rate));
    }
  }
  std::cout << solution_cache->summary() << "\n" << outcome_cache->summary() << "\n";
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
      "the FEM reference at the budget's load; in a guidewire scene also the wire's rod models "
      "against the continuum wire, and every wire-vessel pair (with quantity = \"contact_force\" "
      "each "
      "vessel model judged by its wall's force in the wire-wall contact solve); writes "
      "recommend.md (a report "
      "section), recommend.json and the candidates' results.json.\n"
      "Examples:\n"
      "  vesselverify recommend verification/scenes/contact_straight.toml --rate 1000\n"
      "  vesselverify recommend --quick --time-budget 0.005 --tolerance 0.05 SCENE");
  cmd->add_option("scene", o->scene, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
  auto* rate = cmd->add_option("--rate", o->rates_hz,
                               "Update rate, Hz (30 visual, 1000 haptic); replaces the scene's. "
                               "Several (--rate 30,1000): one recommendation per rate in "
                               "<output-dir>/<rate>hz, the candidates run once (static scenes)")
                   ->delimiter(',')
                   ->check(CLI::PositiveNumber);
  cmd->add_option("--time-budget", o->time_budget_s,
                  "Compute time allowed per update, s; replaces the scene's")
      ->check(CLI::PositiveNumber)
      ->excludes(rate);
  cmd->add_option(
         "--tolerance", o->tolerance,
         "Error tolerance in the budget quantity's unit (mm; mN for reaction and contact_force)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--output-dir", o->output_dir, "Where the outputs go")->capture_default_str();
  add_cache_options(*cmd, o->cache);
  add_retime_option(*cmd, o->cache.retime);
  add_jobs_option(*cmd, o->jobs, kReferencesAtATime);
  cmd->add_flag("--quick", o->quick,
                "Candidates at level 0 only (reference at level <= 1), ROI radii 4 and 8 mm");
  add_timing_options(*cmd, o->repeats, o->updates);
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
