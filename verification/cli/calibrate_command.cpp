/// `vesselverify calibrate`: a mass-spring model's stiffness fitted to the FEM reference on a
/// scene's training loads, and checked on held-out loads (verification/studies/calibrate/calibrate.hpp).
#include <fstream>
#include <iostream>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/scene_problems.hpp"
#include "verification/studies/calibrate/calibrate.hpp"

namespace vessel::cli {

namespace {

struct Options {
  std::string scene;
  std::string model;
  std::string granularity = "groups";
  std::string weights = "equal";
  double gravity = CalibrateOptions{}.gravity;
  std::vector<std::string> train;
  std::vector<std::string> held_out_scenes;
  double nu = -1.0;
  int level = -1;
  int reference_level = -1;
  double smoothness = CalibrateOptions{}.regulariser.smoothness;
  double ridge = CalibrateOptions{}.regulariser.ridge;
  int iterations = CalibrateOptions{}.max_iterations;
  std::string prior;
  std::filesystem::path output = "calibration.json";
  std::filesystem::path summary;
  std::filesystem::path study;
  CacheOptions cache;
  std::string command;
};

LoadKind parse_kind(const std::string& k) {
  if (k == "contact") return LoadKind::contact;
  if (k == "pressure") return LoadKind::pressure;
  if (k == "gravity") return LoadKind::gravity;
  throw InputError("--train: found \"" + k + "\", expected contact, pressure or gravity");
}

/// --study, or the calibration file's name with ".study.json" for its extension.
std::filesystem::path study_output(const Options& o) {
  if (!o.study.empty()) return o.study;
  std::filesystem::path p = o.output;
  return p.replace_extension(".study.json");
}

void run(const Options& o) {
  Scene s = read_scene(o.scene);
  solve_guidewire_load(s);
  CalibrateOptions c;
  c.model = o.model;
  c.granularity = parse_calibration_granularity(o.granularity);
  c.weights = parse_case_weights(o.weights);
  c.gravity = o.gravity;
  for (const auto& k : o.train) c.train.push_back(parse_kind(k));
  for (const auto& f : o.held_out_scenes) {
    c.other_vessels.push_back(read_scene(f));
    solve_guidewire_load(c.other_vessels.back());
  }
  if (o.nu >= 0.0) c.poisson_ratio = o.nu;
  if (o.level >= 0) c.level = o.level;
  if (o.reference_level >= 0) c.reference_level = o.reference_level;
  c.regulariser = {o.smoothness, o.ridge, {}};
  c.max_iterations = o.iterations;
  if (!o.prior.empty()) {
    c.prior = read_calibration(o.prior);
    c.prior_source = o.prior;
  }
  c.cache_dir = o.cache.mesh_dir();
  const auto solution_cache = o.cache.solution_cache(std::cout);
  c.solution_cache = solution_cache.get();
  c.log = &std::cout;
  const CalibrationStudy study = calibrate_scene(s, c);
  write_calibration(o.output, study.calibration);
  const std::filesystem::path study_path = study_output(o);
  write_calibration_study(study_path, study, o.command, o.output.string());
  const std::string md = reports::calibration_markdown(reports::read_calibrate(study_path));
  std::cout << "\n" << md;
  if (!o.summary.empty()) {
    write_file_atomically(o.summary, [&](std::ostream& out) { out << md; });
  }
  std::cout << "\nwrote " << o.output.string() << ", " << study_path.string()
            << (o.summary.empty() ? "" : " and " + o.summary.string()) << "\n";
  std::cout << solution_cache->summary() << "\n";
}

}  // namespace

void add_calibrate_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<Options>();
  o->command = command_line;
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Fit a mass-spring model's stiffness to the FEM reference (P2) on the scene's training "
      "loads, by least squares on nodal displacements (the model linearised at rest, adjoint "
      "gradients, L-BFGS), and report its error on held-out loads (other magnitudes, other "
      "contact points, other load types, other vessels) beside P1 and the uncalibrated model. "
      "Writes a calibration file that a scene's model uses with calibration = \"file.json\".\n"
      "Examples:\n"
      "  vesselverify calibrate verification/scenes/contact_straight.toml --held-out-scene "
      "verification/scenes/contact_arch.toml\n"
      "  vesselverify calibrate SCENE --granularity per-spring --output per_spring.json");
  cmd->add_option("scene", o->scene, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model,
                  "The scene's mass-spring model to calibrate (default: its hybrid volume model, "
                  "else its first mass-spring model)");
  cmd->add_option("--granularity", o->granularity,
                  "groups: a factor per spring class (direction x boundary) and kappa; "
                  "wall-layers: a factor per spring class (direction x layer through the wall: "
                  "inner, middle, outer third) and a kappa per half of the wall; edge-types: the "
                  "same with the edge's type (the frame directions it spans, diagonals apart) "
                  "instead of its largest direction; per-section-spring: a factor per spring of "
                  "a cross-section, shared by its images along the centreline, and kappa (this "
                  "mesh only); "
                  "per-spring: a factor per spring and kappa (this mesh only); both with a "
                  "smoothness regulariser")
      ->check(CLI::IsMember({"groups", "wall-layers", "edge-types", "per-section-spring",
                             "per-spring"}))
      ->capture_default_str();
  cmd->add_option("--weights", o->weights,
                  "How the training loads weigh in the fit: equal (each load's squared relative "
                  "L2 error alike) or p1 (each divided by P1's squared error on that load: the "
                  "fit minimises the mean squared ratio to P1)")
      ->check(CLI::IsMember({"equal", "p1"}))
      ->capture_default_str();
  cmd->add_option("--gravity", o->gravity,
                  "Magnitude (g) of the gravity load cases, training or held out, on scenes whose "
                  "own load is not gravity")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--train", o->train,
                  "Load types fitted on (contact, pressure, gravity; default the scene's); the "
                  "others are held out")
      ->delimiter(',');
  cmd->add_option("--held-out-scene", o->held_out_scenes,
                  "Scenes whose loads are held-out cases on another vessel (not per-spring)")
      ->check(CLI::ExistingFile)
      ->delimiter(',');
  cmd->add_option("--nu", o->nu, "Poisson's ratio (default 0.45 if the scene has it, else its first)")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--level", o->level, "Model mesh level (default the scene's first)")
      ->check(CLI::Range(0, 4));
  cmd->add_option("--reference-level", o->reference_level,
                  "Level of the P2 reference (default the scene's)")
      ->check(CLI::Range(0, 4));
  cmd->add_option("--smoothness", o->smoothness,
                  "Per-spring: weight alpha of the smoothness regulariser (log k differences of "
                  "springs sharing a node)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--ridge", o->ridge, "Per-spring: weight beta of the ridge on log factors")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--prior", o->prior,
                  "Per-spring, per-section-spring: a class calibration file (groups, wall-layers, "
                  "edge-types) of the "
                  "same model and mesh to start from; the smoothness and the ridge then act on "
                  "each spring's departure from its factor (its kappa halves stay apart)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--iterations", o->iterations, "L-BFGS iterations at most")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--output", o->output, "Calibration file to write (JSON)")->capture_default_str();
  cmd->add_option("--study", o->study,
                  "The study's JSON document (the fit and every case's errors; schema "
                  "vesselverify.calibrate) (default: the --output file with .study.json)");
  cmd->add_option("--summary", o->summary,
                  "Also write the Markdown tables (rendered from the study's JSON) here");
  add_cache_options(*cmd, o->cache);
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
