/// `vesselverify insertion`: a guidewire scene's wire pushed into the vessel in steps against the
/// deformable wall (verification/harness/contact_insertion.hpp): per step the contact force, the
/// zones, the dent and the hub's forces.
#include <filesystem>
#include <iostream>

#include "verification/cli/commands.hpp"
#include "verification/harness/contact_insertion.hpp"
#include "verification/scene.hpp"

namespace vessel::cli {

namespace {

struct InsertionCli {
  std::filesystem::path scene;
  std::vector<double> ei;
  std::string wall = "neo-hookean";
  ContactInsertionOptions options;
};

}  // namespace

void add_insertion_command(CLI::App& app) {
  auto o = std::make_shared<InsertionCli>();
  CLI::App* cmd = app.add_subcommand(
      "insertion",
      "A guidewire scene's wire pushed into the vessel in steps, quasi-statically, against the "
      "deformable wall: at each insertion length the wire (DER) and the wall (finite-strain "
      "neo-Hookean or linear FEM) solved together from the last step's equilibrium, the "
      "contacts found by the solve. Per step: the total contact force, the contact zones, the "
      "dent, the clamp's axial force, the push that advances the wire (R·t − M²/2EI, and dΠ/dL "
      "from the steps' energies) and the tip.\n"
      "Example:\n"
      "  vesselverify insertion verification/scenes/guidewire_straight.toml --ei 4e-7 "
      "--steps 8");
  cmd->add_option("scene", o->scene, "A scene file with a guidewire load")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--ei", o->ei,
                  "Wire bending stiffnesses EI, N·m², comma separated (default: the scene's "
                  "stiffness_sweep, or its wire's own EI)")
      ->delimiter(',');
  cmd->add_option("--wall", o->wall, "The wall: neo-hookean (finite strain) or linear")
      ->check(CLI::IsMember({"linear", "neo-hookean"}))
      ->capture_default_str();
  cmd->add_option("--from", o->options.first, "The first insertion length, m (0: 80 % of the last)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--to", o->options.last, "The last insertion length, m (0: the scene's)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--steps", o->options.steps, "Steps from the first length to the last")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--fine-size", o->options.fine_size,
                  "The wall's element size where the wire may bear, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--refine-radius", o->options.refine_radius,
                  "The refined ball's radius around each rigid-lumen wall point, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--degree", o->options.degree, "The wall's element degree")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--max-steps", o->options.max_steps, "Newton steps per insertion step")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->callback([o] {
    o->options.log = &std::cerr;  // progress; the table goes to stdout
    o->options.wall = parse_contact_wall(o->wall);
    const Scene scene = read_scene(o->scene);
    const std::vector<double> ei = o->ei.empty() ? contact_reference_stiffnesses(scene) : o->ei;
    for (const double EI : ei) {
      print_contact_insertion(solve_contact_insertion(scene, EI, o->options), std::cout);
      std::cout << "\n" << std::flush;
    }
  });
}

}  // namespace vessel::cli
