/// `vesselverify validity`: the measured limit of the linear reference's validity and the
/// mass-spring models against the finite-strain reference over a load ladder (issue 17);
/// writes validity.json for the report.
#include <filesystem>
#include <iostream>

#include "meshes/foundation/errors.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/scene_problems.hpp"
#include "verification/studies/validity/validity.hpp"

namespace vessel::cli {

namespace fs = std::filesystem;

namespace {

struct ValidityCli {
  std::vector<fs::path> scenes;
  fs::path output_dir = "results";
  CacheOptions cache;
  bool full = false;
  bool quick = false;
  bool time_updates = false;
  int reference_level = -1;
  int degree = 2;
  std::vector<double> ladder;
  std::vector<std::string> models;
  // Fail fast: Newton near a solution converges in ~3-7 iterations here; a step that needs more
  // than 10 is cheaper halved than iterated to the solver's default 25 (each iteration of P2 on
  // level 0 costs a second or more).
  int max_newton_iterations = 10;
  int jobs = 1;
  std::string fields = "largest";
};

}  // namespace

void add_validity_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<ValidityCli>();
  CLI::App* cmd = app.add_subcommand(
      "validity",
      "Where the linear FEM reference stops being valid, and the mass-spring and P1 tet models "
      "(linear, corotational, XPBD) against the "
      "finite-strain (neo-Hookean) reference over a load ladder (contact: seed 000's 0.01-140 "
      "mN). Per scene one finite-strain continuation through the ladder (cached), the two "
      "references' relative difference at the QoI and over the mesh, the loads where they part "
      "by 1, 5 and 10 %, and each model's errors against the finite-strain reference up to the "
      "largest load reached. Writes validity.json (read by `vesselverify report --validity`).\n"
      "Examples:\n"
      "  vesselverify validity verification/scenes/contact_straight.toml --output-dir results\n"
      "  vesselverify validity --full verification/scenes/contact_arch.toml   # scene's level");
  cmd->add_option("scenes", o->scenes, "Scene files (static loads)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--output-dir", o->output_dir, "Where validity.json goes")
      ->capture_default_str();
  add_cache_options(*cmd, o->cache);
  cmd->add_flag("--full", o->full,
                "The scene's reference level, the full ladder and every whole-vessel static "
                "mass-spring model (default: level 0, the short ladder, the seed models)");
  cmd->add_flag("--quick", o->quick,
                "The quick ladder: contact 0.1, 1 and 10 mN, other loads the scene's largest alone")
      ->excludes("--full");
  cmd->add_flag("--time-updates", o->time_updates,
                "Also time each model's update at each load as `run` does, set-up apart (a ramp "
                "of warm-started updates; XPBD FEM from rest to steady state), with the time per "
                "update at 30 Hz and 1 kHz; scenes one at a time");
  cmd->add_option("--reference-level", o->reference_level,
                  "The references' mesh level (default: 0, or the scene's with --full)");
  cmd->add_option("--degree", o->degree, "The references' element degree")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--ladder", o->ladder,
                  "The loads (the scene's unit: N, Pa or g), comma separated")
      ->delimiter(',');
  cmd->add_option("--models", o->models, "Model names of the scene, comma separated")
      ->delimiter(',');
  cmd->add_option("--max-newton-iterations", o->max_newton_iterations,
                  "Newton iterations per load step of the continuation")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--fields", o->fields,
                  "Each model's VTU fields against the finite-strain reference at the largest load "
                  "reached, under OUTPUT-DIR/validity_fields/<scene>/ (the report draws them in "
                  "3D): largest or none")
      ->check(CLI::IsMember({"largest", "none"}))
      ->capture_default_str();
  add_jobs_option(*cmd, o->jobs,
                  "Scenes studied at a time (default: the core count; 1 with --time-updates)");
  cmd->callback([o, command_line] {
    std::error_code ec;
    fs::create_directories(o->output_dir, ec);
    if (ec) {
      throw InputError("--output-dir " + o->output_dir.string() + ": cannot create it (" +
                       ec.message() + ")");
    }
    const auto cache = o->cache.solution_cache(std::cout);
    ValidityOptions vo;
    vo.full = o->full;
    vo.quick = o->quick;
    vo.time_updates = o->time_updates;
    vo.reference_level = o->reference_level;
    vo.degree = o->degree;
    vo.ladder = o->ladder;
    vo.models = o->models;
    vo.mesh_cache_dir = o->cache.mesh_dir();
    if (o->fields != "none") vo.fields_dir = o->output_dir / "validity_fields";
    vo.cache = cache.get();
    vo.finite.max_newton_iterations = o->max_newton_iterations;
    vo.log = &std::cout;
    std::vector<Scene> scenes;
    for (const fs::path& p : o->scenes) scenes.push_back(read_scene(p));
    for (Scene& s : scenes) solve_guidewire_load(s);
    const ValidityStudy study = run_validity_study(scenes, vo, o->jobs, command_line);
    print_validity_summary(study, std::cout);
    write_validity_json(study, o->output_dir / "validity.json");
    std::cout << cache->summary() << "\n";
    std::cout << "wrote " << (o->output_dir / "validity.json").string() << " in "
              << study.total_seconds << " s\n";
  });
}

}  // namespace vessel::cli
