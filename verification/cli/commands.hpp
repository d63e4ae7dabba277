#pragma once
/// Subcommands of the vesselverify program. Each adds itself to the app; its callback throws
/// vessel::InputError for bad input, which main() reports with a non-zero exit.
#include <CLI/CLI.hpp>

namespace vessel::cli {

void add_mesh_command(CLI::App& app);
void add_scene_command(CLI::App& app);
/// `export`: a scene's exchange folders for models outside the suite (export_command.cpp).
void add_export_command(CLI::App& app);
/// `vesselverify run`; `command_line` is recorded in the results.
void add_run_command(CLI::App& app, const std::string& command_line);
/// `vesselverify reference`: scenes' references solved over MPI ranks into the FEM solution
/// cache (reference_command.cpp).
void add_reference_command(CLI::App& app);
/// `vesselverify report`: results → Markdown and HTML report; `command_line` is recorded in it.
void add_report_command(CLI::App& app, const std::string& command_line);
/// `vesselverify gate`: the CI gate against a committed baseline.
void add_gate_command(CLI::App& app, const std::string& command_line);
/// `vesselverify recommend`: the cheapest model meeting a scene's budget (recommend_command.cpp).
void add_recommend_command(CLI::App& app, const std::string& command_line);
/// `vesselverify msm`: run a mass-spring model on a vessel mesh under a contact load.
void add_msm_command(CLI::App& app);
/// `vesselverify fem`: the deal.II linear-elastic reference (fem_command.cpp).
void add_fem_command(CLI::App& app);
/// `vesselverify stability`: critical time steps and hard cases (stability_command.cpp).
void add_stability_command(CLI::App& app, const std::string& command_line);
/// `vesselverify calibrate`: stiffness fitted to the FEM, checked on held-out loads.
void add_calibrate_command(CLI::App& app, const std::string& command_line);
/// `vesselverify validity` (verification/cli/validity_command.cpp).
void add_validity_command(CLI::App& app, const std::string& command_line);
/// `vesselverify contact`: a guidewire scene's contact reference (contact_command.cpp).
void add_contact_command(CLI::App& app);
/// `vesselverify insertion`: a guidewire pushed into the vessel in steps against the deformable
/// wall (contact_command.cpp); `command_line` is recorded in its JSON document.
void add_insertion_command(CLI::App& app, const std::string& command_line);
/// `vesselverify contact-models`: every model's wall in the wire-wall contact
/// (contact_models_command.cpp).
void add_contact_models_command(CLI::App& app);

}  // namespace vessel::cli
