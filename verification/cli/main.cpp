/// vesselverify: how wrong, and how fast, is a mass-spring vessel compared with continuum
/// mechanics? One program, one subcommand per stage.
#include <iostream>

#include "meshes/foundation/errors.hpp"
#include "verification/cli/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "vesselverify: verifies mass-spring vessel models against linear-elastic FEM.\n"
      "Lengths are in metres on the command line; printed results are in mm.\n"
      "Run 'vesselverify <command> --help' for a command's options."};
  app.require_subcommand(1);
  vessel::cli::add_mesh_command(app);
  vessel::cli::add_scene_command(app);
  std::string command_line;
  for (int i = 0; i < argc; ++i) command_line += (i ? " " : "") + std::string(argv[i]);
  vessel::cli::add_run_command(app, command_line);
  vessel::cli::add_reference_command(app);
  vessel::cli::add_report_command(app, command_line);
  vessel::cli::add_gate_command(app, command_line);
  vessel::cli::add_recommend_command(app, command_line);
  vessel::cli::add_msm_command(app);
  vessel::cli::add_fem_command(app);
  vessel::cli::add_stability_command(app, command_line);
  vessel::cli::add_calibrate_command(app, command_line);
  vessel::cli::add_validity_command(app, command_line);
  vessel::cli::add_contact_command(app);
  vessel::cli::add_insertion_command(app, command_line);
  vessel::cli::add_export_command(app);
  vessel::cli::add_contact_models_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;  // usage error
  } catch (const vessel::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
