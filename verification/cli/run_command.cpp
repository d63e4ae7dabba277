/// `vesselverify run`: run scenes against the FEM reference and write results and a summary.
#include <algorithm>
#include <iostream>

#include "meshes/foundation/errors.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/harness/harness.hpp"
#include "verification/harness/results.hpp"
#include "verification/harness/timed_updates.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::cli {

namespace {

struct RunOptions {
  std::vector<std::string> scenes;
  std::filesystem::path output_dir = "results";
  CacheOptions cache;
  int jobs = 1;
  bool quick = false;
  int repeats = 1;
  int updates = kRampUpdates;  ///< static and linear models: updates of the timed load ramp
  std::vector<double> poisson_ratios;  ///< sweeps overriding the scenes' own (empty: keep)
  std::vector<int> levels;
  std::vector<double> magnitudes;
  int reference_level = -1;
  int modes = -1;                 ///< natural frequencies per model (−1: the scenes' [modes])
  int modes_reference_level = -1;  ///< level of the modal reference (−1: the scenes')
  std::string fields = "representative";
  double contact_fine_size = 0.0;  ///< m; 0: the scene's contact_fine_size
  std::string command;
};

/// The command line's sweeps replace the scene's values (after --quick, so they win).
void apply_sweeps(const RunOptions& o, Scene& s) {
  if (!o.poisson_ratios.empty()) s.poisson_ratios = o.poisson_ratios;
  if (!o.magnitudes.empty()) s.load.magnitudes = o.magnitudes;
  if (!o.levels.empty()) {
    s.model_levels = o.levels;
    std::sort(s.model_levels.begin(), s.model_levels.end());
    s.model_levels.erase(std::unique(s.model_levels.begin(), s.model_levels.end()),
                         s.model_levels.end());
    s.vessel.level = s.model_levels.front();
  }
  if (o.reference_level >= 0) s.reference_level = o.reference_level;
  if (o.modes >= 0) s.modes.count = o.modes;
  if (o.modes_reference_level >= 0) s.modes.reference_level = o.modes_reference_level;
  if (s.reference_level < s.model_levels.back()) {
    std::cerr << "warning: " << s.name << ": the reference (level " << s.reference_level
              << ") is coarser than the finest model level (" << s.model_levels.back()
              << "); its error may exceed the models'\n";
  }
}

void run(const RunOptions& o) {
  std::vector<Scene> scenes;
  for (const auto& f : o.scenes) scenes.push_back(read_scene(f));  // validate all before running
  for (Scene& s : scenes) {
    solve_guidewire_load(s);  // a wire that cannot load its vessel stops here
    if (s.load.wire) {
      const GuidewireSolution& w = *s.load.wire;
      std::cout << s.name << ": the guidewire pushes the wall with " << w.force * 1e3 << " mN at ("
                << w.wall_point.x() * 1e3 << ", " << w.wall_point.y() * 1e3 << ", "
                << w.wall_point.z() * 1e3 << ") mm\n";
    }
  }
  for (Scene& s : scenes) {
    if (o.quick) s = quick_variant(std::move(s));
    apply_sweeps(o, s);
  }
  HarnessOptions h;
  h.cache_dir = o.cache.mesh_dir();
  const auto solution_cache = o.cache.solution_cache(std::cout);
  h.solution_cache = solution_cache.get();
  const auto outcome_cache = o.cache.outcome_cache(std::cout);
  h.outcome_cache = outcome_cache.get();
  h.log = &std::cout;
  h.jobs = o.jobs;
  h.repeats = o.repeats;
  h.ramp_updates = o.updates;
  if (o.fields != "none") h.fields_dir = o.output_dir / "fields";
  h.fields_every_load = o.fields == "all";
  h.exchange_dir = o.output_dir / "exchange";  // external models' case folders
  h.contact_fine_size = o.contact_fine_size;
  run_and_write(scenes, h, o.output_dir, o.command);
  std::cout << solution_cache->summary() << "\n" << outcome_cache->summary() << "\n";
}

}  // namespace

void add_run_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<RunOptions>();
  o->command = command_line;
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Run scenes: every model of each scene against the FEM reference (P2, or Taylor-Hood P2-P1 "
      "for nu >= 0.49) at every Poisson's ratio and load magnitude; write results.json (schema "
      "vesselverify.results), results.csv and summary.md (seed 000's error statistics in mm, the "
      "reference's own uncertainty, timings) and VTU fields per model (fields/).\n"
      "Examples:\n"
      "  vesselverify run verification/scenes/contact_straight.toml\n"
      "  vesselverify run --quick --output-dir results verification/scenes/*.toml");
  cmd->add_option("scenes", o->scenes, "Scene files (TOML)")->required();
  cmd->add_option("--output-dir", o->output_dir, "Where results are written")->capture_default_str();
  add_cache_options(*cmd, o->cache);
  add_retime_option(*cmd, o->cache.retime);
  add_jobs_option(*cmd, o->jobs, kReferencesAtATime);
  cmd->add_flag("--quick", o->quick,
                "Coarse levels (models 0, reference 1) and the smallest and largest load only; a "
                "guidewire's contact solve at the scene wire's EI alone, its mesh at 0.12 mm");
  add_timing_options(*cmd, o->repeats, o->updates);
  cmd->add_option("--nu", o->poisson_ratios,
                  "Sweep Poisson's ratio over these values instead of the scenes' (e.g. "
                  "--nu 0,0.25,0.45,0.49,0.5)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--levels", o->levels,
                  "Run the models at these mesh levels instead of the scenes' (a convergence "
                  "sweep, e.g. --levels 0,1,2)")
      ->delimiter(',')
      ->check(CLI::Range(0, kMaxMeshLevel));
  cmd->add_option("--magnitudes", o->magnitudes,
                  "Load magnitudes instead of the scenes' (N, Pa or g as the scene's load)")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  cmd->add_option("--reference-level", o->reference_level,
                  "Level of the P2 reference instead of the scene's (its uncertainty comes from "
                  "the level below)")
      ->check(CLI::Range(0, kMaxMeshLevel));
  cmd->add_option("--modes", o->modes,
                  "Lowest natural frequencies per model instead of the scenes' [modes] count (0: "
                  "none), beside the FEM's (P2, displacement formulation, consistent mass)")
      ->check(CLI::Range(0, 100));
  cmd->add_option("--modes-reference-level", o->modes_reference_level,
                  "Mesh level of the modal reference instead of the scenes' [modes] "
                  "reference_level (default there: the scene's reference level)")
      ->check(CLI::Range(0, kMaxMeshLevel));
  cmd->add_option("--fields", o->fields,
                  "VTU files for ParaView under OUTPUT-DIR/fields/<scene>/ (model and reference "
                  "displacement, their difference), one per model, nu and level: at the "
                  "representative load (the budget's, else the largest within 5 % strain), at "
                  "every load, or none")
      ->check(CLI::IsMember({"representative", "all", "none"}))
      ->capture_default_str();
  cmd->add_option("--contact-fine-size", o->contact_fine_size,
                  "Guidewire scenes with coupling = \"contact\": the contact mesh's element size "
                  "near the wire's contact, m (default: the scene's contact_fine_size)")
      ->check(CLI::PositiveNumber);
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
