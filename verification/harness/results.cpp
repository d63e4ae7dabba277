#include "verification/harness/results.hpp"

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/harness/guidewire_contact.hpp"
#include "verification/harness/guidewire_coupling.hpp"
#include "verification/harness/harness.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

namespace {

/// The unit of a scene's load magnitudes: N (contact), Pa (pressure), g (gravity, in g).
/// The Richardson/GCI order per reference: the linear one's (observed or assumed), and the
/// finite-strain one's where the scene uses it (no coarser finite-strain level is solved).
nlohmann::json uncertainty_order_json(const Scene& s, const ReferenceInfo& ref) {
  nlohmann::json linear{{"source", ref.gci_order_source}, {"note", ref.gci_note}};
  if (ref.gci_order_source != "none") {
    linear["order"] = ref.gci_order;
    linear["safety_factor"] = ref.gci_safety_factor;
  } else {
    linear["note"] = "no coarser reference level: no Richardson estimate";
  }
  nlohmann::json finite = nullptr;
  if (s.reference != ReferenceChoice::linear) {
    finite = {{"source", "none"},
              {"note", "the finite-strain reference is solved on the fine level only: no "
                       "Richardson estimate"}};
  }
  return {{"linear", linear}, {"finite_strain", finite}};
}

const char* load_unit(LoadKind k) {
  return k == LoadKind::contact ? "N" : (k == LoadKind::pressure ? "Pa" : "g");
}

std::string host_name() {
  char buf[256] = {};
  gethostname(buf, sizeof buf - 1);
  return buf;
}

nlohmann::json error_json(const ErrorStatistics& e) {
  return {{"max_mm", e.max_mm},     {"mean_mm", e.mean_mm},         {"stddev_mm", e.stddev_mm},
          {"rms_mm", e.rms_mm},     {"relative_l2", e.relative_l2}, {"points", e.points}};
}

/// A number, or null where it is not finite (JSON has no infinity) or not computable.
nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }
nlohmann::json number_or_null(const std::optional<double>& v) {
  return v ? number_or_null(*v) : nlohmann::json(nullptr);
}

nlohmann::json budget_json(const Budget& b) {
  nlohmann::json j{{"quantity", to_string(b.quantity)},
                   {"unit", budget_unit(b.quantity)},
                   {"tolerance", b.tolerance},
                   {"rate_hz", number_or_null(b.rate_hz > 0.0 ? b.rate_hz : NAN)},
                   {"seconds_per_update", b.seconds_per_update()},
                   {"update_period_s", b.update_period()},
                   {"magnitude", number_or_null(b.magnitude > 0.0 ? b.magnitude : NAN)}};
  if (b.quantity == BudgetQuantity::patch) j["radius_mm"] = b.radius * 1e3;
  return j;
}

/// The modal reference at ν, or nullptr.
const ModalOutcome* reference_modes_at(const SceneResult& r, double nu) {
  for (const auto& m : r.reference_modes) {
    if (m.poisson_ratio == nu) return &m;
  }
  return nullptr;
}

/// The natural frequencies of a model (or the reference), with f/f_reference mode by mode.
nlohmann::json modal_json(const ModalOutcome& m, const ModalOutcome* reference) {
  nlohmann::json j{{"model", m.model},   {"kind", m.kind},   {"detail", m.detail},
                   {"poisson_ratio", m.poisson_ratio},     {"level", m.level},
                   {"ok", m.ok},         {"dofs", m.dofs},   {"seconds", m.seconds}};
  if (!m.ok) {
    j["failure"] = m.failure;
    return j;
  }
  j["frequencies_hz"] = m.frequencies_hz;
  j["mechanisms"] = m.mechanisms;
  if (reference) j["ratio_to_reference"] = frequency_ratios(m, *reference);
  return j;
}

/// "f1;f2;..." for a CSV cell.
std::string joined(const std::vector<double>& v) {
  std::ostringstream s;
  s << std::setprecision(8);
  for (std::size_t i = 0; i < v.size(); ++i) s << (i ? ";" : "") << v[i];
  return s.str();
}

/// Where a contact load acts: the patch's centre and radius and the wall's outward normal there
/// (its force per magnitude is the magnitude, N, along the inward normal); null for other loads.
nlohmann::json contact_patch_json(const SceneResult& r) {
  const Scene& s = r.scene;
  if (s.load.kind != LoadKind::contact) return nullptr;
  const Vec3& c = s.load.contact.point;
  const Vec3& n = r.contact_normal;
  return {{"point_mm", {c.x() * 1e3, c.y() * 1e3, c.z() * 1e3}},
          {"radius_mm", s.load.contact.radius * 1e3},
          {"outward_normal", {n.x(), n.y(), n.z()}}};
}

/// One outcome's record; `results_dir` is where results.json goes (its fields path is relative
/// to it).
nlohmann::json outcome_json(const ModelOutcome& o, const SceneResult& r,
                            const std::filesystem::path& results_dir) {
  nlohmann::json j{{"model", o.model},
                   {"kind", o.kind},
                   {"detail", o.detail},
                   {"poisson_ratio", o.poisson_ratio},
                   {"magnitude", o.magnitude},
                   {"level", o.level},
                   {"reference", o.reference},
                   {"ok", o.ok},
                   {"nodes", o.nodes},
                   {"unknowns", o.unknowns},
                   {"setup_seconds", o.setup_seconds},
                   {"solve_seconds", o.solve_seconds},
                   {"memory_mib", o.memory_mib}};
  if (o.roi_radius > 0.0) j["roi_radius_mm"] = o.roi_radius * 1e3;
  if (!o.timing_source.empty()) j["timing_source"] = o.timing_source;
  if (!o.timing.measured_at.empty()) {
    j["timing_provenance"] = {{"source", o.timing.cached ? "cache" : "measured"},
                              {"measured_at", o.timing.measured_at}};
  }
  if (o.updates > 0) {
    j["updates"] = {{"count", o.updates},
                    {"iterations_per_update", o.iterations_per_update},
                    {"factorisations_per_update", o.factorisations_per_update}};
  }
  if (o.ok) {
    j["error"] = error_json(o.error);
    if (o.has_reference_uncertainty) {
      j["reference_uncertainty"] = {{"max_mm", o.reference_uncertainty.max_mm},
                                    {"rms_mm", o.reference_uncertainty.rms_mm}};
    } else {
      j["reference_uncertainty"] = nullptr;  // the reference had no coarser level
    }
    j["qoi_displacement_mm"] = o.qoi_displacement_mm;
    j["qoi_reference_mm"] = o.qoi_reference_mm;
    j["max_strain"] = o.max_strain;
    j["beyond_linear_regime"] = o.beyond_linear_regime;
    const QuantityErrors& q = o.quantities;
    j["quantities"] = {{"contact_point_mm", q.contact_point_mm},
                       {"field_mm", q.field_mm},
                       {"patch_mm", number_or_null(q.patch_mm)},
                       {"indentation_mm", number_or_null(q.indentation_mm)},
                       {"indentation_reference_mm", number_or_null(q.indentation_reference_mm)},
                       {"reaction_mN", number_or_null(q.reaction_mN)}};
    if (r.scene.budget.stated) {
      j["budget_error"] = number_or_null(o.budget_error);
      j["update_seconds"] = o.update_seconds;
      if (o.steps_per_update > 0) j["steps_per_update"] = o.steps_per_update;
    }
    j["wall_profile"] = {{"s_mm", o.wall_profile.s_mm},
                         {"model_mm", o.wall_profile.model_mm},
                         {"reference_mm", o.wall_profile.reference_mm}};
    if (!o.history.time_s.empty()) {
      j["history"] = {{"time_s", o.history.time_s},
                      {"model_mm", o.history.model_mm},
                      {"reference_mm", o.history.reference_mm},
                      {"max_error_mm", o.history.max_error_mm},
                      {"steps", o.history.steps},
                      {"simulated_s", o.history.simulated_s},
                      {"mass_damping_per_s", o.history.mass_damping},
                      {"reference_level", o.history.reference_level}};
    }
  } else {
    j["failure"] = o.failure;
  }
  if (!o.fields_file.empty()) {
    j["fields"] = std::filesystem::absolute(o.fields_file)
                      .lexically_relative(std::filesystem::absolute(results_dir))
                      .generic_string();
  }
  return j;
}

nlohmann::json scene_json(const SceneResult& r, const std::filesystem::path& results_dir) {
  nlohmann::json quality = nlohmann::json::array();
  for (const auto& [level, slivers] : r.mesh_slivers) {
    nlohmann::json q = mesh_quality_json(slivers);
    q["level"] = level;
    quality.push_back(q);
  }
  nlohmann::json refs = nlohmann::json::array();
  for (const auto& ref : r.references) {
    refs.push_back({{"poisson_ratio", ref.poisson_ratio},
                    {"element", ref.element},
                    {"level", ref.level},
                    {"dofs", ref.dofs},
                    {"solve_seconds", ref.solve_seconds},
                    {"max_abs_strain_at_unit_load", ref.max_abs_strain_unit},
                    {"budget_magnitude", ref.budget_magnitude},
                    {"uncertainty_order", uncertainty_order_json(r.scene, ref)}});
  }
  nlohmann::json outcomes = nlohmann::json::array();
  for (const auto& o : r.outcomes) outcomes.push_back(outcome_json(o, r, results_dir));
  const Scene& s = r.scene;
  nlohmann::json modes = nullptr;
  if (s.modes.count > 0) {
    nlohmann::json reference = nlohmann::json::array(), models = nlohmann::json::array();
    for (const auto& m : r.reference_modes) reference.push_back(modal_json(m, nullptr));
    for (const auto& m : r.model_modes) {
      models.push_back(modal_json(m, reference_modes_at(r, m.poisson_ratio)));
    }
    modes = {{"count", s.modes.count}, {"reference", reference}, {"models", models}};
  }
  nlohmann::json j = {
      {"name", s.name},
      {"source", s.source.string()},
      {"description", s.description},
      {"vessel", describe(s.vessel)},
      {"model_levels", s.model_levels},
      {"reference_level", s.reference_level},
      {"youngs_modulus_pa", s.youngs_modulus},
      {"load", to_string(s.load.kind)},
      {"load_unit", load_unit(s.load.kind)},
      {"qoi_point_mm", {r.qoi_point.x() * 1e3, r.qoi_point.y() * 1e3, r.qoi_point.z() * 1e3}},
      {"contact_patch", contact_patch_json(r)},
      {"tolerance_max_error_mm", s.tolerances.max_error_mm},
      {"budget", s.budget.stated ? budget_json(s.budget) : nlohmann::json(nullptr)},
      {"seconds", r.seconds},
      {"references", refs},
      {"outcomes", outcomes},
      {"modes", modes}};
  if (r.guidewire) j["guidewire"] = guidewire_json(*r.guidewire);
  if (r.guidewire_contact) j["guidewire"]["contact"] = guidewire_contact_json(*r.guidewire_contact);
  if (!r.lumen_ends.empty()) {
    j["lumen_ends"] = nlohmann::json::array();
    for (const auto& [group, end] : r.lumen_ends)
      j["lumen_ends"].push_back(lumen_end_json(group, end));
  }
  j["mesh_quality"] = quality;
  return j;
}

}  // namespace

nlohmann::json lumen_end_json(const std::string& group, const LumenEnd& e) {
  return {{"group", group},
          {"centre_mm", {e.centre.x() * 1e3, e.centre.y() * 1e3, e.centre.z() * 1e3}},
          {"radius_mm", e.radius * 1e3},
          {"normal", {e.normal.x(), e.normal.y(), e.normal.z()}},
          {"area_mm2", e.area * 1e6}};
}

nlohmann::json mesh_quality_json(const SliverReport& s) {
  nlohmann::json worst = nullptr;
  if (s.count > 0) {
    worst = {{"centroid_mm",
              {s.worst_centroid.x() * 1e3, s.worst_centroid.y() * 1e3, s.worst_centroid.z() * 1e3}},
             {"min_dihedral_deg", s.worst_min_dihedral_deg},
             {"max_dihedral_deg", s.worst_max_dihedral_deg}};
  }
  return {{"min_dihedral_deg", s.min_dihedral_deg},
          {"max_dihedral_deg", s.max_dihedral_deg},
          {"sliver_count", s.count},
          {"worst_at", worst}};
}

void write_results_json(const std::filesystem::path& path, const std::vector<SceneResult>& results,
                        const std::string& command, double reference_kernel_seconds) {
  nlohmann::json scenes = nlohmann::json::array();
  for (const auto& r : results) scenes.push_back(scene_json(r, path.parent_path()));
  nlohmann::json j{{"schema", "vesselverify.results"},
                         {"schema_version", 2},
                         {"units", {{"displacement", "mm"}, {"time", "s"}, {"strain", "1"}}},
                         {"date", utc_now()},
                         {"command", command},
                         {"machine",
                          {{"host", host_name()},
                           {"hardware_threads", std::thread::hardware_concurrency()}}},
                         {"build", {{"compiler", __VERSION__}, {"cxx_standard", __cplusplus}}},
                         {"scenes", scenes}};
  if (reference_kernel_seconds > 0.0) j["reference_kernel_seconds"] = reference_kernel_seconds;
  write_file_atomically(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

std::vector<SceneResult> run_and_write(const std::vector<Scene>& scenes,
                                       const HarnessOptions& options,
                                       const std::filesystem::path& output_dir,
                                       const std::string& command) {
  std::error_code ec;
  std::filesystem::create_directories(output_dir, ec);
  bool writable = !ec;
  if (writable) {
    const std::filesystem::path probe = output_dir / ".vesselverify-write-test";
    writable = static_cast<bool>(std::ofstream(probe));
    std::error_code ignored;
    std::filesystem::remove(probe, ignored);
  }
  if (!writable) {
    throw InputError(output_dir.string() + ": output directory cannot be " +
                     (ec ? "created (" + ec.message() + ")" : std::string("written")) +
                     "; expected a writable directory");
  }
  const double kernel = reference_kernel_seconds();
  std::vector<SceneResult> results = run_scenes(scenes, options);
  write_results_json(output_dir / "results.json", results, command, kernel);
  write_results_csv(output_dir / "results.csv", results);
  write_summary_markdown(output_dir / "summary.md", results, command);
  if (options.log) {
    *options.log << "wrote " << (output_dir / "results.json").string()
                 << ", results.csv and summary.md\n";
  }
  return results;
}

void write_results_csv(const std::filesystem::path& path, const std::vector<SceneResult>& results) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "scene,model,kind,poisson_ratio,level,magnitude,load_unit,ok,nodes,unknowns,setup_s,"
           "solve_s,memory_mib,"
           "max_mm,mean_mm,stddev_mm,rms_mm,relative_l2,ref_uncertainty_max_mm,qoi_mm,"
           "qoi_reference_mm,max_strain,beyond_linear_regime,updates,iterations_per_update,"
           "factorisations_per_update,mode_frequencies_hz,reference_mode_frequencies_hz,"
           "timing_source\n";
    out << std::setprecision(8);
    for (const auto& r : results) {
      for (const auto& o : r.outcomes) {
        out << r.scene.name << ',' << o.model << ',' << o.kind << ',' << o.poisson_ratio << ','
            << o.level << ',' << o.magnitude << ',' << load_unit(r.scene.load.kind) << ','
            << (o.ok ? 1 : 0) << ',' << o.nodes << ',' << o.unknowns << ',' << o.setup_seconds
            << ',' << o.solve_seconds << ',' << o.memory_mib;
        if (o.ok) {
          out << ',' << o.error.max_mm << ',' << o.error.mean_mm << ',' << o.error.stddev_mm << ','
              << o.error.rms_mm << ',' << o.error.relative_l2 << ',';
          if (o.has_reference_uncertainty) out << o.reference_uncertainty.max_mm;
          out << ',' << o.qoi_displacement_mm << ','
              << o.qoi_reference_mm << ',' << o.max_strain << ','
              << (o.beyond_linear_regime ? 1 : 0);
        } else {
          out << ",,,,,,,,,,";
        }
        out << ',';  // updates, iterations and factorisations per update; empty without a ramp
        if (o.updates > 0) {
          out << o.updates << ',' << o.iterations_per_update << ',' << o.factorisations_per_update;
        } else {
          out << ",,";
        }
        // Natural frequencies (scene's [modes]) of this model at this ν and level and of the
        // modal reference at this ν, "f1;f2;..." in Hz; empty where not computed.
        out << ',';
        for (const auto& m : r.model_modes) {
          if (m.ok && m.model == o.model && m.poisson_ratio == o.poisson_ratio &&
              m.level == o.level) {
            out << joined(m.frequencies_hz);
          }
        }
        out << ',';
        if (const ModalOutcome* ref = reference_modes_at(r, o.poisson_ratio); ref && ref->ok) {
          out << joined(ref->frequencies_hz);
        }
        out << ',' << o.timing_source << '\n';  // models outside the suite: whose times these are
      }
    }
  });
}

void write_summary_markdown(const std::filesystem::path& path,
                            const std::vector<SceneResult>& results, const std::string& command) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# vesselverify summary\n\n"
        << "Produced " << utc_now() << " on " << host_name() << " ("
        << std::thread::hardware_concurrency() << " hardware threads) by\n\n    " << command
        << "\n\nDisplacement errors against the FEM reference (P2, or Taylor–Hood P2–P1 for ν ≥ "
           "0.49) evaluated at each model node's rest position, in mm, with seed 000's "
           "statistics. *ref. unc.* is the reference's own estimated error there (Richardson "
           "between its two finest levels, at the order the scene's references record: observed on "
           "three levels, else assumed): errors below it are not resolved. Rows marked "
           "⚠ strain the reference beyond 5 %, outside linear elasticity's validity. *set-up s*: "
           "model build and the solver's preparation (assembly, factorisation at rest), done once. "
           "*solve s*: static and linear mass-spring models the time per update (median over a "
           "load ramp of warm-started updates ending at the row's load); integrators the run's "
           "steps; FEM the same ramp's median update, prepared as the linear mass-spring models "
           "are (assembly and factorisation are its set-up); models outside the suite "
           "(external, displacements) "
           "the simulator's own times from its timing.json, else its process's wall time "
           "(start-up and file I/O included), as marked.\n\n";
    out << std::setprecision(3);
    for (const auto& r : results) {
      const char* unit = load_unit(r.scene.load.kind);
      out << "## " << r.scene.name << "\n\n" << r.scene.description << ". " << describe(r.scene.vessel)
          << "; reference level " << r.scene.reference_level << " (" << std::fixed
          << std::setprecision(1) << r.seconds << " s in all)." << std::defaultfloat
          << std::setprecision(3) << "\n\n";
      out << "| model | ν | level | load (" << unit
          << ") | max | mean | std | RMS | rel. L2 | ref. unc. (max) | QoI model / ref. | set-up s | "
             "solve s | unknowns |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
      for (const auto& o : r.outcomes) {
        out << "| " << o.model << " | " << o.poisson_ratio << " | " << o.level << " | " << o.magnitude
            << (o.beyond_linear_regime ? " ⚠" : "") << " | ";
        if (!o.ok) {
          out << "FAILED: " << o.failure << " | | | | | | | | | |\n";
          continue;
        }
        out << o.error.max_mm << " | " << o.error.mean_mm << " | " << o.error.stddev_mm << " | "
            << o.error.rms_mm << " | " << o.error.relative_l2 << " | ";
        if (o.has_reference_uncertainty) {
          out << o.reference_uncertainty.max_mm;
        } else {
          out << "–";
        }
        // Models outside the suite: say whose times these are (their own, or their process's).
        const std::string source = o.timing_source == "simulator" ? " (simulator's own)"
                                   : o.timing_source == "process" ? " (process wall time)"
                                   : o.timing_source == "none"    ? " (not timed)"
                                                                  : "";
        out << " | " << o.qoi_displacement_mm << " / "
            << o.qoi_reference_mm << " | " << o.setup_seconds << " | " << o.solve_seconds << source
            << " | " << o.unknowns << " |\n";
      }
      out << "\n";
      const std::string provenance = timing_provenance_line(r.outcomes);
      if (!provenance.empty()) out << "Timings: " << provenance << ".\n\n";
      if (r.guidewire) write_guidewire_markdown(out, *r.guidewire);
      if (r.guidewire_contact) write_guidewire_contact_markdown(out, *r.guidewire_contact);
      if (r.reference_modes.empty() && r.model_modes.empty()) continue;
      // Natural frequencies ([modes]): each model's beside the modal reference's, by rank.
      out << "Natural frequencies (Hz) at rest, the scene's supports held; f/f_ref mode by mode "
             "(k-th lowest against k-th lowest). Reference: P2, displacement formulation, "
             "consistent mass; mass-spring models: K at rest, lumped masses.\n\n"
          << "| model | ν | level | frequencies Hz | f / f_ref | zero modes |\n"
             "|---|---|---|---|---|---|\n";
      const auto row = [&](const ModalOutcome& m, const std::string& name) {
        out << "| " << name << " | " << m.poisson_ratio << " | " << m.level << " | ";
        if (!m.ok) {
          out << "FAILED: " << m.failure << " | | |\n";
          return;
        }
        for (std::size_t k = 0; k < m.frequencies_hz.size(); ++k) {
          out << (k ? ", " : "") << m.frequencies_hz[k];
        }
        out << " | ";
        if (const ModalOutcome* ref = reference_modes_at(r, m.poisson_ratio); ref && &m != ref) {
          const std::vector<double> q = frequency_ratios(m, *ref);
          for (std::size_t k = 0; k < q.size(); ++k) out << (k ? ", " : "") << q[k];
        }
        out << " | " << m.mechanisms << " |\n";
      };
      for (const auto& m : r.reference_modes) row(m, "reference (" + m.detail + ")");
      for (const auto& m : r.model_modes) row(m, m.model);
      out << "\n";
    }
  });
}

}  // namespace vessel
