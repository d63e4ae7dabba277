#include "verification/harness/model_readout.hpp"

#include <algorithm>
#include <sstream>
#include <tuple>

#include "meshes/tet_locator.hpp"
#include "reports/representative_load.hpp"
#include "verification/harness/budget.hpp"
#include "verification/harness/external_model.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

std::vector<Vec3> scaled(const std::vector<Vec3>& u, double factor) {
  std::vector<Vec3> out(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) out[i] = factor * u[i];
  return out;
}

std::size_t free_unknowns(const msm::Problem& p) {
  return static_cast<std::size_t>(std::count(p.fixed.begin(), p.fixed.end(), 0));
}

std::vector<Vec3> per_node(const Eigen::VectorXd& v) {
  std::vector<Vec3> out(static_cast<std::size_t>(v.size() / 3));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = v.segment<3>(3 * static_cast<Eigen::Index>(i));
  }
  return out;
}

std::vector<Vec3> displacements(const Eigen::VectorXd& x, const std::vector<Vec3>& nodes) {
  std::vector<Vec3> u = per_node(x);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] -= nodes[i];
  return u;
}

ReadOut read_out(const Scene& s, int level, const std::vector<Vec3>& nodes, const Vec3& qoi) {
  // A vessel from a file has no centreline to run a wall line along: no wall profile.
  if (!s.vessel.parametric()) return {nearest_node(nodes, qoi), {}};
  return {nearest_node(nodes, qoi), wall_line(s.vessel, level, nodes, qoi)};
}

void finish_outcome(ModelOutcome& out, const Scene& s, const std::vector<Vec3>& nodes,
                    const std::vector<Vec3>& u_model, const ReferenceAtPoints& ref,
                    double magnitude, const ReadOut& at, double ref_max_strain_unit,
                    const Vec3& qoi_point, const std::vector<Vec3>& loads, long steps, double dt) {
  const std::vector<Vec3> u_ref = scaled(ref.u, magnitude);
  const std::size_t qoi = at.qoi;
  out.quantities =
      quantity_errors(s.budget, nodes, u_model, u_ref, qoi, qoi_point, loads, out.history);
  if (s.budget.stated) {
    out.budget_error = budget_quantity_error(out.quantities, s.budget.quantity);
    std::tie(out.update_seconds, out.steps_per_update) =
        time_per_update(out.solve_seconds, steps, dt, s.budget.update_period());
  }
  out.wall_profile = wall_profile(s.vessel, nodes, at.wall_line, u_model, u_ref);
  out.error = compare_displacements(u_model, u_ref);
  out.has_reference_uncertainty = ref.has_uncertainty;
  if (ref.has_uncertainty) {
    out.reference_uncertainty.max_mm = ref.uncertainty.max_error * magnitude * 1e3;
    out.reference_uncertainty.rms_mm = ref.uncertainty.rms_error * magnitude * 1e3;
    out.reference_uncertainty.relative_l2 = ref.uncertainty.relative_l2;
  }
  out.qoi_displacement_mm = u_model[qoi].norm() * 1e3;
  out.qoi_reference_mm = u_ref[qoi].norm() * 1e3;
  out.beyond_linear_regime = ref_max_strain_unit * magnitude > kLinearRegimeStrain;
  out.ok = true;
}

bool wants_fields(const HarnessOptions& o, const Scene& s, double magnitude,
                  double ref_max_strain_unit) {
  if (o.fields_dir.empty()) return false;
  if (o.fields_every_load) return true;
  Scene without_budget_load = s;
  const auto& m = s.load.magnitudes;
  if (std::find(m.begin(), m.end(), s.budget.magnitude) == m.end()) {
    without_budget_load.budget.magnitude = 0.0;
  }
  return magnitude == budget_magnitude(without_budget_load, ref_max_strain_unit);
}

std::filesystem::path fields_file(const Scene& s, const ModelOutcome& out) {
  std::ostringstream name;
  name << file_stem(out.model) << "_nu" << out.poisson_ratio << "_L" << out.level << "_load"
       << out.magnitude << ".vtu";
  return std::filesystem::path(s.name) / name.str();
}

void write_model_fields(const HarnessOptions& o, const Scene& s, const ModelOutcome& out,
                        const std::vector<Vec3>& nodes, const VtuCells& cells,
                        const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref) {
  write_fields_vtu(o.fields_dir / fields_file(s, out), nodes, cells, u_model, u_ref);
}

void write_fields_vtu(const std::filesystem::path& path, const std::vector<Vec3>& nodes,
                      const VtuCells& cells, const std::vector<Vec3>& u_model,
                      const std::vector<Vec3>& u_ref) {
  VtuField model{"displacement_model_m", 3, {}};
  VtuField reference{"displacement_reference_m", 3, {}};
  VtuField error{"error_m", 3, {}};
  VtuField error_mm{"error_magnitude_mm", 1, {}};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Vec3 e = u_model[i] - u_ref[i];
    for (int c = 0; c < 3; ++c) {
      model.values.push_back(u_model[i][c]);
      reference.values.push_back(u_ref[i][c]);
      error.values.push_back(e[c]);
    }
    error_mm.values.push_back(e.norm() * 1e3);
  }
  std::filesystem::create_directories(path.parent_path());
  write_vtu(path, nodes, cells, {model, reference, error, error_mm});
}

VtuCells network_cells(const msm::SpringNetwork& n) {
  if (!n.tets.empty()) return tet_cells(n.tets);
  VtuCells cells;
  if (!n.triangles.empty()) {
    cells = {5, 3, {}};
    for (const auto& t : n.triangles) {
      for (const int v : t) cells.connectivity.push_back(static_cast<std::size_t>(v));
    }
  } else {
    cells = {3, 2, {}};
    for (const auto& sp : n.springs) {
      cells.connectivity.push_back(static_cast<std::size_t>(sp.a));
      cells.connectivity.push_back(static_cast<std::size_t>(sp.b));
    }
  }
  return cells;
}

}  // namespace vessel
