// stability.json, and stability.md rendered from it by the report's section.
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "meshes/foundation/atomic_file.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "verification/studies/stability/stability.hpp"
#include "verification/studies/stability/study_models.hpp"

namespace vessel {

namespace {

nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
}

/// The guidewire's rows (rod_steps.hpp): the wire, then per model and integrator.
nlohmann::json rod_json(const StabilityReport& r) {
  const RodWire& w = r.rod_wire;
  nlohmann::json rows = nlohmann::json::array();
  for (const RodStepRow& row : r.rod_rows) {
    nlohmann::json bounded = nlohmann::json::array();
    for (const bool b : row.bounded) bounded.push_back(b);
    rows.push_back({{"model", row.model},
                    {"integrator", row.integrator},
                    {"segments", row.segments},
                    {"h", row.h},
                    {"axial_dt", row.axial_dt},
                    {"twist_dt", row.twist_dt},
                    {"bending_dt", row.bending_dt},
                    {"closed_form_dt", row.closed_form_dt},
                    {"omega_max", finite_or_null(row.omega_max)},
                    {"predicted_dt", finite_or_null(row.predicted_dt)},
                    {"found_dt", finite_or_null(row.found_dt)},
                    {"unstable_dt", finite_or_null(row.unstable_dt)},
                    {"found_over_closed_form", finite_or_null(row.found_dt / row.closed_form_dt)},
                    {"steps_tried", row.steps_tried},
                    {"bounded", bounded},
                    {"failure", row.failure},
                    {"steps_per_trial", row.steps_per_trial},
                    {"trials", row.trials},
                    {"seconds", row.seconds}});
  }
  return {{"wire",
           {{"length", w.length},
            {"diameter", w.diameter},
            {"young", w.young},
            {"shear", w.shear},
            {"density", w.density},
            {"segments", w.segments}}},
          {"rows", rows}};
}

/// Corotational P1's and XPBD FEM's rows (tet_steps.hpp).
nlohmann::json tet_json(const StabilityReport& r) {
  nlohmann::json rows = nlohmann::json::array();
  for (const TetStepRow& row : r.tet_rows) {
    nlohmann::json bounded = nlohmann::json::array();
    for (const bool b : row.bounded) bounded.push_back(b);
    rows.push_back({{"model", row.model},
                    {"integrator", row.integrator},
                    {"level", row.level},
                    {"nodes", row.nodes},
                    {"tets", row.tets},
                    {"nu", row.nu},
                    {"load", row.load},
                    {"omega_lanczos", finite_or_null(row.omega_lanczos)},
                    {"omega_power", finite_or_null(row.omega_power)},
                    {"predicted_dt", finite_or_null(row.predicted_dt)},
                    {"power_dt", finite_or_null(row.power_dt)},
                    {"found_dt", finite_or_null(row.found_dt)},
                    {"unstable_dt", finite_or_null(row.unstable_dt)},
                    {"found_over_predicted", finite_or_null(row.found_dt / row.predicted_dt)},
                    {"steps_tried", row.steps_tried},
                    {"bounded", bounded},
                    {"failure", row.failure},
                    {"steps_per_trial", row.steps_per_trial},
                    {"trials", row.trials},
                    {"seconds", row.seconds}});
  }
  return rows;
}

}  // namespace

std::string stability_json(const StabilityReport& r) {
  nlohmann::json j;
  j["schema"] = "vesselverify.stability";
  j["schema_version"] = 1;
  j["command"] = r.command_line;
  j["quick"] = r.quick;
  j["units"] = {{"time", "s"},
                {"length", "m"},
                {"angular_frequency", "rad/s"},
                {"damping", "N·s/m"},
                {"values", "SI unless the key ends in _mm"}};
  j["steps_per_trial"] = r.trial_steps;
  j["critical_steps"] = nlohmann::json::array();
  for (const auto& row : r.rows) {
    j["critical_steps"].push_back(
        {{"model", row.model},
         {"integrator", row.integrator},
         {"zeta", row.zeta},
         {"point_damping", row.point_damping},
         {"level", row.level},
         {"nodes", row.nodes},
         {"springs", row.springs},
         {"h_nominal", row.h_nominal},
         {"omega_max", row.omega_max},
         {"omega_gershgorin", row.omega_gershgorin},
         {"omega_min", row.omega_min},
         {"gamma_max", row.gamma_max},
         {"predicted_dt", row.predicted_dt},
         {"found_dt", row.found_dt},
         {"unstable_dt", row.unstable_dt},
         {"found_over_predicted", row.found_dt / row.predicted_dt},
         {"guaranteed_dt",
          std::isfinite(row.guaranteed_dt) ? nlohmann::json(row.guaranteed_dt) : nlohmann::json()},
         {"found_over_guaranteed", std::isfinite(row.guaranteed_dt) && row.guaranteed_dt > 0
                                       ? nlohmann::json(row.found_dt / row.guaranteed_dt)
                                       : nlohmann::json()},
         {"trials", row.trials},
         {"seconds", row.seconds}});
  }
  j["refinement"] = nlohmann::json::array();
  for (const auto& f : r.fits) {
    j["refinement"].push_back({{"model", f.model},
                               {"integrator", f.integrator},
                               {"zeta", f.zeta},
                               {"levels", f.levels},
                               {"found_exponent", f.exponent},
                               {"predicted_exponent", f.predicted_exponent}});
  }
  if (!r.rod_rows.empty()) j["rod_critical_steps"] = rod_json(r);
  if (!r.tet_rows.empty()) j["tet_critical_steps"] = tet_json(r);
  j["hard_cases"] = nlohmann::json::array();
  for (const auto& hc : r.hard_cases) {
    nlohmann::json c{{"id", hc.id},
                     {"title", hc.title},
                     {"setup", hc.setup},
                     {"seconds", hc.seconds},
                     {"outcomes", nlohmann::json::array()}};
    for (const auto& oc : hc.outcomes) {
      nlohmann::json v = nlohmann::json::object();
      for (const auto& [k, x] : oc.values)
        v[k] = std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
      c["outcomes"].push_back(
          {{"model", oc.model},
           {"finished", oc.finished},
           {"converged", oc.converged ? nlohmann::json(*oc.converged) : nlohmann::json()},
           {"bounded", oc.bounded ? nlohmann::json(*oc.bounded) : nlohmann::json()},
           {"reported", oc.reported},
           {"values", v}});
    }
    j["hard_cases"].push_back(c);
  }
  j["total_seconds"] = r.seconds;
  j["hard_cases_at_a_time"] = r.hard_cases_at_a_time;
  // Which timings (rows' and cases' seconds) were read from the outcome cache, and when measured.
  j["timing_provenance"] = {{"items", r.timed_items}, {"cached_measured_at", r.cached_at}};
  return j.dump(2) + "\n";
}

void write_stability(const std::filesystem::path& dir, const StabilityReport& report) {
  const std::string json = stability_json(report);
  // The Markdown is the report's section drawn from the document just written.
  const std::string md =
      reports::stability_markdown(reports::parse_stability(json, dir / "stability.json"));
  write_file_atomically(dir / "stability.json", [&](std::ostream& out) { out << json; });
  write_file_atomically(dir / "stability.md", [&](std::ostream& out) { out << md; });
}

}  // namespace vessel
