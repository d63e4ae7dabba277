/// `vesselverify contact-models`: every vessel model's wall in the same wire–wall contact as the
/// FEM reference's (verification/contact_models/contact_models.hpp), one Markdown table per EI.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "meshes/vessel_geometry.hpp"
#include "reports/document.hpp"
#include "verification/cli/commands.hpp"
#include "verification/cli/jobs_option.hpp"
#include "verification/contact_models/contact_models.hpp"

namespace vessel::cli {

namespace {

struct ContactModelsCli {
  std::string scene;
  std::vector<double> ei;
  bool scene_models_only = false;
  std::vector<std::string> only;
  contact::ContactModelsOptions options;
};

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

/// The centroid's arc length along the vessel's centreline, mm (z on the straight tube).
std::string along(const VesselParams& vessel, const Vec3& centroid) {
  return fmt("%.3f", centreline_coordinates(vessel, centroid).s * 1e3);
}

/// `own_equilibrium`: the run solved every wall at its own equilibrium (the finite-strain
/// reference among them), so a dented-through linear wall is judged by the table's own reference.
void print_run(const contact::ContactModelsRun& run, const VesselParams& vessel,
               bool own_equilibrium) {
  const contact::ModelContact& ref = run.reference;
  std::cout << "\n### EI = " << fmt("%.3g", run.bending_stiffness) << " N·m²\n\n"
            << "Rigid lumen: " << fmt("%.4f", run.rigid_force * 1e3) << " mN. Reference ("
            << ref.name << ", " << ref.detail << "): ";
  if (!ref.failure.empty()) {
    std::cout << "FAILED: " << reports::markdown_cell(ref.failure) << "\n";
  } else {
    std::cout << fmt("%.4f", ref.force * 1e3) << " mN, " << ref.pressed << " pressed, dent "
              << fmt("%.4f", ref.dent * 1e3) << " mm, centroid at " << along(vessel, ref.centroid)
              << " mm along the centreline, " << ref.candidates << " candidates.\n";
  }
  constexpr int kColumns = 15;
  std::cout << "\n| model | wall | F (mN) | error (mN) | error (%) | pressed | centroid s (mm) "
               "| zone axial × circ. (mm) | dent (mm) | tip error (mm) | own imbalance "
               "| inverted tets | set-up (s) | solve (s) | steps |\n|";
  for (int c = 0; c < kColumns; ++c) std::cout << " --- |";
  std::cout << "\n";
  const auto row = [&](const contact::ModelContact& m) {
    std::cout << "| " << m.name << " | ";
    if (!m.failure.empty()) {
      std::cout << m.linearisation << " | failed: " << reports::markdown_cell(m.failure) << " |";
      for (int c = 3; c < kColumns; ++c) std::cout << " |";
      std::cout << "\n";
      return;
    }
    const bool judged = ref.failure.empty();
    std::cout << m.linearisation << " | " << fmt("%.4f", m.force * 1e3) << " | "
              << (judged ? fmt("%+.4f", (m.force - ref.force) * 1e3) : "n/a") << " | "
              << (judged ? fmt("%+.2f", 100 * (m.force / ref.force - 1)) : "n/a") << " | "
              << m.pressed << " | " << along(vessel, m.centroid) << " | "
              << fmt("%.3f", m.axial_extent * 1e3) << " × "
              << fmt("%.3f", m.circumferential_extent * 1e3) << " | " << fmt("%.4f", m.dent * 1e3)
              << " | " << (judged ? fmt("%.4f", (m.tip - ref.tip).norm() * 1e3) : "n/a") << " | "
              << fmt("%.1e", m.own_imbalance) << " | "
              << (m.inverted_tets ? std::to_string(*m.inverted_tets) : "—") << " | "
              << fmt("%.1f", m.setup_seconds) << " | " << fmt("%.1f", m.solve_seconds) << " | "
              << m.steps << " |\n";
  };
  row(ref);
  for (const contact::ModelContact& m : run.models) row(m);
  const std::string folded = contact::folded_walls(run);
  if (!folded.empty()) {
    std::cout << "\nInverted tets at the model's own equilibrium: " << folded
              << ". Such a wall has folded: its force is not an elastic wall's.\n";
  }
  const std::string through = contact::linear_walls_dented_through(run, vessel.wall_thickness);
  if (!through.empty()) {
    std::cout << "\nLinear walls dented deeper than the wall is thick ("
              << fmt("%.3g", vessel.wall_thickness * 1e3) << " mm): " << through
              << ". A linear wall there is far beyond its validity: judge this EI by the "
              << (own_equilibrium ? "finite-strain walls above.\n"
                                  : "finite-strain walls (--own-equilibrium).\n");
  }
}

}  // namespace

void add_contact_models_command(CLI::App& app) {
  auto o = std::make_shared<ContactModelsCli>();
  CLI::App* cmd = app.add_subcommand(
      "contact-models",
      "Every vessel model in the same wire-wall contact: the guidewire scene's wire (DER) "
      "against each model's wall linearised at rest (its stiffness, the scene's supports held), "
      "the contact between the wire's surface and the inner wall found by the solve (Signorini), "
      "on one mesh refined around the rigid wire's contact; each model's contact force against "
      "the FEM reference's on the same mesh. Prints a Markdown table per EI (forces in mN, "
      "lengths in mm).\n"
      "Example:\n  vesselverify contact-models verification/scenes/guidewire_straight.toml "
      "--ei 4e-7");
  cmd->add_option("scene", o->scene, "A guidewire scene (the straight tube or the arch)")
      ->required();
  cmd->add_option("--ei", o->ei,
                  "Bending stiffness of the wire, N*m^2 (repeatable; default: the scene wire's)");
  cmd->add_flag("--scene-models-only", o->scene_models_only,
                "Only the scene's own models (default: also one of each model kind it lacks)");
  cmd->add_option("--model", o->only, "Only this model (repeatable; by name)");
  cmd->add_option("--fine-size", o->options.fine_size, "Element size near the rigid contact, m")
      ->capture_default_str();
  cmd->add_option("--fine-radius", o->options.fine_radius,
                  "Radius of the refined patch around the rigid contact, m")
      ->capture_default_str();
  cmd->add_option(
         "--bearing-band-size", o->options.bearing_band_size,
         "Element size along the band the wire may bear on (its rigid-lumen shape and "
         "the straight wire along its clamp, where near the wall), m; 0: not refined there")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--band-radius", o->options.band_radius,
                  "First contact candidates: inner-wall nodes this near the rigid contact, m "
                  "(grown while the contact reaches the band's edge)")
      ->capture_default_str();
  cmd->add_option("--max-move", o->options.max_move,
                  "Each contact step moves no wire or wall node by more than this times the "
                  "wire's radius")
      ->capture_default_str();
  cmd->add_option("--reference-degree", o->options.reference_degree,
                  "Degree of the reference FEM wall (deal.II)")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_flag("--active-set", o->options.active_set,
                "Every wall linearised at rest, its contact solved by the active set on the wall "
                "condensed on a growing band (the second formulation) instead of with the wire as "
                "one potential (an energy line search, a wire through the wall refused); it loses "
                "contacts the potential holds");
  cmd->add_flag("--own-equilibrium", o->options.own_equilibrium,
                "Each model at its own nonlinear equilibrium (its own energy) and the reference at "
                "finite strain (neo-Hookean FEM), the wire and each wall solved as one potential; "
                "default: every wall linearised at rest");
  add_threads_option(*cmd, o->options.reference_threads,
                     "Threads of the reference wall's factorisations (CHOLMOD's BLAS; default: "
                     "the core count); the models' walls are solved on one thread, their times "
                     "comparable");
  cmd->add_flag(
      "--p1-start", [o](std::int64_t) { o->options.p2_from_p1 = true; },
      "With --own-equilibrium and the P2 reference: P2 solved from P1's equilibrium on the same "
      "mesh (a P1 factorisation takes a fortieth of P2's time; it pays in the arch) instead of "
      "alone");
  cmd->add_flag(
      "--from-rest", [o](std::int64_t) { o->options.from_softer_wire = false; },
      "With --own-equilibrium: every EI solved from the wall at rest, instead of from the wall's "
      "equilibrium under the softer wire before it (in EI rungs a factor sqrt(10) apart)");
  cmd->callback([o] {
    const Scene scene = read_scene(o->scene);
    std::vector<ModelSpec> models =
        o->scene_models_only ? scene.models : contact::contact_model_kinds(scene);
    if (!o->only.empty()) {
      std::vector<ModelSpec> chosen;
      for (const std::string& name : o->only) {
        const auto it = std::find_if(models.begin(), models.end(),
                                     [&](const ModelSpec& m) { return m.name == name; });
        if (it == models.end()) {
          throw InputError("--model " + name + ": no such model among the " +
                           std::to_string(models.size()) + " of " + o->scene);
        }
        chosen.push_back(*it);
      }
      models = chosen;
    }
    o->options.bending_stiffness = o->ei;
    o->options.log = &std::cerr;  // progress: a wall at its own equilibrium takes minutes
    const contact::ContactModels result = contact::solve_contact_models(scene, models, o->options);
    std::cout << "Scene " << scene.name << ": nu = " << result.nu << ", mesh " << result.mesh_nodes
              << " nodes, " << result.mesh_tets << " tets (refined to "
              << o->options.fine_size * 1e3 << " mm within " << o->options.fine_radius * 1e3
              << " mm of the rigid contact";
    if (o->options.bearing_band_size > 0.0) {
      std::cout << ", to " << o->options.bearing_band_size * 1e3
                << " mm along the band the wire may bear on";
    }
    std::cout << ").\n";
    for (const contact::ContactModelsRun& run : result.runs)
      print_run(run, scene.vessel, o->options.own_equilibrium);
  });
}

}  // namespace vessel::cli
