/// `vesselverify export`: writes the exchange folders of a scene's outside models (kinds external
/// and displacements) without running anything, for users who run their simulator by hand and
/// read its answers back with a `displacements` model (verification/harness/external_model.hpp).
#include <iostream>

#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/harness/external_model.hpp"
#include "verification/harness/harness.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::cli {

namespace {

struct ExportOptions {
  std::string scene;
  std::filesystem::path output_dir;
  CacheOptions cache;
  bool quick = false;
};

void export_scene(const ExportOptions& o) {
  Scene s = read_scene(o.scene);
  solve_guidewire_load(s);
  if (o.quick) s = quick_variant(std::move(s));
  std::cout << "exchange folders of " << s.name << " under " << o.output_dir.string() << ":\n";
  const std::size_t cases = export_exchange(s, o.cache.mesh_dir(), o.output_dir, &std::cout);
  std::cout << "wrote " << cases << " cases (manifest.json and problem.vtu each); a simulator "
            << "answers each with displacements.csv or displacements.vtu in the same folder\n";
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write the exchange folders of a scene's external and displacements models alone: one "
      "folder per model and case (nu, level, load), OUTPUT-DIR/<model>/<case>/ with "
      "manifest.json (schema vesselverify.exchange) and problem.vtu (nodes, cells, consistent "
      "nodal loads, fixed components, masses). Run your simulator on each, writing "
      "displacements.csv (node,ux,uy,uz in m) into the folder, then read them with a model "
      "kind = \"displacements\", file = \"OUTPUT-DIR/<model>\".\n"
      "Examples:\n"
      "  vesselverify export examples/external/python_model.toml --output-dir exchange\n"
      "  vesselverify export --quick my_scene.toml --output-dir exchange");
  cmd->add_option("scene", o->scene, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--output-dir", o->output_dir, "Where the case folders are written")->required();
  cmd->add_flag("--quick", o->quick,
                "The cases of `run --quick`: models at level 0, smallest and largest load");
  add_cache_options(*cmd, o->cache);
  cmd->callback([o] { export_scene(*o); });
}

}  // namespace vessel::cli
