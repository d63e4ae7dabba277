/// `vesselverify report`: results.json (+ stability.json, recommend.json) → report.md,
/// report.html, figures/.
#include <iostream>

#include "reports/report.hpp"
#include "verification/cli/commands.hpp"

namespace vessel::cli {

void add_report_command(CLI::App& app, const std::string& command_line) {
  auto o = std::make_shared<reports::ReportOptions>();
  o->command = command_line;
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Turn results into a report: report.md (figures as .svg files under figures/) and "
      "report.html (one file, no network: a card per scene with the recommended and the best "
      "mass-spring model, each scene's models in 3D coloured by their error, read from the "
      "run's fields/ beside results.json, and interactive plots; Debian's three.js and Chart.js "
      "inlined, else the SVG figures): a summary table, and per scene speed "
      "against error with the Pareto front, error against nu and against mesh level, load "
      "against contact displacement beside the FEM and seed 000's Hooke line, the radial "
      "displacement along the wall, dynamic histories, and seed 000's statistics for every "
      "model; plus the numerical-stability and model-recommendation sections, drawn from the "
      "studies' JSON files, when given.\n"
      "Examples:\n"
      "  vesselverify report results/results.json\n"
      "  vesselverify report results/results.json --stability results/stability.json -o report\n"
      "  vesselverify report rec/results.json --recommend rec/recommend.json");
  cmd->add_option("results", o->results, "results.json written by `vesselverify run`")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--stability", o->stability,
                  "stability.json written by `vesselverify stability`, drawn as a section")
      ->check(CLI::ExistingFile);
  cmd->add_option("--recommend", o->recommend,
                  "recommend.json written by `vesselverify recommend`, drawn as a section "
                  "(repeatable; the results.json beside it names the load unit and reference)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--validity", o->validity,
                  "validity.json written by `vesselverify validity`: the linear reference's "
                  "limit and the models against the finite-strain reference, drawn as a section")
      ->check(CLI::ExistingFile);
  cmd->add_option("--insertion", o->insertion,
                  "the JSON of `vesselverify insertion --json`: the guidewire pushed in, its "
                  "forces per step as tables and curves, drawn as a section")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output-dir", o->output_dir,
                  "Where report.md, report.html and figures/ go (default: beside the results)");
  cmd->callback([o] {
    if (o->output_dir.empty()) o->output_dir = o->results.parent_path();
    if (o->output_dir.empty()) o->output_dir = ".";
    reports::write_report(*o);
    std::cout << "wrote " << (o->output_dir / "report.md").string() << " and report.html\n";
  });
}

}  // namespace vessel::cli
