/// `vesselverify scene`: validate scene files and print what they would run.
#include <iostream>

#include "meshes/lumen_mesh.hpp"
#include "verification/cli/commands.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/scene.hpp"
#include "verification/scene_keys.hpp"

namespace vessel::cli {

namespace {

void print_scene(const Scene& s) {
  std::cout << s.source.string() << ": scene '" << s.name << "' is valid\n";
  if (!s.description.empty()) std::cout << "  " << s.description << "\n";
  std::cout << "  vessel: " << describe(s.vessel) << "; reference level " << s.reference_level
            << "\n";
  if (s.vessel.kind == VesselKind::lumen) {
    const auto ends = lumen_file_ends(s.vessel.file, s.vessel.file_scale, s.vessel.listed_ends);
    std::cout << "  ends of the lumen: " << ends.size() << "\n";
    for (const auto& [group, e] : ends) {
      std::cout << "    " << group << ": " << format_end(e) << "\n";
    }
  }
  std::cout << "  material: E = " << s.youngs_modulus << " Pa, ν =";
  for (double nu : s.poisson_ratios) std::cout << " " << nu;
  std::cout << ", ρ = " << s.density << " kg/m³\n  boundary:";
  for (const auto& [group, bc] : s.boundary) std::cout << " " << group << "=" << to_string(bc);
  if (s.load.guidewire) {
    std::cout << "\n  load: contact on the inner wall, its force and point the guidewire's\n"
              << "  guidewire: " << describe_guidewire_solve(*s.load.guidewire);
  } else {
    std::cout << "\n  load: " << to_string(s.load.kind) << ", " << s.load.magnitudes.size()
              << " magnitude(s)";
  }
  std::cout << "\n  models:";
  for (const auto& m : s.models) std::cout << " " << m.name << " (" << to_string(m.kind) << ")";
  std::cout << "\n";
}

}  // namespace

void add_scene_command(CLI::App& app) {
  auto files = std::make_shared<std::vector<std::string>>();
  auto schema = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "scene",
      "Validate scene files (TOML) and print what each would run (nothing is solved or run: a "
      "guidewire's solve, or its external program, is left to `run`). Unknown keys, wrong types and "
      "out-of-range values are reported with file, line and key. --schema prints every key "
      "(type, default, unit, range, meaning) as JSON Schema; docs/scene_reference.md is made "
      "from it.\n"
      "Examples:\n  vesselverify scene verification/scenes/*.toml\n  vesselverify scene --schema");
  cmd->add_option("files", *files, "Scene files");
  cmd->add_flag("--schema", *schema, "Print the scene files' JSON Schema and exit");
  cmd->callback([files, schema] {
    if (*schema) {
      std::cout << scene_json_schema();
      return;
    }
    if (files->empty()) throw CLI::RequiredError("files (or --schema)");
    for (const auto& f : *files) print_scene(read_scene(f));
  });
}

}  // namespace vessel::cli
