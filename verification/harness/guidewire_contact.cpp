#include "verification/harness/guidewire_contact.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>

#include "meshes/foundation/content_hash.hpp"
#include "reports/document.hpp"
#include "verification/harness/guidewire_coupling.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/harness/parallel.hpp"

namespace vessel {

namespace {

using nlohmann::json;

json vec_json(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
Vec3 vec_of(const json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

/// One wall's contact as the cache keeps it (SI units).
json wall_json(const contact::ModelContact& m) {
  return {{"name", m.name},
          {"detail", m.detail},
          {"linearisation", m.linearisation},
          {"failure", m.failure},
          {"force", m.force},
          {"force_on_wall", vec_json(m.force_on_wall)},
          {"pressed", m.pressed},
          {"candidates", m.candidates},
          {"rounds", m.rounds},
          {"centroid", vec_json(m.centroid)},
          {"axial_extent", m.axial_extent},
          {"circumferential_extent", m.circumferential_extent},
          {"dent", m.dent},
          {"strain", m.strain},
          {"inverted_tets", m.inverted_tets ? json(*m.inverted_tets) : json()},
          {"tip", vec_json(m.tip)},
          {"own_imbalance", m.own_imbalance},
          {"steps", m.steps},
          {"setup_seconds", m.setup_seconds},
          {"solve_seconds", m.solve_seconds}};
}

/// j[key] as a number; NaN where it is null (a NaN, e.g. the strain of a wall without tets, is
/// written as null).
double number(const json& j, const char* key) {
  const json& v = j.at(key);
  return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>();
}

contact::ModelContact wall_of(const json& j) {
  contact::ModelContact m;
  m.name = j.at("name");
  m.detail = j.at("detail");
  m.linearisation = j.at("linearisation");
  m.failure = j.at("failure");
  m.force = number(j, "force");
  m.force_on_wall = vec_of(j.at("force_on_wall"));
  m.pressed = j.at("pressed");
  m.candidates = j.at("candidates");
  m.rounds = j.at("rounds");
  m.centroid = vec_of(j.at("centroid"));
  m.axial_extent = number(j, "axial_extent");
  m.circumferential_extent = number(j, "circumferential_extent");
  m.dent = number(j, "dent");
  m.strain = number(j, "strain");
  if (!j.at("inverted_tets").is_null()) m.inverted_tets = j.at("inverted_tets").get<std::size_t>();
  m.tip = vec_of(j.at("tip"));
  m.own_imbalance = number(j, "own_imbalance");
  m.steps = j.at("steps");
  m.setup_seconds = number(j, "setup_seconds");
  m.solve_seconds = number(j, "solve_seconds");
  return m;
}

std::string serialise(const contact::ContactModels& s) {
  json runs = json::array();
  for (const contact::ContactModelsRun& r : s.runs) {
    json walls = json::array();
    for (const contact::ModelContact& m : r.models) walls.push_back(wall_json(m));
    runs.push_back({{"bending_stiffness", r.bending_stiffness},
                    {"rigid_force", r.rigid_force},
                    {"rigid_wall_point", vec_json(r.rigid_wall_point)},
                    {"reference", wall_json(r.reference)},
                    {"models", walls}});
  }
  return json{
      {"mesh_nodes", s.mesh_nodes}, {"mesh_tets", s.mesh_tets}, {"nu", s.nu}, {"runs", runs}}
      .dump();
}

contact::ContactModels deserialise(const std::string& bytes) {
  const json j = json::parse(bytes);
  contact::ContactModels s;
  s.mesh_nodes = j.at("mesh_nodes");
  s.mesh_tets = j.at("mesh_tets");
  s.nu = j.at("nu");
  for (const json& r : j.at("runs")) {
    contact::ContactModelsRun run;
    run.bending_stiffness = r.at("bending_stiffness");
    run.rigid_force = r.at("rigid_force");
    run.rigid_wall_point = vec_of(r.at("rigid_wall_point"));
    run.reference = wall_of(r.at("reference"));
    for (const json& m : r.at("models")) run.models.push_back(wall_of(m));
    s.runs.push_back(std::move(run));
  }
  return s;
}

/// The outcome cache's key: the scene file's bytes (its wire, vessel, material and models), the
/// stiffnesses and the solve's options (OutcomeCache adds the code and the machine).
std::string contact_key(const Scene& scene, const std::vector<std::string>& models,
                        const contact::ContactModelsOptions& o) {
  ContentHash h;
  h.text(file_contents(scene.source));
  for (const double EI : o.bending_stiffness) h.real(EI);
  for (const std::string& m : models) h.text(m);
  h.real(o.fine_size).real(o.fine_radius).real(o.bearing_band_size).real(o.band_radius);
  h.integer(o.reference_degree);
  h.integer(o.max_newton).real(o.max_move).integer(o.own_equilibrium ? 1 : 0);
  h.integer(o.active_set ? 0 : 1);  // the formulation: 1 the potential, 0 the active set
  h.integer(o.from_softer_wire ? 1 : 0);
  return "guidewire-contact " + h.hex();
}

bool same_stiffness(double a, double b) { return std::abs(a / b - 1.0) <= 1e-6; }

/// The shortcuts at one run's EI: the rigid lumen's force and the series springs' (the reference's
/// wall once per level, then each model's) at the contact's ν.
std::vector<GuidewireShortcut> shortcuts_at(const contact::ContactModelsRun& run, double nu,
                                            const GuidewireOutcome& coupled) {
  std::vector<GuidewireShortcut> out{{"rigid lumen", run.rigid_force}};
  std::vector<int> reference_levels;
  for (const GuidewireCouplingRow& r : coupled.rows) {
    if (!r.ok || !same_stiffness(r.bending_stiffness, run.bending_stiffness) ||
        std::abs(r.poisson_ratio - nu) > 1e-12) {
      continue;
    }
    const std::string level = " (level " + std::to_string(r.level) + ")";
    if (std::find(reference_levels.begin(), reference_levels.end(), r.level) ==
        reference_levels.end()) {
      reference_levels.push_back(r.level);
      out.push_back({"series springs, reference's wall" + level, r.reference_force_mN * 1e-3});
    }
    out.push_back({"series springs, " + r.model + level, r.force_mN * 1e-3});
  }
  return out;
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

json mm(const Vec3& v) { return vec_json(1e3 * v); }

/// results.json's row of one wall at one EI (mm and mN; errors against `reference`).
json wall_row(const contact::ModelContact& m, const contact::ModelContact& reference) {
  const bool ok = m.failure.empty();
  const bool judged = ok && reference.failure.empty() && reference.force > 0.0;
  json row{{"model", m.name}, {"wall", m.linearisation}, {"detail", m.detail}, {"ok", ok}};
  if (!ok) {
    row["failure"] = m.failure;
    return row;
  }
  row.update(
      {{"force_mN", m.force * 1e3},
       {"force_error_mN", judged ? json((m.force - reference.force) * 1e3) : json()},
       {"force_error_percent", judged ? json(100.0 * (m.force / reference.force - 1.0)) : json()},
       {"pressed", m.pressed},
       {"candidates", m.candidates},
       {"centroid_mm", mm(m.centroid)},
       {"axial_extent_mm", m.axial_extent * 1e3},
       {"circumferential_extent_mm", m.circumferential_extent * 1e3},
       {"dent_mm", m.dent * 1e3},
       {"largest_strain", m.strain},
       {"inverted_tets", m.inverted_tets ? json(*m.inverted_tets) : json()},
       {"tip_mm", mm(m.tip)},
       {"tip_error_mm", judged ? json((m.tip - reference.tip).norm() * 1e3) : json()},
       {"setup_seconds", m.setup_seconds},
       {"solve_seconds", m.solve_seconds},
       {"steps", m.steps}});
  return row;
}

/// The EIs of the contact coupling: the wire's own first, then its stiffness_sweep's (the wire's
/// own alone in the quick variant).
std::vector<double> contact_stiffnesses(const GuidewireSpec& spec) {
  std::vector<double> out = guidewire_stiffnesses(spec);
  if (spec.contact_at_own_stiffness_only) out.resize(1);
  return out;
}

/// Why the contact at EI is not solved, or empty: a linear wall dented deeper than it is thick
/// cannot hold the wire (its solve stops with the wire through the wall, after minutes), and the
/// series springs of the reference's wall (C_ref·F_ref) say beforehand whether it will be.
std::string beyond_the_linear_wall(const Scene& scene, const GuidewireOutcome& coupled, double EI) {
  for (const GuidewireRigid& r : coupled.rigid) {
    if (!same_stiffness(r.bending_stiffness, EI)) continue;
    if (reference_within_wall(r, scene.vessel.wall_thickness)) return {};
    const double dent = r.reference_compliance * r.reference_force;
    return "not solved: the series springs put the reference's wall " + fmt("%.2f", dent * 1e3) +
           " mm in under " + fmt("%.3f", r.reference_force * 1e3) +
           " mN, deeper than the wall is thick (" + fmt("%.2f", scene.vessel.wall_thickness * 1e3) +
           " mm): a linear wall cannot hold the wire there (the finite-strain reference can: "
           "contact_wall = \"neo-hookean\" in the scene, or vesselverify contact-models "
           "--own-equilibrium)";
  }
  return {};
}

/// A run at EI that was not solved, for `why`.
contact::ContactModelsRun unsolved_run(const GuidewireOutcome& coupled, double EI, int degree,
                                       const std::string& why) {
  contact::ContactModelsRun run;
  run.bending_stiffness = EI;
  for (const GuidewireRigid& r : coupled.rigid) {
    if (!same_stiffness(r.bending_stiffness, EI)) continue;
    run.rigid_force = r.solution.force;
    run.rigid_wall_point = r.solution.wall_point;
  }
  run.reference.name = "reference_fem_p" + std::to_string(degree);
  run.reference.failure = why;
  return run;
}

/// Why the contact at EI is not solved with the scene's walls, or empty: only a linear wall has
/// EIs it cannot hold.
std::string not_solved(const Scene& scene, const GuidewireOutcome& coupled, double EI) {
  if (scene.load.guidewire->contact_wall == ContactWall::neo_hookean) return {};
  return beyond_the_linear_wall(scene, coupled, EI);
}

}  // namespace

contact::ContactModelsOptions guidewire_contact_options(const Scene& scene,
                                                        const GuidewireOutcome& coupled,
                                                        const HarnessOptions& options) {
  const GuidewireSpec& spec = *scene.load.guidewire;
  contact::ContactModelsOptions o;
  for (const double EI : contact_stiffnesses(spec)) {
    if (not_solved(scene, coupled, EI).empty()) o.bending_stiffness.push_back(EI);
  }
  o.fine_size =
      options.contact_fine_size > 0.0 ? options.contact_fine_size : spec.contact_fine_size;
  o.fine_radius = spec.contact_fine_radius;
  o.own_equilibrium = spec.contact_wall == ContactWall::neo_hookean;
  o.p2_from_p1 = spec.contact_p1_start;
  // The solve runs alone, after the models' runs: the reference wall's factorisations get every
  // core (the models' stay on one, their times a simulator's).
  o.reference_threads = machine_cores();
  // A linear wall's run solves only the EIs whose dent stays within the wall's thickness, where
  // the wire bears near its rigid contact: the band along its body is refined at finite strain
  // alone (on the straight scene at EI 4e-7 it more than doubles the solve and moves no force).
  if (!o.own_equilibrium) o.bearing_band_size = 0.0;
  return o;
}

std::optional<double> worst_contact_force_error_mN(const GuidewireContact& contact,
                                                   const std::string& model, std::string& why) {
  if (contact.solve.runs.empty()) {
    why = "the wire-wall contact solve has no EI";
    return std::nullopt;
  }
  double worst = 0.0;
  for (const contact::ContactModelsRun& run : contact.solve.runs) {
    const std::string at = " at EI " + reports::significant(run.bending_stiffness) + " N·m²";
    const auto row = std::find_if(run.models.begin(), run.models.end(),
                                  [&](const contact::ModelContact& m) { return m.name == model; });
    if (row == run.models.end()) {
      why =
          "it has no wall in the wire-wall contact solve (a network, an external program or a "
          "surface model on the outer wall)";
    } else if (!run.reference.failure.empty()) {
      why = "the contact reference failed" + at + ": " + run.reference.failure;
    } else if (contact.beyond_its_reference(run)) {
      why = "the linear contact reference is strained beyond its validity" + at +
            " (contact_wall = \"neo-hookean\" judges that regime)";
    } else if (!row->failure.empty()) {
      why = "its contact solve failed" + at + ": " + row->failure;
    } else {
      worst = std::max(worst, std::abs(row->force - run.reference.force) * 1e3);
      continue;
    }
    return std::nullopt;
  }
  return worst;
}

GuidewireContact solve_guidewire_contact(const Scene& scene, const GuidewireOutcome& coupled,
                                         const HarnessOptions& options) {
  GuidewireContact c;
  c.wall = scene.load.guidewire->contact_wall;
  c.options = guidewire_contact_options(scene, coupled, options);
  std::vector<ModelSpec> walls;
  std::vector<std::string> names;
  for (const ModelSpec& m : scene.models) {
    if (!contact::has_contact_wall(m)) continue;
    walls.push_back(m);
    names.push_back(m.name);
  }
  contact::ContactModelsOptions o = c.options;
  o.log = options.log;
  const auto solve = [&] {
    if (options.log) {
      *options.log << scene.name << ": the wire-wall contact, the reference and " << walls.size()
                   << " model walls"
                   << (o.own_equilibrium ? " at finite strain (each at its own equilibrium)" : "")
                   << " at " << o.bending_stiffness.size()
                   << " bending stiffnesses (a contact solve each; minutes)" << std::endl;
    }
    return serialise(contact::solve_contact_models(scene, walls, o));
  };
  if (c.options.bending_stiffness.empty()) {
    c.solve.nu = scene.poisson_ratios.front();
  } else if (options.outcome_cache && options.outcome_cache->enabled()) {
    c.solve = deserialise(
        options.outcome_cache->get(contact_key(scene, names, c.options), solve, c.provenance));
  } else {
    c.solve = deserialise(solve());
  }
  // Every EI in the scene's order, those not solved with their reason.
  std::vector<contact::ContactModelsRun> runs;
  std::size_t solved = 0;
  for (const double EI : contact_stiffnesses(*scene.load.guidewire)) {
    const std::string why = not_solved(scene, coupled, EI);
    runs.push_back(why.empty() ? c.solve.runs.at(solved++)
                               : unsolved_run(coupled, EI, c.options.reference_degree, why));
  }
  c.solve.runs = std::move(runs);
  for (const contact::ContactModelsRun& run : c.solve.runs) {
    c.shortcuts.push_back(shortcuts_at(run, c.solve.nu, coupled));
  }
  return c;
}

json guidewire_contact_json(const GuidewireContact& c) {
  json runs = json::array();
  for (std::size_t k = 0; k < c.solve.runs.size(); ++k) {
    const contact::ContactModelsRun& run = c.solve.runs[k];
    const contact::ModelContact& ref = run.reference;
    json models = json::array();
    for (const contact::ModelContact& m : run.models) models.push_back(wall_row(m, ref));
    json shortcuts = json::array();
    for (const GuidewireShortcut& s : c.shortcuts[k]) {
      const bool judged = ref.failure.empty() && ref.force > 0.0;
      shortcuts.push_back(
          {{"name", s.name},
           {"force_mN", s.force * 1e3},
           {"force_error_percent", judged ? json(100.0 * (s.force / ref.force - 1.0)) : json()}});
    }
    runs.push_back({{"bending_stiffness_Nm2", run.bending_stiffness},
                    {"rigid_force_mN", run.rigid_force * 1e3},
                    {"rigid_wall_point_mm", mm(run.rigid_wall_point)},
                    {"within_linear_validity", c.within_linear_validity(run)},
                    {"reference", wall_row(ref, ref)},
                    {"models", models},
                    {"shortcuts", shortcuts}});
  }
  json out{{"poisson_ratio", c.solve.nu},
           {"mesh_nodes", c.solve.mesh_nodes},
           {"mesh_tets", c.solve.mesh_tets},
           {"fine_size_mm", c.options.fine_size * 1e3},
           {"fine_radius_mm", c.options.fine_radius * 1e3},
           {"wall", to_string(c.wall)},
           {"reference_degree", c.options.reference_degree},
           {"strain_limit", c.strain_limit},
           {"runs", runs}};
  if (c.provenance.cached) out["cached_from"] = c.provenance.measured_at;
  return out;
}

void write_guidewire_contact_markdown(std::ostream& out, const GuidewireContact& c) {
  out << "Contact (coupling = \"contact\"): the wire's surface against each wall "
      << (c.wall == ContactWall::neo_hookean
              ? "at its own nonlinear equilibrium (the reference the neo-Hookean FEM wall)"
              : "linearised at rest")
      << ", the contact found by the solve, on one mesh of " << c.solve.mesh_nodes
      << " nodes refined to " << c.options.fine_size * 1e3 << " mm within "
      << c.options.fine_radius * 1e3 << " mm of the rigid wire's contact"
      << (c.options.bearing_band_size > 0.0
              ? " and to " + reports::significant(c.options.bearing_band_size * 1e3) +
                    " mm along the band it may bear on"
              : std::string())
      << " (ν = " << c.solve.nu << "); each force against the FEM P" << c.options.reference_degree
      << " wall's in the same solve"
      << (c.provenance.cached ? "; solved " + c.provenance.measured_at + ", from the cache" : "")
      << ".\n\n";
  for (std::size_t k = 0; k < c.solve.runs.size(); ++k) {
    const contact::ContactModelsRun& run = c.solve.runs[k];
    const contact::ModelContact& ref = run.reference;
    out << "EI " << run.bending_stiffness << " N·m²: reference ";
    if (!ref.failure.empty()) {
      out << "FAILED (" << ref.failure << "): no model is judged.\n\n";
      continue;
    }
    out << fmt("%.4f", ref.force * 1e3) << " mN (rigid lumen " << fmt("%.4f", run.rigid_force * 1e3)
        << " mN), dent " << fmt("%.4f", ref.dent * 1e3) << " mm, largest strain "
        << fmt("%.3f", ref.strain);
    if (c.beyond_its_reference(run)) {
      out << " ⚠ beyond the linear reference's validity (strain > " << c.strain_limit
          << "): the rows show the regime, not a prediction (the finite-strain reference: "
             "`vesselverify contact-models --own-equilibrium`)";
    }
    out << ".\n\n| model | F mN | error % | pressed | zone along × around mm | dent mm | tip "
           "error mm | set-up s | solve s |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const contact::ModelContact& m : run.models) {
      if (!m.failure.empty()) {
        out << "| " << m.name << " | failed: " << reports::markdown_cell(m.failure)
            << " | | | | | | | |\n";
        continue;
      }
      out << "| " << m.name << " | " << fmt("%.4f", m.force * 1e3) << " | "
          << fmt("%+.2f", 100.0 * (m.force / ref.force - 1.0)) << " | " << m.pressed << " | "
          << fmt("%.3f", m.axial_extent * 1e3) << " × "
          << fmt("%.3f", m.circumferential_extent * 1e3) << " | " << fmt("%.4f", m.dent * 1e3)
          << " | " << fmt("%.4f", (m.tip - ref.tip).norm() * 1e3) << " | "
          << fmt("%.2f", m.setup_seconds) << " | " << fmt("%.2f", m.solve_seconds) << " |\n";
    }
    out << "\n| shortcut | F mN | error % |\n|---|---|---|\n";
    for (const GuidewireShortcut& s : c.shortcuts[k]) {
      out << "| " << s.name << " | " << fmt("%.4f", s.force * 1e3) << " | "
          << fmt("%+.2f", 100.0 * (s.force / ref.force - 1.0)) << " |\n";
    }
    out << "\n";
  }
}

}  // namespace vessel
