#include "verification/fem_document.hpp"

#include <algorithm>
#include <iomanip>
#include <nlohmann/json.hpp>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/vtu_io.hpp"

namespace vessel {

namespace {

nlohmann::json json_vec(const Vec3& v, double scale) {
  return nlohmann::json::array({v.x() * scale, v.y() * scale, v.z() * scale});
}

nlohmann::json contact_json(const ContactRecord& c) {
  return {{"point_mm", json_vec(c.point, 1e3)},
          {"inward_normal", json_vec(c.inward_normal, 1.0)},
          {"radius_mm", c.radius * 1e3},
          {"force_mN", c.force * 1e3},
          {"patch_area_mm2", c.patch_area * 1e6},
          {"patch_triangles", c.patch_triangles},
          {"displacement_mm", json_vec(c.displacement, 1e3)}};
}

nlohmann::json richardson_json(const RichardsonRecord& r) {
  return {{"coarse_level", r.coarse_level},
          {"coarse_dofs", r.coarse_dofs},
          {"order", r.value.order},
          {"direction", json_vec(r.direction, 1.0)},
          {"u_coarse_mm", r.value.u_coarse * 1e3},
          {"u_fine_mm", r.value.u_fine * 1e3},
          {"extrapolated_mm", r.value.estimate.extrapolated * 1e3},
          {"error_fine_mm", r.value.estimate.error_fine * 1e3},
          {"gci_fine", r.value.estimate.gci_fine}};
}

nlohmann::json transient_json(const fem::TransientOptions& o, const fem::TransientResult& t) {
  return {{"dt_s", o.dt},
          {"steps", o.steps},
          {"mass_damping_per_s", o.mass_damping},
          {"probe_mm", json_vec(o.probe_points.at(0), 1e3)},
          {"final_probe_displacement_mm", json_vec(t.probe_displacement.back()[0], 1e3)},
          {"setup_seconds", t.setup_seconds},
          {"seconds_per_step", t.seconds_per_step}};
}

/// The parts every run has: set-up, element, solver, results, timings.
nlohmann::json core_json(const FemRunRecord& run) {
  const fem::ElasticityResult& r = run.result;
  nlohmann::json reactions = nlohmann::json::array();
  for (const auto& g : r.reactions) {
    reactions.push_back({{"group", g.group}, {"force_mN", json_vec(g.force, 1e3)}});
  }
  return {{"schema", "vesselverify.fem"},
          {"schema_version", 1},
          {"units", {{"length", "mm"}, {"force", "mN"}, {"energy", "mJ"}, {"time", "s"}}},
          {"vessel", describe(run.vessel)},
          {"mesh", {{"nodes", run.mesh_nodes}, {"tets", run.mesh_tets}, {"cache_hit", run.cache_hit}}},
          {"material",
           {{"E_Pa", run.youngs_modulus}, {"nu", run.poisson_ratio}, {"density_kg_m3", run.density}}},
          {"loads", run.loads},
          {"ends", run.ends},
          {"element", r.element},
          {"curved", r.curved},
          {"formulation", fem::to_string(r.formulation)},
          {"solver", fem::to_string(r.solver)},
          {"cg_iterations", r.iterations},  // CG or FGMRES, by "solver"
          {"inner_iterations", r.inner_iterations},
          {"dofs", r.n_dofs},
          {"pressure_dofs", r.n_pressure_dofs},
          {"max_displacement_mm", run.max_displacement() * 1e3},
          {"strain_energy_mJ", r.strain_energy * 1e3},
          {"max_principal_strain", r.max_principal_strain},
          {"max_abs_principal_strain", r.max_abs_principal_strain},
          {"applied_load_mN", json_vec(r.applied_load, 1e3)},
          {"reactions", reactions},
          {"timings_s",
           {{"mesh", run.mesh_seconds},
            {"setup", r.timings.setup},
            {"assembly", r.timings.assembly},
            {"solve", r.timings.solve},
            {"postprocess", r.timings.postprocess},
            {"output", run.output_seconds}}}};
}

}  // namespace

double FemRunRecord::max_displacement() const {
  double m = 0.0;
  for (const auto& u : result.nodal_displacement) m = std::max(m, u.norm());
  return m;
}

std::string fem_json(const FemRunRecord& run) {
  nlohmann::json j = core_json(run);
  if (run.lame_error) j["lame_relative_l2_error"] = *run.lame_error;
  if (run.modal) {
    j["modal"] = {{"frequencies_hz", run.modal->frequencies_hz},
                  {"dofs", run.modal->n_dofs},
                  {"seconds", run.modal->seconds}};
  }
  if (run.richardson) j["richardson"] = richardson_json(*run.richardson);
  if (run.transient && run.transient_options) {
    j["transient"] = transient_json(*run.transient_options, *run.transient);
  }
  if (run.distributed) {
    j["distributed"] = {{"mpi_ranks", run.distributed->ranks},
                        {"tets_per_rank", run.distributed->tets_per_rank},
                        {"dofs_per_rank", run.distributed->dofs_per_rank},
                        {"local_tets_per_rank", run.distributed->local_tets_per_rank},
                        {"peak_memory_mb_per_rank", run.distributed->peak_memory_mb_per_rank}};
  }
  if (run.contact) j["contact"] = contact_json(*run.contact);
  return j.dump(2) + "\n";
}

void write_fem_json(const std::filesystem::path& path, const FemRunRecord& run) {
  const std::string text = fem_json(run);
  write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

std::string finite_strain_json(const FemRunRecord& run, const fem::HyperelasticResult& r) {
  double max_u = 0.0;
  for (const auto& u : r.nodal_displacement) max_u = std::max(max_u, u.norm());
  nlohmann::json j{
      {"schema", "vesselverify.fem_finite_strain"},
      {"schema_version", 1},
      {"units", {{"length", "mm"}, {"force", "mN"}, {"energy", "mJ"}, {"time", "s"}}},
      {"vessel", describe(run.vessel)},
      {"mesh", {{"nodes", run.mesh_nodes}, {"tets", run.mesh_tets}, {"cache_hit", run.cache_hit}}},
      {"material",
       {{"E_Pa", run.youngs_modulus}, {"nu", run.poisson_ratio}, {"density_kg_m3", run.density}}},
      {"loads", run.loads},
      {"ends", run.ends},
      {"reference", "finite-strain (compressible neo-Hookean)"},
      {"element", r.element},
      {"formulation", fem::to_string(r.formulation)},
      {"solver", fem::to_string(r.solver)},
      {"dofs", r.n_dofs},
      {"load_factor", r.load_factor},
      {"completed", r.completed},
      {"stop_reason", r.stop_reason},
      {"load_steps", r.steps.size()},
      {"rejected_steps", r.rejected_steps},
      {"newton_iterations", r.newton_iterations},
      {"max_displacement_mm", max_u * 1e3},
      {"strain_energy_mJ", r.strain_energy * 1e3},
      {"max_abs_principal_green_lagrange_strain", r.max_abs_principal_strain},
      {"min_jacobian", r.min_jacobian},
      {"timings_s",
       {{"mesh", run.mesh_seconds}, {"setup", r.timings.setup}, {"assembly", r.timings.assembly},
        {"solve", r.timings.solve}, {"postprocess", r.timings.postprocess}}}};
  if (run.contact) j["contact"] = contact_json(*run.contact);
  if (const auto& q = run.finite_strain_qoi) {
    const auto mm3 = [](const Vec3& v) {
      return std::vector<double>{v.x() * 1e3, v.y() * 1e3, v.z() * 1e3};
    };
    j["qoi"] = {{"point_mm", mm3(q->point)},
                {"direction", {q->direction.x(), q->direction.y(), q->direction.z()}},
                {"displacement_mm", mm3(q->displacement)},
                {"along_mm", q->displacement.dot(q->direction) * 1e3},
                {"linear_along_mm", q->linear_displacement.dot(q->direction) * 1e3}};
  }
  return j.dump(2) + "\n";
}

void write_finite_strain_json(const std::filesystem::path& path, const FemRunRecord& run,
                              const fem::HyperelasticResult& result) {
  const std::string text = finite_strain_json(run, result);
  write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

void write_fem_vtu(const std::filesystem::path& path, const TetMesh& mesh,
                   const FemRunRecord& run) {
  const fem::ElasticityResult& r = run.result;
  VtuField disp{"displacement", 3, {}}, strain{"strain", 6, {}}, stress{"stress", 6, {}};
  for (const auto& u : r.nodal_displacement) disp.values.insert(disp.values.end(), {u.x(), u.y(), u.z()});
  for (const auto& e : r.tet_strain) strain.values.insert(strain.values.end(), e.begin(), e.end());
  for (const auto& s : r.tet_stress) stress.values.insert(stress.values.end(), s.begin(), s.end());
  std::vector<VtuField> point_fields{disp};
  if (run.modal) {
    for (std::size_t k = 0; k < run.modal->mode_shapes.size(); ++k) {
      VtuField mode{"mode_" + std::to_string(k + 1), 3, {}};
      for (const auto& u : run.modal->mode_shapes[k]) {
        mode.values.insert(mode.values.end(), {u.x(), u.y(), u.z()});
      }
      point_fields.push_back(std::move(mode));
    }
  }
  std::vector<VtuField> cell_fields;
  if (!r.tet_strain.empty()) cell_fields = {strain, stress};  // the distributed solve has none
  write_vtu(path, mesh, point_fields, cell_fields);
}

void write_transient_csv(const std::filesystem::path& path, const fem::TransientResult& t) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "t_s,ux_mm,uy_mm,uz_mm,kinetic_energy_mJ,strain_energy_mJ,load_work_mJ\n";
    out << std::setprecision(12);
    for (std::size_t n = 0; n < t.time.size(); ++n) {
      const Vec3& u = t.probe_displacement[n][0];
      out << t.time[n] << "," << u.x() * 1e3 << "," << u.y() * 1e3 << "," << u.z() * 1e3 << ","
          << t.kinetic_energy[n] * 1e3 << "," << t.strain_energy[n] * 1e3 << ","
          << t.load_work[n] * 1e3 << "\n";
    }
  });
}

}  // namespace vessel
