/// `vesselverify contact`: the contact reference of a guidewire scene (the wire's surface against
/// the wall's, found by the solve) at one or more wire stiffnesses, the wall refined level by
/// level around the contact zone, with the force's Richardson extrapolate and GCI; and
/// `vesselverify insertion`: the scene's wire pushed into the vessel in steps against the
/// deformable wall (verification/harness/contact_insertion.hpp).
#include <filesystem>
#include <iostream>
#include <vector>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "reports/insertion_section.hpp"
#include "reports/study_files.hpp"
#include "reports/svg_plot.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/harness/contact_insertion.hpp"
#include "verification/harness/contact_reference.hpp"
#include "verification/scene.hpp"

namespace vessel::cli {

namespace {

struct ContactCli {
  std::filesystem::path scene;
  std::vector<double> ei;
  std::string wall = "linear";
  bool from_rest = false;
  ContactReferenceOptions options;
};

struct InsertionCli {
  std::filesystem::path scene;
  std::vector<double> ei;
  std::string wall = "neo-hookean";
  ContactInsertionOptions options;
  std::filesystem::path svg;   // empty: no figure
  std::filesystem::path json;  // empty: no document
  CacheOptions cache;
  std::vector<std::string> models{"reference"};
};

/// The options a guidewire scene's contact commands share: the scene, the stiffnesses and the wall.
void add_scene_stiffness_wall(CLI::App* cmd, std::filesystem::path& scene, std::vector<double>& ei,
                              std::string& wall) {
  cmd->add_option("scene", scene, "A scene file with a guidewire load")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--ei", ei,
                  "Wire bending stiffnesses EI, N·m², comma separated (default: the scene's "
                  "stiffness_sweep, or its wire's own EI)")
      ->delimiter(',');
  cmd->add_option("--wall", wall,
                  "The wall: linear (`contact`: condensed on the contact candidates, the "
                  "contact by the active set; `insertion`: with the wire as one potential, P1 "
                  "condensed on a band of contact candidates grown as the contact slides, P2 "
                  "whole with its mid-edge candidates) or neo-hookean (finite strain, the wire "
                  "and the wall as one potential)")
      ->check(CLI::IsMember({"linear", "neo-hookean"}))
      ->capture_default_str();
}

/// The stiffnesses asked for, or the scene's (contact_reference_stiffnesses).
std::vector<double> stiffnesses(const Scene& scene, const std::vector<double>& ei) {
  return ei.empty() ? contact_reference_stiffnesses(scene) : ei;
}

/// Solves (or reads from the cache) the insertions asked for, prints their tables and writes the
/// document and the figure asked for.
void run_insertion(InsertionCli& o, const std::string& command_line) {
  o.options.log = &std::cerr;  // progress; the tables go to stdout
  o.options.wall = parse_contact_wall(o.wall);
  const Scene scene = read_scene(o.scene);
  const auto cache = o.cache.outcome_cache(std::cerr);
  const std::string json =
      contact_insertion_document(scene, stiffnesses(scene, o.ei), o.options, command_line,
                                 cache.get(), insertion_walls(scene, o.models));
  // The tables and the figure from the document, as the report reads it.
  const reports::InsertionFile file = reports::parse_insertion(json, "insertion");
  std::cout << reports::insertion_markdown(file) << std::flush;
  if (!o.json.empty()) {
    write_file_atomically(o.json, [&](std::ostream& f) { f << json; });
    std::cout << "document: " << o.json.string() << "\n";
  }
  if (!o.svg.empty()) {
    write_file_atomically(
        o.svg, [&](std::ostream& f) { f << reports::render_svg(reports::insertion_plot(file)); });
    std::cout << "figure: " << o.svg.string() << "\n";
  }
}

}  // namespace

void add_contact_command(CLI::App& app) {
  auto o = std::make_shared<ContactCli>();
  CLI::App* cmd = app.add_subcommand(
      "contact",
      "The contact reference of a guidewire scene: its wire (DER) and its wall (linear or "
      "finite-strain neo-Hookean FEM) solved together, the contact between the wire's surface "
      "and the wall's found by the solve (Signorini's conditions), the wall refined level by "
      "level around the contact zone. "
      "Per level: the total contact force, the zone's centroid and extent, the dent, the largest "
      "strain, steps and time; then the force's Richardson extrapolate, observed order and GCI, "
      "and whether the answer is a reference (converged, the zone inside the refined patch, the "
      "GCI within its limit, and for the linear wall the strain within its validity).\n"
      "Example:\n"
      "  vesselverify contact verification/scenes/guidewire_straight.toml --ei 4e-7 "
      "--wall neo-hookean");
  add_scene_stiffness_wall(cmd, o->scene, o->ei, o->wall);
  cmd->add_option("--levels", o->options.levels, "Refinement levels")
      ->check(CLI::Range(1, 6))
      ->capture_default_str();
  cmd->add_option("--coarsest-size", o->options.coarsest_size,
                  "Element size around the contact zone at level 0, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--ratio", o->options.ratio, "Element size ratio between levels (> 1)")
      ->check(CLI::Range(1.01, 4.0))
      ->capture_default_str();
  cmd->add_option("--degree", o->options.degree, "The wall's element degree")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--strain-limit", o->options.strain_limit,
                  "The linear wall's validity: largest strain at most this")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--gci-limit", o->options.gci_limit,
                  "A reference's GCI on the force (relative) at most this; larger: not a "
                  "reference")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-steps", o->options.max_steps, "Linearised contact steps per solve")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--continuation-from", o->options.continuation_from,
                  "Neo-Hookean wall: a stiffer wire is reached by raising EI from this, N·m², "
                  "each rung solved from the last one's equilibrium")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--continuation-ratio", o->options.continuation_ratio,
                  "Neo-Hookean wall: the EI ratio between the continuation's rungs (> 1)")
      ->check(CLI::Range(1.01, 1e6))
      ->capture_default_str();
  cmd->add_flag("--from-rest", o->from_rest,
                "Neo-Hookean wall: every level climbs the EI rungs from the wall at rest, instead "
                "of starting from the level before's equilibrium");
  cmd->add_flag("--p1-start", o->options.p1_start,
                "With --wall neo-hookean and --degree 2: each level's P2 wall solved from P1's "
                "equilibrium on the same mesh (P1 climbs the EI rungs; a P1 factorisation takes a "
                "fortieth of P2's time), P2's own path where that fails");
  add_threads_option(*cmd, o->options.threads,
                     "Threads of the wall's factorisations (CHOLMOD's BLAS; default: the core "
                     "count)");
  cmd->callback([o] {
    o->options.log = &std::cerr;  // progress; the table goes to stdout
    o->options.wall = parse_contact_wall(o->wall);
    o->options.from_previous_solve = !o->from_rest;
    if (o->options.p1_start &&
        (o->options.wall != ContactWall::neo_hookean || o->options.degree != 2)) {
      throw InputError(
          "--p1-start: expected --wall neo-hookean and --degree 2 (a P2 "
          "finite-strain wall solved from P1's equilibrium)");
    }
    const Scene scene = read_scene(o->scene);
    for (const double EI : stiffnesses(scene, o->ei)) {
      print_contact_reference(solve_contact_reference(scene, EI, o->options), std::cout);
      std::cout << "\n" << std::flush;
    }
  });
}

void add_insertion_command(CLI::App& app, const std::string& command_line) {
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
      "--steps 8\n"
      "  vesselverify insertion verification/scenes/guidewire_straight.toml --ei 4e-7 "
      "--models reference,volume_hybrid --json insertion.json");
  add_scene_stiffness_wall(cmd, o->scene, o->ei, o->wall);
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
  cmd->add_option("--view-at", o->options.view_at,
                  "The report's 3D view shows the converged step nearest this insertion length, "
                  "m (0: the last converged step)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--svg", o->svg,
                  "Also write the forces against the insertion length as an SVG figure here");
  cmd->add_option("--json", o->json,
                  "Also write the insertion as a JSON document here (schema "
                  "verification/harness/contact_insertion.schema.json), which `vesselverify "
                  "report --insertion` draws as a section");
  cmd->add_option("--models", o->models,
                  "The walls pushed against, comma separated: reference (deal.II's FEM, as --wall "
                  "says) and any of the scene's models by name (its own wall on the same mesh, "
                  "at its own equilibrium); all: the reference and every scene model with a wall "
                  "in the contact")
      ->delimiter(',')
      ->capture_default_str();
  add_threads_option(*cmd, o->options.reference_threads,
                     "Threads of the reference wall's factorisations (CHOLMOD's BLAS; default: "
                     "the core count); a model's wall is solved on one thread, its times a "
                     "simulator's on one core");
  add_cache_options(*cmd, o->cache);
  cmd->add_flag("--retime", o->cache.retime,
                "Solve every insertion again (and replace its entry in the outcome cache) instead "
                "of reading the one a run of the same executable on this machine stored");
  cmd->callback([o, command_line] { run_insertion(*o, command_line); });
}

}  // namespace vessel::cli
