#include "verification/harness/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "meshes/vessel_geometry.hpp"

namespace vessel {

ErrorStatistics compare_displacements(const std::vector<Vec3>& model,
                                      const std::vector<Vec3>& reference) {
  if (model.size() != reference.size() || model.empty()) {
    throw std::invalid_argument("compare_displacements: " + std::to_string(model.size()) +
                                " model values vs " + std::to_string(reference.size()) +
                                " reference values; expected the same non-zero count");
  }
  ErrorStatistics s;
  s.points = model.size();
  const auto n = static_cast<double>(model.size());
  double sum = 0.0;
  double sum_sq = 0.0;
  double ref_sq = 0.0;
  double model_sq = 0.0;
  for (std::size_t i = 0; i < model.size(); ++i) {
    const double e = (model[i] - reference[i]).norm();
    s.max_mm = std::max(s.max_mm, e);
    sum += e;
    sum_sq += e * e;
    ref_sq += reference[i].squaredNorm();
    model_sq += model[i].squaredNorm();
  }
  const double mean = sum / n;
  constexpr double kMm = 1e3;
  s.max_mm *= kMm;
  s.mean_mm = mean * kMm;
  s.rms_mm = std::sqrt(sum_sq / n) * kMm;
  s.stddev_mm = std::sqrt(std::max(0.0, sum_sq / n - mean * mean)) * kMm;
  s.relative_l2 = ref_sq > 0.0 ? std::sqrt(sum_sq / ref_sq) : 0.0;
  s.model_l2_over_reference = ref_sq > 0.0 ? std::sqrt(model_sq / ref_sq) : 0.0;
  return s;
}

QuantityErrors quantity_errors(const Budget& budget, const std::vector<Vec3>& nodes,
                               const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref,
                               std::size_t qoi, const Vec3& qoi_point,
                               const std::vector<Vec3>& loads, const History& history) {
  QuantityErrors q;
  q.contact_point_mm = (u_model[qoi] - u_ref[qoi]).norm() * 1e3;
  if (!history.time_s.empty())
    q.contact_point_mm = std::max(q.contact_point_mm, history.max_error_mm);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    q.field_mm = std::max(q.field_mm, (u_model[i] - u_ref[i]).norm() * 1e3);
  }
  if (budget.quantity == BudgetQuantity::patch && budget.radius > 0.0) {
    double worst = 0.0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if ((nodes[i] - qoi_point).norm() <= budget.radius) {
        worst = std::max(worst, (u_model[i] - u_ref[i]).norm());
      }
    }
    q.patch_mm = worst * 1e3;
  }
  if (!loads.empty()) {
    // Work-conjugate indentation: the total contact force F does work F·d on the wall.
    Vec3 total = Vec3::Zero();
    double work_model = 0.0;
    double work_ref = 0.0;
    for (std::size_t i = 0; i < loads.size(); ++i) {
      total += loads[i];
      work_model += loads[i].dot(u_model[i]);
      work_ref += loads[i].dot(u_ref[i]);
    }
    const double force = total.norm();
    if (force > 0.0) {
      const double d_model = work_model / force;
      const double d_ref = work_ref / force;
      q.indentation_mm = d_model * 1e3;
      q.indentation_reference_mm = d_ref * 1e3;
      q.reaction_mN = d_model > 0.0 ? force * std::abs(d_ref - d_model) / d_model * 1e3
                                    : std::numeric_limits<double>::infinity();
    }
  }
  return q;
}

double budget_quantity_error(const QuantityErrors& q, BudgetQuantity quantity) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  switch (quantity) {
    case BudgetQuantity::contact_point:
      return q.contact_point_mm;
    case BudgetQuantity::field:
      return q.field_mm;
    case BudgetQuantity::patch:
      return q.patch_mm.value_or(nan);
    case BudgetQuantity::reaction:
      return q.reaction_mN.value_or(nan);
    case BudgetQuantity::contact_force:  // from the contact solve (the harness sets it after)
      return nan;
  }
  return nan;
}

std::vector<std::size_t> wall_line(const VesselParams& v, int level,
                                   const std::vector<Vec3>& nodes, const Vec3& qoi) {
  const CentrelineCoordinates q = centreline_coordinates(v, qoi);
  const double cell = v.wall_thickness / static_cast<double>(1 << level);
  std::vector<std::size_t> on_line;
  std::vector<CentrelineCoordinates> c(nodes.size());
  double nearest_radius = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    c[i] = centreline_coordinates(v, nodes[i]);
    const double dtheta = std::remainder(c[i].theta - q.theta, 2.0 * std::numbers::pi);
    if (std::abs(dtheta) * q.rho > cell / 3.0) continue;
    on_line.push_back(i);
    nearest_radius = std::min(nearest_radius, std::abs(c[i].rho - q.rho));
  }
  std::erase_if(on_line, [&](std::size_t i) {
    return std::abs(c[i].rho - q.rho) > nearest_radius + 0.1 * cell;
  });
  std::sort(on_line.begin(), on_line.end(), [&](std::size_t a, std::size_t b) { return c[a].s < c[b].s; });
  return on_line;
}

WallProfile wall_profile(const VesselParams& v, const std::vector<Vec3>& nodes,
                         const std::vector<std::size_t>& line, const std::vector<Vec3>& u_model,
                         const std::vector<Vec3>& u_ref) {
  WallProfile p;
  for (const std::size_t i : line) {
    const CentrelineCoordinates c = centreline_coordinates(v, nodes[i]);
    p.s_mm.push_back(c.s * 1e3);
    p.model_mm.push_back(u_model[i].dot(c.e_rho) * 1e3);
    p.reference_mm.push_back(u_ref[i].dot(c.e_rho) * 1e3);
  }
  return p;
}

double largest_edge_strain(const std::vector<Vec3>& nodes, const VtuCells& cells,
                           const std::vector<Vec3>& u) {
  const auto per = static_cast<std::size_t>(cells.points_per_cell);
  double worst = 0.0;
  for (std::size_t c = 0; c + per <= cells.connectivity.size(); c += per) {
    for (std::size_t i = 0; i < per; ++i) {
      for (std::size_t j = i + 1; j < per; ++j) {
        const std::size_t a = cells.connectivity[c + i], b = cells.connectivity[c + j];
        const double rest = (nodes[b] - nodes[a]).norm();
        const double now = (nodes[b] + u[b] - nodes[a] - u[a]).norm();
        if (rest > 0.0) worst = std::max(worst, std::abs(now - rest) / rest);
      }
    }
  }
  return worst;
}

std::vector<double> frequency_ratios(const ModalOutcome& model, const ModalOutcome& reference) {
  std::vector<double> r;
  if (!model.ok || !reference.ok) return r;
  const std::size_t n = std::min(model.frequencies_hz.size(), reference.frequencies_hz.size());
  for (std::size_t k = 0; k < n; ++k) {
    const double f = reference.frequencies_hz[k];
    r.push_back(f > 0.0 ? model.frequencies_hz[k] / f : 0.0);
  }
  return r;
}

}  // namespace vessel
