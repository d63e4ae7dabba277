#include "reports/study_files.hpp"

#include "reports/json_fields.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

namespace {

using json_fields::field;
using json_fields::field_or;
using json_fields::optional_field;
using nlohmann::json;

/// j[key] as an array, each element with its JSON path for messages.
template <class Read>
auto read_array(const json& j, const char* key, const std::string& where, Read&& read) {
  const json a = field<json>(j, key, where);
  if (!a.is_array()) throw InputError(where + ": field '" + key + "' is not an array");
  std::vector<decltype(read(a[0], where))> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    // "file: key[i]" at the top level, "file: outer[k].key[i]" below it.
    const std::string sep = where.find(": ") == std::string::npos ? ": " : ".";
    out.push_back(read(a[i], where + sep + key + "[" + std::to_string(i) + "]"));
  }
  return out;
}

CriticalStepEntry read_step(const json& j, const std::string& where) {
  CriticalStepEntry e;
  e.model = field<std::string>(j, "model", where);
  e.integrator = field<std::string>(j, "integrator", where);
  e.zeta = field<double>(j, "zeta", where);
  e.level = field<int>(j, "level", where);
  e.nodes = field<int>(j, "nodes", where);
  e.omega_max = field<double>(j, "omega_max", where);
  e.omega_gershgorin = field<double>(j, "omega_gershgorin", where);
  e.predicted_dt = field<double>(j, "predicted_dt", where);
  e.found_dt = field<double>(j, "found_dt", where);
  e.guaranteed_dt = optional_field<double>(j, "guaranteed_dt", where);
  return e;
}

RefinementEntry read_refinement(const json& j, const std::string& where) {
  RefinementEntry e;
  e.model = field<std::string>(j, "model", where);
  e.integrator = field<std::string>(j, "integrator", where);
  e.zeta = field<double>(j, "zeta", where);
  e.levels = field<std::vector<int>>(j, "levels", where);
  e.found_exponent = field<double>(j, "found_exponent", where);
  e.predicted_exponent = field<double>(j, "predicted_exponent", where);
  return e;
}

HardCaseOutcomeEntry read_hard_outcome(const json& j, const std::string& where) {
  HardCaseOutcomeEntry e;
  e.model = field<std::string>(j, "model", where);
  e.finished = field<bool>(j, "finished", where);
  e.converged = optional_field<bool>(j, "converged", where);
  e.bounded = optional_field<bool>(j, "bounded", where);
  e.reported = field<std::string>(j, "reported", where);
  return e;
}

HardCaseEntry read_hard_case(const json& j, const std::string& where) {
  HardCaseEntry e;
  e.id = field<std::string>(j, "id", where);
  e.title = field<std::string>(j, "title", where);
  e.setup = field<std::string>(j, "setup", where);
  e.seconds = field<double>(j, "seconds", where);
  e.outcomes = read_array(j, "outcomes", where, read_hard_outcome);
  return e;
}

RodStepEntry read_rod_step(const json& j, const std::string& where) {
  RodStepEntry e;
  e.model = field<std::string>(j, "model", where);
  e.integrator = field<std::string>(j, "integrator", where);
  e.failure = field<std::string>(j, "failure", where);
  e.segments = field<int>(j, "segments", where);
  e.h = field<double>(j, "h", where);
  e.axial_dt = field<double>(j, "axial_dt", where);
  e.twist_dt = field<double>(j, "twist_dt", where);
  e.bending_dt = field<double>(j, "bending_dt", where);
  e.closed_form_dt = field<double>(j, "closed_form_dt", where);
  e.predicted_dt = optional_field<double>(j, "predicted_dt", where);
  e.found_dt = optional_field<double>(j, "found_dt", where);
  e.steps_tried = field<std::vector<double>>(j, "steps_tried", where);
  e.bounded = field<std::vector<bool>>(j, "bounded", where);
  if (e.bounded.size() != e.steps_tried.size()) {
    throw InputError(where + ": 'bounded' and 'steps_tried' differ in length");
  }
  return e;
}

TetStepEntry read_tet_step(const json& j, const std::string& where) {
  TetStepEntry e;
  e.model = field<std::string>(j, "model", where);
  e.integrator = field<std::string>(j, "integrator", where);
  e.failure = field<std::string>(j, "failure", where);
  e.level = field<int>(j, "level", where);
  e.nodes = field<int>(j, "nodes", where);
  e.nu = field<double>(j, "nu", where);
  e.load = field<double>(j, "load", where);
  e.predicted_dt = optional_field<double>(j, "predicted_dt", where);
  e.power_dt = optional_field<double>(j, "power_dt", where);
  e.found_dt = optional_field<double>(j, "found_dt", where);
  e.unstable_dt = optional_field<double>(j, "unstable_dt", where);
  e.steps_tried = field<std::vector<double>>(j, "steps_tried", where);
  e.bounded = field<std::vector<bool>>(j, "bounded", where);
  if (e.bounded.size() != e.steps_tried.size()) {
    throw InputError(where + ": 'bounded' and 'steps_tried' differ in length");
  }
  return e;
}

WireCandidateEntry read_wire_candidate(const json& j, const std::string& where) {
  WireCandidateEntry e;
  e.name = field<std::string>(j, "name", where);
  e.verdict = field<std::string>(j, "verdict", where);
  e.reason = field<std::string>(j, "reason", where);
  e.ok = field<bool>(j, "ok", where);
  if (!e.ok) {
    e.failure = field<std::string>(j, "failure", where);
    return e;
  }
  e.force_error_mN = field<double>(j, "force_error_mN", where);
  e.contact_error_mm = field<double>(j, "contact_point_error_mm", where);
  e.update_seconds = field<double>(j, "update_seconds", where);
  e.setup_seconds = field<double>(j, "setup_seconds", where);
  return e;
}

WireEntry read_wire(const json& j, const std::string& where) {
  WireEntry w;
  const json ref = field_or<json>(j, "reference", nullptr, where);
  if (!ref.is_object()) {
    w.no_reference = field<std::string>(j, "no_reference", where);
    return w;
  }
  w.reference = field<std::string>(ref, "what", where + ".reference");
  w.reference_force_N = field<double>(ref, "contact_force_N", where + ".reference");
  w.recommended = optional_field<std::string>(j, "recommended", where);
  w.candidates = read_array(j, "candidates", where, read_wire_candidate);
  return w;
}

PairCandidateEntry read_pair(const json& j, const std::string& where) {
  PairCandidateEntry e;
  e.name = field<std::string>(j, "name", where);
  e.wire = field<std::string>(j, "wire", where);
  e.vessel = field<std::string>(j, "vessel", where);
  e.error = optional_field<double>(j, "error", where);
  e.update_seconds = field<double>(j, "update_seconds", where);
  e.setup_seconds = field<double>(j, "setup_seconds", where);
  e.pareto = field<bool>(j, "pareto", where);
  e.verdict = field<std::string>(j, "verdict", where);
  e.reason = field<std::string>(j, "reason", where);
  return e;
}

PairsEntry read_pairs(const json& j, const std::string& where) {
  PairsEntry p;
  p.recommended = optional_field<std::string>(j, "recommended", where);
  p.closest = optional_field<std::string>(j, "closest", where);
  p.pairs = read_array(j, "pairs", where, read_pair);
  return p;
}

CandidateEntry read_candidate(const json& j, const std::string& where) {
  CandidateEntry e;
  e.name = field<std::string>(j, "name", where);
  e.detail = field<std::string>(j, "detail", where);
  e.unknowns = field<std::size_t>(j, "unknowns", where);
  e.ok = field<bool>(j, "ok", where);
  e.pareto = field<bool>(j, "pareto", where);
  e.verdict = field<std::string>(j, "verdict", where);
  e.reason = field<std::string>(j, "reason", where);
  e.roi_radius_mm = optional_field<double>(j, "roi_radius_mm", where);
  if (e.ok) {
    e.error = optional_field<double>(j, "error", where);
    e.update_seconds = field<double>(j, "update_seconds", where);
    e.setup_seconds = optional_field<double>(j, "setup_seconds", where);
  } else {
    e.failure = field<std::string>(j, "failure", where);
  }
  return e;
}

BudgetLoadEntry read_load(const json& j, const std::string& where) {
  BudgetLoadEntry e;
  e.poisson_ratio = field<double>(j, "poisson_ratio", where);
  e.magnitude = field<double>(j, "magnitude", where);
  e.reference_element = field_or<std::string>(j, "reference_element", "", where);
  return e;
}

CalibrationParameterEntry read_parameter(const json& j, const std::string& where) {
  return {field<std::string>(j, "name", where), field<double>(j, "factor", where)};
}

CalibrationCaseEntry read_calibration_case(const json& j, const std::string& where) {
  CalibrationCaseEntry e;
  e.scene = field<std::string>(j, "scene", where);
  e.name = field<std::string>(j, "name", where);
  e.holds_out = field<std::string>(j, "holds_out", where);
  e.training = field<bool>(j, "training", where);
  e.load_kind = field<std::string>(j, "load_kind", where);
  e.load_unit = field<std::string>(j, "load_unit", where);
  e.magnitude = field<double>(j, "magnitude", where);
  e.level = field<int>(j, "level", where);
  e.p1_relative_l2 = field<double>(j, "p1_relative_l2", where);
  e.p1_solve_seconds = field<double>(j, "p1_solve_seconds", where);
  e.max_strain_reference = field<double>(j, "max_strain_reference", where);
  e.base_relative_l2 = optional_field<double>(j, "base_relative_l2", where);
  e.base_update_seconds = optional_field<double>(j, "base_update_seconds", where);
  e.calibrated_relative_l2 = optional_field<double>(j, "calibrated_relative_l2", where);
  e.calibrated_update_seconds = optional_field<double>(j, "calibrated_update_seconds", where);
  e.failure = field_or<std::string>(j, "failure", "", where);
  e.base_failure = field_or<std::string>(j, "base_failure", "", where);
  return e;
}

ValidityCrossingEntry read_crossing(const json& j, const std::string& where) {
  ValidityCrossingEntry e;
  e.threshold = field<double>(j, "threshold", where);
  e.status = field<std::string>(j, "status", where);
  if (e.status != "interpolated" && e.status != "below_ladder" && e.status != "not_reached") {
    throw InputError(where + ": field 'status' is '" + e.status +
                     "', expected interpolated, below_ladder or not_reached");
  }
  e.load = optional_field<double>(j, "load", where);
  if (e.status != "not_reached" && !e.load) throw InputError(where + ": missing field 'load'");
  e.lower = field<double>(j, "lower", where);
  e.upper = field<double>(j, "upper", where);
  return e;
}

ValidityModelEntry read_validity_model(const json& j, const std::string& where) {
  ValidityModelEntry e;
  e.model = field<std::string>(j, "model", where);
  e.ok = field<bool>(j, "ok", where);
  if (e.ok) {
    e.relative_l2 = field<double>(j, "relative_l2", where);
    e.max_error_mm = field<double>(j, "max_error_mm", where);
    e.qoi_error_mm = field<double>(j, "qoi_error_mm", where);
    e.qoi_relative = field<double>(j, "qoi_relative", where);
    e.fields = json_fields::field_or<std::string>(j, "fields", "", where);
  } else {
    e.failure = field<std::string>(j, "failure", where);
  }
  return e;
}

ValidityRowEntry read_validity_row(const json& j, const std::string& where) {
  ValidityRowEntry e;
  e.magnitude = field<double>(j, "magnitude", where);
  e.linear_qoi_mm = field<double>(j, "linear_qoi_mm", where);
  e.finite_qoi_mm = field<double>(j, "finite_qoi_mm", where);
  e.qoi_difference = field<double>(j, "qoi_difference", where);
  e.l2_difference = field<double>(j, "l2_difference", where);
  e.linear_strain = field<double>(j, "linear_strain", where);
  if (const auto g = j.find("wall_gap_mm"); g != j.end() && !g->is_null()) {
    e.wall_gap_mm = field<double>(j, "wall_gap_mm", where);
  }
  e.newton_iterations = field<int>(j, "newton_iterations", where);
  e.load_steps = field<int>(j, "load_steps", where);
  e.finite_seconds = field<double>(j, "finite_seconds", where);
  e.models = read_array(j, "models", where, read_validity_model);
  return e;
}

ValiditySceneEntry read_validity_scene(const json& j, const std::string& where) {
  ValiditySceneEntry e;
  e.scene = field<std::string>(j, "scene", where);
  e.load_kind = field<std::string>(j, "load_kind", where);
  e.load_unit = field<std::string>(j, "load_unit", where);
  e.element = field<std::string>(j, "element", where);
  e.poisson_ratio = field<double>(j, "poisson_ratio", where);
  e.reference_level = field<int>(j, "reference_level", where);
  e.model_level = field<int>(j, "model_level", where);
  e.dofs = field<std::size_t>(j, "dofs", where);
  e.ladder = field<std::vector<double>>(j, "ladder", where);
  for (const json& m : field<json>(j, "models", where)) {
    e.models.push_back(field<std::string>(m, "name", where + ".models[]"));
  }
  const json c = field<json>(j, "continuation", where);
  const std::string cw = where + ".continuation";
  e.completed = field<bool>(c, "completed", cw);
  e.largest_load = field<double>(c, "largest_load", cw);
  e.stop_reason = field<std::string>(c, "stop_reason", cw);
  // Files written before the self-contact check have no such field: their stop is shown as
  // written (its reason), not as self-contact.
  if (c.contains("self_contact")) e.self_contact = field<bool>(c, "self_contact", cw);
  e.load_steps = field<int>(c, "load_steps", cw);
  e.rejected_steps = field<int>(c, "rejected_steps", cw);
  e.newton_iterations = field<int>(c, "newton_iterations", cw);
  e.solve_seconds = field<double>(c, "solve_seconds", cw);
  e.from_cache = field<bool>(c, "from_cache", cw);
  e.qoi_limits = read_array(j, "qoi_limits", where, read_crossing);
  e.l2_limits = read_array(j, "l2_limits", where, read_crossing);
  e.rows = read_array(j, "rows", where, read_validity_row);
  if (const auto q = j.find("qoi_point_mm"); q != j.end()) {
    e.qoi_point_mm = field<std::vector<double>>(j, "qoi_point_mm", where);
    if (e.qoi_point_mm->size() != 3) throw InputError(where + ": qoi_point_mm needs 3 numbers");
  }
  return e;
}

std::array<double, 3> read_vector(const json& j, const char* key, const std::string& where) {
  const auto v = field<std::vector<double>>(j, key, where);
  if (v.size() != 3) throw InputError(where + ": " + key + " needs 3 numbers");
  return {v[0], v[1], v[2]};
}

InsertionZoneEntry read_insertion_zone(const json& j, const std::string& where) {
  InsertionZoneEntry z;
  z.force = field<double>(j, "force_N", where);
  z.centroid = read_vector(j, "centroid_m", where);
  z.extent = field<double>(j, "extent_m", where);
  z.nodes = field<int>(j, "nodes", where);
  return z;
}

InsertionStepEntry read_insertion_step(const json& j, const std::string& where) {
  InsertionStepEntry s;
  s.insertion = field<double>(j, "insertion_m", where);
  s.converged = field<bool>(j, "converged", where);
  s.failure = field<std::string>(j, "failure", where);
  s.force = field<double>(j, "force_N", where);
  s.pressed = field<int>(j, "pressed", where);
  s.zones = read_array(j, "zones", where, read_insertion_zone);
  s.clamp_axial = field<double>(j, "clamp_axial_N", where);
  s.push = field<double>(j, "push_N", where);
  s.push_by_energy = optional_field<double>(j, "push_by_energy_N", where);
  s.tip = read_vector(j, "tip_m", where);
  s.dent = field<double>(j, "dent_m", where);
  s.centreline = field_or<std::vector<double>>(j, "centreline_m", {}, where);
  if (s.centreline.size() % 3 != 0)
    throw InputError(where + ": centreline_m needs 3 numbers a point");
  s.newton_steps = field<int>(j, "newton_steps", where);
  s.seconds = field<double>(j, "seconds", where);
  return s;
}

/// The view, its arrays' sizes checked against each other and the entry's `steps`.
InsertionViewEntry read_insertion_view(const json& j, const std::string& where, std::size_t steps) {
  InsertionViewEntry v;
  v.step = field<int>(j, "step", where);
  v.nodes = field<std::vector<int>>(j, "nodes", where);
  v.rest = field<std::vector<double>>(j, "rest_m", where);
  v.displacement = field<std::vector<double>>(j, "displacement_m", where);
  v.force = field<std::vector<double>>(j, "force_N", where);
  v.triangles = field<std::vector<int>>(j, "triangles", where);
  const std::size_t n = v.nodes.size();
  const bool indices_fit = std::all_of(v.triangles.begin(), v.triangles.end(), [&](int i) {
    return i >= 0 && static_cast<std::size_t>(i) < n;
  });
  if (v.step < 0 || static_cast<std::size_t>(v.step) >= steps || v.rest.size() != 3 * n ||
      v.displacement.size() != 3 * n || v.force.size() != n || v.triangles.size() % 3 != 0 ||
      !indices_fit) {
    throw InputError(where +
                     ": expected a step among the steps, 3 numbers a node in rest_m and "
                     "displacement_m, one in force_N, and triangles of 3 indices into nodes");
  }
  return v;
}

InsertionEntry read_insertion_entry(const json& j, const std::string& where) {
  InsertionEntry e;
  e.scene = field<std::string>(j, "scene", where);
  e.wall = field<std::string>(j, "wall", where);
  e.model = field<std::string>(j, "model", where);
  e.model_detail = field<std::string>(j, "model_detail", where);
  e.bending_stiffness = field<double>(j, "bending_stiffness_Nm2", where);
  e.mesh_nodes = field<int>(j, "mesh_nodes", where);
  e.refined_balls = field<int>(j, "refined_balls", where);
  e.mesh_seconds = field<double>(j, "mesh_seconds", where);
  e.cached_from = field_or<std::string>(j, "cached_from", "", where);
  e.wire_radius = field_or<double>(j, "wire_radius_m", 0.0, where);
  e.steps = read_array(j, "steps", where, read_insertion_step);
  if (const auto v = j.find("view"); v != j.end()) {
    e.view = read_insertion_view(*v, where + ".view", e.steps.size());
  }
  return e;
}

}  // namespace

ValidityFile parse_validity(const std::string& text, const std::filesystem::path& source) {
  const std::string file = source.string();
  const json j = json_fields::parse_versioned(text, file, "vesselverify.validity", 1,
                                              "validity file", "vesselverify validity");
  ValidityFile v;
  v.path = source;
  v.command = field<std::string>(j, "command", file);
  v.full = field<bool>(j, "full", file);
  v.total_seconds = field<double>(j, "total_seconds", file);
  v.scenes = read_array(j, "scenes", file, read_validity_scene);
  return v;
}

ValidityFile read_validity(const std::filesystem::path& path) {
  return parse_validity(json_fields::read_text(path, "validity file"), path);
}

StabilityFile parse_stability(const std::string& text, const std::filesystem::path& source) {
  const std::string file = source.string();
  const json j = json_fields::parse_versioned(text, file, "vesselverify.stability", 1,
                                              "stability file", "vesselverify stability");
  StabilityFile s;
  s.path = source;
  s.command = field<std::string>(j, "command", file);
  s.quick = field<bool>(j, "quick", file);
  s.steps_per_trial = field<int>(j, "steps_per_trial", file);
  s.total_seconds = field<double>(j, "total_seconds", file);
  s.critical_steps = read_array(j, "critical_steps", file, read_step);
  s.refinement = read_array(j, "refinement", file, read_refinement);
  s.hard_cases = read_array(j, "hard_cases", file, read_hard_case);
  s.hard_cases_at_a_time = field_or<int>(j, "hard_cases_at_a_time", 1, file);
  if (const auto rod = j.find("rod_critical_steps"); rod != j.end() && !rod->is_null()) {
    const std::string where = file + ": rod_critical_steps";
    const json w = field<json>(*rod, "wire", where);
    s.rod_wire = RodWireEntry{
        field<double>(w, "length", where + ".wire"), field<double>(w, "diameter", where + ".wire"),
        field<double>(w, "young", where + ".wire"), field<double>(w, "shear", where + ".wire"),
        field<double>(w, "density", where + ".wire")};
    s.rod_steps = read_array(*rod, "rows", where, read_rod_step);
  }
  if (j.contains("tet_critical_steps")) {
    s.tet_steps = read_array(j, "tet_critical_steps", file, read_tet_step);
  }
  if (const auto t = j.find("timing_provenance"); t != j.end() && t->is_object()) {
    const std::string where = file + ": timing_provenance";
    s.timing_provenance =
        timing_provenance_line(field<std::size_t>(*t, "items", where),
                               field<std::vector<std::string>>(*t, "cached_measured_at", where));
  }
  return s;
}

StabilityFile read_stability(const std::filesystem::path& path) {
  return parse_stability(json_fields::read_text(path, "stability file"), path);
}

RecommendFile parse_recommend(const std::string& text, const std::filesystem::path& source) {
  const std::string file = source.string();
  const json j = json_fields::parse_versioned(text, file, "vesselverify.recommend", 1,
                                              "recommend file", "vesselverify recommend");
  RecommendFile r;
  r.path = source;
  r.command = field<std::string>(j, "command", file);
  r.scene = field<std::string>(j, "scene", file);
  r.model_levels = field<std::vector<int>>(j, "model_levels", file);
  r.reference_level = field<int>(j, "reference_level", file);
  const json budget = field<json>(j, "budget", file);
  const std::string where = file + ": budget";
  r.quantity = field<std::string>(budget, "quantity", where);
  r.unit = field<std::string>(budget, "unit", where);
  r.tolerance = field<double>(budget, "tolerance", where);
  r.seconds_per_update = field<double>(budget, "seconds_per_update", where);
  r.rate_hz = optional_field<double>(budget, "rate_hz", where);
  r.radius_mm = optional_field<double>(budget, "radius_mm", where);
  r.loads = read_array(j, "loads", file, read_load);
  r.recommended = optional_field<std::string>(j, "recommended", file);
  r.closest = optional_field<std::string>(j, "closest", file);
  r.whole_vessel = optional_field<std::string>(j, "whole_vessel", file);
  r.whole_vessel_reported = j.contains("whole_vessel");
  r.load_unit = field_or<std::string>(j, "load_unit", "", file);
  const auto results = optional_field<std::string>(j, "results", file);
  r.results = source.parent_path() / (results ? *results : std::string("results.json"));
  r.reference_contact_point_mm = field<double>(j, "reference_contact_point_mm", file);
  r.candidates = read_array(j, "candidates", file, read_candidate);
  if (const auto w = j.find("wire"); w != j.end() && !w->is_null()) {
    r.wire = read_wire(*w, file + ": wire");
  }
  if (const auto p = j.find("pairs"); p != j.end() && !p->is_null()) {
    r.pairs = read_pairs(*p, file + ": pairs");
  }
  return r;
}

RecommendFile read_recommend(const std::filesystem::path& path) {
  return parse_recommend(json_fields::read_text(path, "recommend file"), path);
}

CalibrateFile parse_calibrate(const std::string& text, const std::filesystem::path& source) {
  const std::string file = source.string();
  const json j = json_fields::parse_versioned(text, file, "vesselverify.calibrate", 1,
                                              "calibration study", "vesselverify calibrate");
  CalibrateFile c;
  c.path = source;
  c.command = field<std::string>(j, "command", file);
  c.calibration_file = field<std::string>(j, "calibration_file", file);
  c.scene = field<std::string>(j, "scene", file);
  const json model = field<json>(j, "model", file);
  const std::string mw = file + ": model";
  c.model = field<std::string>(model, "name", mw);
  c.model_detail = field<std::string>(model, "detail", mw);
  c.poisson_ratio = field<double>(model, "poisson_ratio", mw);
  c.vessel = field<std::string>(model, "vessel", mw);
  c.mesh_hash = field<std::string>(model, "mesh_hash", mw);
  c.nodes = field<std::size_t>(model, "nodes", mw);
  c.springs = field<std::size_t>(model, "springs", mw);
  const json fit = field<json>(j, "fit", file);
  const std::string fw = file + ": fit";
  c.granularity = field<std::string>(fit, "granularity", fw);
  c.method = field<std::string>(fit, "method", fw);
  c.iterations = field<int>(fit, "iterations", fw);
  c.stop_reason = field<std::string>(fit, "stop_reason", fw);
  c.fit_seconds = field<double>(fit, "seconds", fw);
  c.objective_before = field<double>(fit, "objective_before", fw);
  c.objective_after = field<double>(fit, "objective_after", fw);
  c.parameter_count = field<std::size_t>(fit, "parameter_count", fw);
  const json f = field<json>(fit, "factors", fw);
  c.factor_min = field<double>(f, "min", fw + ".factors");
  c.factor_median = field<double>(f, "median", fw + ".factors");
  c.factor_max = field<double>(f, "max", fw + ".factors");
  if (fit.contains("parameters")) c.parameters = read_array(fit, "parameters", fw, read_parameter);
  c.cases = read_array(j, "cases", file, read_calibration_case);
  return c;
}

CalibrateFile read_calibrate(const std::filesystem::path& path) {
  return parse_calibrate(json_fields::read_text(path, "calibration study"), path);
}

std::string validity_view_slot(const std::string& scene) { return "view:validity-" + scene; }

InsertionFile parse_insertion(const std::string& text, const std::filesystem::path& source) {
  const std::string file = source.string();
  const json j = json_fields::parse_versioned(text, file, "vesselverify.insertion", 1,
                                              "insertion file", "vesselverify insertion --json");
  InsertionFile f;
  f.path = source;
  f.command = field<std::string>(j, "command", file);
  f.total_seconds = field<double>(j, "total_seconds", file);
  f.insertions = read_array(j, "insertions", file, read_insertion_entry);
  return f;
}

InsertionFile read_insertion(const std::filesystem::path& path) {
  return parse_insertion(json_fields::read_text(path, "insertion file"), path);
}

}  // namespace vessel::reports
