// The calibration study's JSON document (calibrate.schema.json), which the report renders.
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/studies/calibrate/calibrate.hpp"

namespace vessel {

namespace {

const char* load_unit(LoadKind kind) {
  return kind == LoadKind::contact ? "N" : kind == LoadKind::pressure ? "Pa" : "g";
}

nlohmann::json case_json(const CalibrationCaseResult& c) {
  nlohmann::json j{{"scene", c.scene},
                   {"name", c.name},
                   {"training", c.training},
                   {"holds_out", c.holds_out},
                   {"load_kind", to_string(c.kind)},
                   {"load_unit", load_unit(c.kind)},
                   {"magnitude", c.magnitude},
                   {"level", c.level},
                   {"p1_relative_l2", c.p1.relative_l2},
                   {"p1_solve_seconds", c.p1_solve_seconds},
                   {"max_strain_reference", c.max_strain_reference}};
  if (c.kind == LoadKind::contact) j["point"] = {c.point.x(), c.point.y(), c.point.z()};
  if (c.base_ok) {
    j["base_relative_l2"] = c.base.relative_l2;
    j["base_update_seconds"] = c.base_update_seconds;
  } else {
    j["base_failure"] = c.base_failure;
  }
  if (c.ok) {
    j["calibrated_relative_l2"] = c.calibrated.relative_l2;
    j["calibrated_update_seconds"] = c.calibrated_update_seconds;
  } else {
    j["failure"] = c.failure;
  }
  return j;
}

nlohmann::json fit_json(const CalibrationStudy& study) {
  const Calibration& c = study.calibration;
  if (c.factors.empty()) throw std::logic_error("calibration_study_json: a fit without factors");
  std::vector<double> sorted = c.factors;
  std::sort(sorted.begin(), sorted.end());
  nlohmann::json fit{{"granularity", c.granularity},
                     {"method", c.method},
                     {"iterations", c.iterations},
                     {"stop_reason", c.stop_reason},
                     {"seconds", study.fit_seconds},
                     {"objective_before", c.objective_before},
                     {"objective_after", c.objective_after},
                     {"parameter_count", c.names.size()},
                     {"factors",
                      {{"min", sorted.front()},
                       {"median", sorted[sorted.size() / 2]},
                       {"max", sorted.back()}}}};
  // Per-spring factors are many and indexed by the mesh's springs: the calibration file has them.
  if (c.granularity != "per_spring" && c.granularity != "per_section_spring") {
    nlohmann::json params = nlohmann::json::array();
    for (std::size_t i = 0; i < c.names.size(); ++i) {
      params.push_back({{"name", c.names[i]}, {"factor", c.factors[i]}});
    }
    fit["parameters"] = params;
  }
  return fit;
}

}  // namespace

std::string calibration_study_json(const CalibrationStudy& study, const std::string& command,
                                   const std::string& calibration_file) {
  const Calibration& c = study.calibration;
  nlohmann::json cases = nlohmann::json::array();
  for (const CalibrationCaseResult& cs : study.cases) cases.push_back(case_json(cs));
  const nlohmann::json j{{"schema", "vesselverify.calibrate"},
                         {"schema_version", 1},
                         {"command", command},
                         {"calibration_file", calibration_file},
                         {"scene", c.scene},
                         {"model",
                          {{"name", c.model},
                           {"detail", study.model_detail},
                           {"poisson_ratio", c.poisson_ratio},
                           {"level", c.level},
                           {"vessel", c.vessel},
                           {"mesh_hash", c.mesh_hash},
                           {"nodes", c.nodes},
                           {"springs", c.springs}}},
                         {"fit", fit_json(study)},
                         {"cases", cases}};
  return j.dump(2) + "\n";
}

void write_calibration_study(const std::filesystem::path& path, const CalibrationStudy& study,
                             const std::string& command, const std::string& calibration_file) {
  const std::string text = calibration_study_json(study, command, calibration_file);
  write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace vessel
