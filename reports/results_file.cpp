#include "reports/results_file.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "reports/json_fields.hpp"

namespace vessel::reports {

namespace {

using json_fields::field;
using json_fields::field_or;
using nlohmann::json;

OutcomeRow read_outcome(const json& j, const std::string& where) {
  OutcomeRow o;
  o.model = field<std::string>(j, "model", where);
  o.kind = field<std::string>(j, "kind", where);
  o.detail = field<std::string>(j, "detail", where);
  o.poisson_ratio = field<double>(j, "poisson_ratio", where);
  o.magnitude = field<double>(j, "magnitude", where);
  o.level = field<int>(j, "level", where);
  o.ok = field<bool>(j, "ok", where);
  o.nodes = field<std::size_t>(j, "nodes", where);
  o.unknowns = field<std::size_t>(j, "unknowns", where);
  o.setup_seconds = field<double>(j, "setup_seconds", where);
  o.solve_seconds = field<double>(j, "solve_seconds", where);
  o.memory_mib = field_or<double>(j, "memory_mib", 0.0, where);
  o.timing_source = field_or<std::string>(j, "timing_source", "", where);
  o.fields = field_or<std::string>(j, "fields", "", where);
  if (const auto t = j.find("timing_provenance"); t != j.end() && t->is_object()) {
    o.timing_cached = field<std::string>(*t, "source", where + ".timing_provenance") == "cache";
    o.timing_measured_at = field<std::string>(*t, "measured_at", where + ".timing_provenance");
  }
  if (!o.ok) {
    o.failure = field<std::string>(j, "failure", where);
    return o;
  }
  o.budget_error = json_fields::optional_field<double>(j, "budget_error", where);
  o.update_seconds = json_fields::optional_field<double>(j, "update_seconds", where);
  const json e = field<json>(j, "error", where);
  o.max_mm = field<double>(e, "max_mm", where + ".error");
  o.mean_mm = field<double>(e, "mean_mm", where + ".error");
  o.stddev_mm = field<double>(e, "stddev_mm", where + ".error");
  o.rms_mm = field<double>(e, "rms_mm", where + ".error");
  o.relative_l2 = field<double>(e, "relative_l2", where + ".error");
  if (const auto u = j.find("reference_uncertainty"); u != j.end() && !u->is_null()) {
    o.reference_uncertainty_max_mm = field<double>(*u, "max_mm", where + ".reference_uncertainty");
  }
  o.qoi_mm = field<double>(j, "qoi_displacement_mm", where);
  o.qoi_reference_mm = field<double>(j, "qoi_reference_mm", where);
  o.max_strain = field<double>(j, "max_strain", where);
  o.beyond_linear_regime = field<bool>(j, "beyond_linear_regime", where);
  if (const auto p = j.find("wall_profile"); p != j.end()) {
    o.profile_s_mm = field<std::vector<double>>(*p, "s_mm", where + ".wall_profile");
    o.profile_model_mm = field<std::vector<double>>(*p, "model_mm", where + ".wall_profile");
    o.profile_reference_mm = field<std::vector<double>>(*p, "reference_mm", where + ".wall_profile");
  }
  if (const auto h = j.find("history"); h != j.end()) {
    o.history_time_s = field<std::vector<double>>(*h, "time_s", where + ".history");
    o.history_model_mm = field<std::vector<double>>(*h, "model_mm", where + ".history");
    o.history_reference_mm = field<std::vector<double>>(*h, "reference_mm", where + ".history");
    o.history_max_error_mm = field<double>(*h, "max_error_mm", where + ".history");
    o.steps = field<long>(*h, "steps", where + ".history");
    o.simulated_s = field<double>(*h, "simulated_s", where + ".history");
    o.mass_damping_per_s = field<double>(*h, "mass_damping_per_s", where + ".history");
    o.history_reference_level =
        json_fields::optional_field<int>(*h, "reference_level", where + ".history");
  }
  return o;
}

ModalRow read_modal(const json& j, const std::string& where) {
  ModalRow m;
  m.model = field<std::string>(j, "model", where);
  m.kind = field<std::string>(j, "kind", where);
  m.detail = field<std::string>(j, "detail", where);
  m.poisson_ratio = field<double>(j, "poisson_ratio", where);
  m.level = field<int>(j, "level", where);
  m.ok = field<bool>(j, "ok", where);
  m.dofs = field<std::size_t>(j, "dofs", where);
  m.seconds = field<double>(j, "seconds", where);
  if (!m.ok) {
    m.failure = field<std::string>(j, "failure", where);
    return m;
  }
  m.frequencies_hz = field<std::vector<double>>(j, "frequencies_hz", where);
  m.mechanisms = field_or<int>(j, "mechanisms", 0, where);
  m.ratio_to_reference = field_or<std::vector<double>>(j, "ratio_to_reference", {}, where);
  return m;
}

ContactWallRow read_contact_wall(const json& j, const std::string& where) {
  ContactWallRow w;
  w.model = field<std::string>(j, "model", where);
  w.wall = field<std::string>(j, "wall", where);
  w.ok = field<bool>(j, "ok", where);
  if (!w.ok) {
    w.failure = field<std::string>(j, "failure", where);
    return w;
  }
  w.force_mN = field<double>(j, "force_mN", where);
  w.force_error_mN = json_fields::optional_field<double>(j, "force_error_mN", where);
  w.force_error_percent = json_fields::optional_field<double>(j, "force_error_percent", where);
  w.tip_error_mm = json_fields::optional_field<double>(j, "tip_error_mm", where);
  w.pressed = field<int>(j, "pressed", where);
  w.axial_extent_mm = field<double>(j, "axial_extent_mm", where);
  w.circumferential_extent_mm = field<double>(j, "circumferential_extent_mm", where);
  w.dent_mm = field<double>(j, "dent_mm", where);
  // null: not computable (a surface model's wall has no tets)
  w.largest_strain = json_fields::optional_field<double>(j, "largest_strain", where).value_or(NAN);
  w.setup_seconds = field<double>(j, "setup_seconds", where);
  w.solve_seconds = field<double>(j, "solve_seconds", where);
  return w;
}

GuidewireContactRows read_guidewire_contact(const json& c, const std::string& where) {
  GuidewireContactRows out;
  out.poisson_ratio = field<double>(c, "poisson_ratio", where);
  out.fine_size_mm = field<double>(c, "fine_size_mm", where);
  out.fine_radius_mm = field<double>(c, "fine_radius_mm", where);
  out.strain_limit = field<double>(c, "strain_limit", where);
  out.mesh_nodes = field<int>(c, "mesh_nodes", where);
  out.reference_degree = field<int>(c, "reference_degree", where);
  out.wall = json_fields::field_or<std::string>(c, "wall", "linear", where);
  for (const json& r : field<json>(c, "runs", where)) {
    const std::string rw = where + ".runs";
    ContactRun run;
    run.bending_stiffness = field<double>(r, "bending_stiffness_Nm2", rw);
    run.rigid_force_mN = field<double>(r, "rigid_force_mN", rw);
    run.within_linear_validity = field<bool>(r, "within_linear_validity", rw);
    run.reference = read_contact_wall(field<json>(r, "reference", rw), rw + ".reference");
    for (const json& m : field<json>(r, "models", rw)) {
      run.models.push_back(read_contact_wall(m, rw + ".models"));
    }
    for (const json& s : field<json>(r, "shortcuts", rw)) {
      const std::string sw = rw + ".shortcuts";
      run.shortcuts.push_back({field<std::string>(s, "name", sw), field<double>(s, "force_mN", sw),
                               json_fields::optional_field<double>(s, "force_error_percent", sw)});
    }
    out.runs.push_back(std::move(run));
  }
  return out;
}

GuidewireRows read_guidewire(const json& g, const std::string& where) {
  GuidewireRows w;
  w.model = field<std::string>(g, "model", where);
  w.coupling = field<std::string>(g, "coupling", where);
  w.diameter_mm = field_or<double>(g, "diameter_m", 0.0, where) * 1e3;
  using Line = std::vector<std::array<double, 3>>;
  for (const json& r : field<json>(g, "rigid", where)) {
    const std::string rw = where + ".rigid";
    GuidewireRigidRow row{field<double>(r, "bending_stiffness_Nm2", rw),
                          field<double>(r, "contact_force_N", rw) * 1e3,
                          json_fields::optional_field<double>(r, "wire_compliance_m_per_N", rw),
                          field_or<Line>(r, "centreline_mm", {}, rw),
                          {},
                          "",
                          json_fields::optional_field<double>(r, "force_error_mN", rw)};
    const json coupled = field_or<json>(r, "reference_coupled", nullptr, rw);
    if (coupled.is_object()) {
      row.reference_centreline_mm = field<Line>(coupled, "centreline_mm", rw + ".reference_coupled");
      row.reference_row = field<std::string>(coupled, "row", rw + ".reference_coupled");
    }
    w.rigid.push_back(std::move(row));
  }
  for (const json& r : field_or<json>(g, "coupling_rows", json::array(), where)) {
    const std::string rw = where + ".coupling_rows";
    GuidewireCoupledRow c;
    c.model = field<std::string>(r, "model", rw);
    c.poisson_ratio = field<double>(r, "poisson_ratio", rw);
    c.level = field<int>(r, "level", rw);
    c.bending_stiffness = field<double>(r, "bending_stiffness_Nm2", rw);
    c.ok = field<bool>(r, "ok", rw);
    if (!c.ok) {
      c.failure = field<std::string>(r, "failure", rw);
    } else {
      c.force_mN = field<double>(r, "force_mN", rw);
      c.reference_force_mN = field<double>(r, "reference_force_mN", rw);
      c.displacement_mm = field<double>(r, "contact_displacement_mm", rw);
      c.reference_displacement_mm = field<double>(r, "reference_contact_displacement_mm", rw);
      c.slide_mm = field<double>(r, "slide_mm", rw);
      c.within_patch = field<bool>(r, "within_patch", rw);
      c.reference_within_wall = field_or<bool>(r, "reference_within_wall", true, rw);
      c.field_relative_l2_rigid = json_fields::optional_field<double>(r, "field_relative_l2_rigid", rw);
      c.field_relative_l2 = json_fields::optional_field<double>(r, "field_relative_l2", rw);
    }
    w.coupled.push_back(std::move(c));
  }
  if (const auto c = g.find("contact"); c != g.end()) {
    w.contact = read_guidewire_contact(*c, where + ".contact");
  }
  return w;
}

/// A reference's GCI order as the report shows it: "1 (assumed, Fs 3)", or "none".
std::string gci_text(const json& j, const std::string& where) {
  const std::string source = field<std::string>(j, "source", where);
  if (source == "none") return "none";
  if (source != "observed" && source != "assumed") {
    throw InputError(where + ": field 'source' is '" + source +
                     "', expected observed, assumed or none");
  }
  std::ostringstream t;
  t.precision(3);
  t << field<double>(j, "order", where) << " (" << source << ", Fs "
    << field<double>(j, "safety_factor", where) << ")";
  return t.str();
}

}  // namespace

ResultsFile parse_results(const std::string& text, const std::filesystem::path& source) {
  const std::string file = source.string();
  const json j = json_fields::parse_versioned(text, file, "vesselverify.results", 2,
                                              "results file", "vesselverify run");
  ResultsFile r;
  r.path = source;
  r.schema_version = 2;
  r.date = field<std::string>(j, "date", file);
  r.command = field<std::string>(j, "command", file);
  r.host = field<std::string>(field<json>(j, "machine", file), "host", file + ": machine");
  r.hardware_threads = field<unsigned>(field<json>(j, "machine", file), "hardware_threads", file + ": machine");
  r.compiler = field<std::string>(field<json>(j, "build", file), "compiler", file + ": build");
  if (const auto k = j.find("reference_kernel_seconds"); k != j.end() && !k->is_null()) {
    r.reference_kernel_seconds = k->get<double>();
  }
  const auto scenes = field<json>(j, "scenes", file);
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const json& s = scenes[i];
    const std::string where = file + ": scenes[" + std::to_string(i) + "]";
    SceneRows sr;
    sr.name = field<std::string>(s, "name", where);
    sr.description = field_or<std::string>(s, "description", "", where);
    sr.vessel = field<std::string>(s, "vessel", where);
    sr.load = field<std::string>(s, "load", where);
    sr.load_unit = field<std::string>(s, "load_unit", where);
    sr.model_levels = field<std::vector<int>>(s, "model_levels", where);
    sr.reference_level = field<int>(s, "reference_level", where);
    sr.tolerance_mm = field_or<double>(s, "tolerance_max_error_mm", 0.1, where);
    sr.seconds = field<double>(s, "seconds", where);
    if (const auto q = s.find("qoi_point_mm"); q != s.end() && q->is_array() && q->size() == 3) {
      sr.qoi_point_mm = q->get<std::vector<double>>();
    }
    if (const auto m = s.find("mesh_quality"); m != s.end() && m->is_array()) {
      for (std::size_t k = 0; k < m->size(); ++k) {
        const json& q = (*m)[k];
        const std::string at = where + ".mesh_quality[" + std::to_string(k) + "]";
        MeshQualityRow row;
        row.level = field<int>(q, "level", at);
        row.min_dihedral_deg = field<double>(q, "min_dihedral_deg", at);
        row.max_dihedral_deg = field<double>(q, "max_dihedral_deg", at);
        row.sliver_count = field<std::size_t>(q, "sliver_count", at);
        if (const auto w = q.find("worst_at"); w != q.end() && !w->is_null()) {
          row.worst_centroid_mm = field<std::vector<double>>(*w, "centroid_mm", at + ".worst_at");
          row.worst_min_dihedral_deg = field<double>(*w, "min_dihedral_deg", at + ".worst_at");
          row.worst_max_dihedral_deg = field<double>(*w, "max_dihedral_deg", at + ".worst_at");
          if (row.worst_centroid_mm.size() != 3) {
            throw InputError(at + ".worst_at: centroid_mm needs 3 numbers");
          }
        }
        sr.mesh_quality.push_back(row);
      }
    }
    if (const auto e = s.find("lumen_ends"); e != s.end() && e->is_array()) {
      for (std::size_t k = 0; k < e->size(); ++k) {
        const std::string at = where + ".lumen_ends[" + std::to_string(k) + "]";
        LumenEndRow row;
        row.group = field<std::string>((*e)[k], "group", at);
        row.centre_mm = field<std::vector<double>>((*e)[k], "centre_mm", at);
        row.radius_mm = field<double>((*e)[k], "radius_mm", at);
        if (row.centre_mm.size() != 3) throw InputError(at + ": centre_mm needs 3 numbers");
        sr.lumen_ends.push_back(row);
      }
    }
    if (const auto c = s.find("contact_patch"); c != s.end() && !c->is_null()) {
      ContactPatchRow patch;
      patch.point_mm = field<std::vector<double>>(*c, "point_mm", where + ".contact_patch");
      patch.radius_mm = field<double>(*c, "radius_mm", where + ".contact_patch");
      patch.outward_normal =
          field<std::vector<double>>(*c, "outward_normal", where + ".contact_patch");
      if (patch.point_mm.size() != 3 || patch.outward_normal.size() != 3) {
        throw InputError(where + ".contact_patch: point_mm and outward_normal need 3 numbers each");
      }
      sr.contact_patch = patch;
    }
    if (const auto b = s.find("budget"); b != s.end() && !b->is_null()) {
      sr.budget_magnitude = json_fields::optional_field<double>(*b, "magnitude", where + ".budget");
      BudgetRow budget;
      budget.quantity = field<std::string>(*b, "quantity", where + ".budget");
      budget.unit = field<std::string>(*b, "unit", where + ".budget");
      budget.tolerance = field<double>(*b, "tolerance", where + ".budget");
      budget.rate_hz = json_fields::optional_field<double>(*b, "rate_hz", where + ".budget");
      budget.seconds_per_update = field<double>(*b, "seconds_per_update", where + ".budget");
      sr.budget = budget;
    }
    for (const json& ref : field<json>(s, "references", where)) {
      ReferenceRow rr;
      rr.poisson_ratio = field<double>(ref, "poisson_ratio", where + ".references");
      rr.element = field<std::string>(ref, "element", where + ".references");
      rr.level = field<int>(ref, "level", where + ".references");
      rr.dofs = field<std::size_t>(ref, "dofs", where + ".references");
      rr.solve_seconds = field<double>(ref, "solve_seconds", where + ".references");
      rr.max_abs_strain_at_unit_load =
          field<double>(ref, "max_abs_strain_at_unit_load", where + ".references");
      if (const auto u = ref.find("uncertainty_order"); u != ref.end() && !u->is_null()) {
        rr.gci_linear = gci_text(field<json>(*u, "linear", where + ".references.uncertainty_order"),
                                 where + ".references.uncertainty_order.linear");
        if (const auto f = u->find("finite_strain"); f != u->end() && !f->is_null()) {
          rr.gci_finite = gci_text(*f, where + ".references.uncertainty_order.finite_strain");
        }
      }
      sr.references.push_back(rr);
    }
    const auto outcomes = field<json>(s, "outcomes", where);
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
      sr.outcomes.push_back(
          read_outcome(outcomes[k], where + ".outcomes[" + std::to_string(k) + "]"));
    }
    if (const auto m = s.find("modes"); m != s.end() && !m->is_null()) {
      const std::string w = where + ".modes";
      const json reference = field<json>(*m, "reference", w);
      for (std::size_t k = 0; k < reference.size(); ++k) {
        sr.reference_modes.push_back(
            read_modal(reference[k], w + ".reference[" + std::to_string(k) + "]"));
      }
      const json models = field<json>(*m, "models", w);
      for (std::size_t k = 0; k < models.size(); ++k) {
        sr.model_modes.push_back(read_modal(models[k], w + ".models[" + std::to_string(k) + "]"));
      }
    }
    if (const auto g = s.find("guidewire"); g != s.end() && !g->is_null()) {
      sr.guidewire = read_guidewire(*g, where + ".guidewire");
    }
    r.scenes.push_back(std::move(sr));
  }
  return r;
}

ResultsFile read_results(const std::filesystem::path& path) {
  return parse_results(json_fields::read_text(path, "results file"), path);
}

std::string timing_provenance_line(std::size_t total, std::vector<std::string> cached_at) {
  if (cached_at.empty()) return "";
  std::sort(cached_at.begin(), cached_at.end());
  std::string line = std::to_string(cached_at.size()) + " of " + std::to_string(total) +
                     " timings from the cache, measured " + cached_at.front();
  if (cached_at.back() != cached_at.front()) line += " to " + cached_at.back();
  return line + " by the same executable on this machine; --retime to measure again";
}

}  // namespace vessel::reports
