#include "verification/msm_document.hpp"

#include <nlohmann/json.hpp>

#include "meshes/foundation/atomic_file.hpp"

namespace vessel {

namespace {

nlohmann::json json_vec(const Vec3& v, double scale) {
  return nlohmann::json::array({v.x() * scale, v.y() * scale, v.z() * scale});
}

/// What the solver did, by family.
nlohmann::json solver_json(const std::string& name, const msm::SolveResult& s) {
  nlohmann::json j{{"name", name}, {"seconds", s.seconds}};
  if (const auto* r = std::get_if<msm::StaticResult>(&s.detail)) {
    j.update({{"iterations", r->iterations},
              {"residual_N", r->residual},
              {"numeric_factorisations", r->numeric_factorisations},
              {"factorisation_seconds", r->factorisation_seconds},
              {"indefinite_iterations", r->indefinite_iterations},
              {"negative_curvature_steps", r->negative_curvature_steps}});
  } else if (const auto* rel = std::get_if<msm::RelaxationResult>(&s.detail)) {
    j.update({{"steps", rel->steps}, {"dt", rel->dt}, {"residual_N", rel->residual}});
  } else if (const auto* dyn = std::get_if<msm::DynamicResult>(&s.detail)) {
    j.update({{"steps", dyn->steps},
              {"dt", s.dt},
              {"seconds_per_step", dyn->seconds / std::max(1, dyn->steps)},
              {"setup_seconds", dyn->setup_seconds},
              {"numeric_factorisations", dyn->numeric_factorisations},
              {"energy_J", dyn->energy}});
  } else if (const auto* pbd = std::get_if<msm::PbdResult>(&s.detail)) {
    j.update({{"steps", pbd->steps},
              {"dt", s.dt},
              {"seconds_per_step", pbd->seconds / std::max(1, pbd->steps)},
              {"max_stretch_violation_mm", pbd->max_violation * 1e3}});
  }
  return j;
}

}  // namespace

std::string msm_json(const MsmRunRecord& run) {
  nlohmann::json springs = nlohmann::json::object();
  for (const auto& [family, count] : run.springs) springs[family] = count;
  nlohmann::json j{{"schema", "vesselverify.msm_result"},
                   {"schema_version", 1},
                   {"units", {{"length", "mm"}, {"time", "s"}, {"force", "mN"}}},
                   {"vessel", describe(run.vessel)},
                   {"model", run.model},
                   {"topology", run.topology},
                   {"stiffness_rule", run.stiffness_rule},
                   {"mass_rule", run.mass_rule},
                   {"nodes", run.nodes},
                   {"springs", springs},
                   {"force_mN", run.contact ? run.contact->force * 1e3 : 0.0},
                   {"build_seconds", run.build_seconds},
                   {"solver", solver_json(run.solver, run.solve)},
                   {"max_displacement_mm", run.max_displacement * 1e3},
                   {"max_spring_strain", run.max_spring_strain},
                   {"total_seconds", run.total_seconds}};
  if (run.model == "surface") j["surface"] = run.surface;
  if (!run.input.empty()) j["input"] = run.input;
  if (run.contact) {
    const ContactRecord& c = *run.contact;
    j["contact"] = {{"point_mm", json_vec(c.point, 1e3)},
                    {"inward_normal", json_vec(c.inward_normal, 1.0)},
                    {"radius_mm", c.radius * 1e3},
                    {"patch_area_mm2", c.patch_area * 1e6},
                    {"patch_triangles", c.patch_triangles}};
    j["contact_displacement_mm"] = c.displacement.norm() * 1e3;
    j["contact_displacement_along_load_mm"] = c.displacement.dot(c.inward_normal) * 1e3;
  }
  return j.dump(2) + "\n";
}

void write_msm_json(const std::filesystem::path& path, const MsmRunRecord& run) {
  const std::string text = msm_json(run);
  write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace vessel
