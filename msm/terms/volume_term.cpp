#include "msm/terms/volume_term.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/four_node_blocks.hpp"

namespace vessel::msm {

namespace {

/// [a]×: the matrix of a × ·.
Eigen::Matrix3d cross_matrix(const Vec3& a) {
  Eigen::Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

}  // namespace

double tet_signed_volume(const std::array<Vec3, 4>& x) {
  return (x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0])) / 6.0;
}

Vec12 tet_volume_gradient(const std::array<Vec3, 4>& x) {
  // V = e1·(e2 × e3)/6 with e_i = x_i − x0: ∂V/∂e1 = e2×e3/6 (cyclic), ∂V/∂x0 = −Σ ∂V/∂e_i.
  const Vec3 e1 = x[1] - x[0], e2 = x[2] - x[0], e3 = x[3] - x[0];
  Vec12 g;
  g.segment<3>(3) = e2.cross(e3) / 6.0;
  g.segment<3>(6) = e3.cross(e1) / 6.0;
  g.segment<3>(9) = e1.cross(e2) / 6.0;
  g.segment<3>(0) = -(g.segment<3>(3) + g.segment<3>(6) + g.segment<3>(9));
  return g;
}

Mat12 tet_volume_hessian(const std::array<Vec3, 4>& x) {
  // In the edge vectors: ∂²V/∂e_i∂e_j = −[e_k]×/6 for (i, j, k) cyclic, +[e_k]×/6 anti-cyclic,
  // zero for i = j. Then x0's blocks by e_i = x_i − x0 (row and column sums with a minus sign).
  const std::array<Vec3, 3> e{x[1] - x[0], x[2] - x[0], x[3] - x[0]};
  Eigen::Matrix<double, 9, 9> He = Eigen::Matrix<double, 9, 9>::Zero();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const Eigen::Matrix3d c = cross_matrix(e[k]) / 6.0;
    He.block<3, 3>(3 * i, 3 * j) = -c;
    He.block<3, 3>(3 * j, 3 * i) = c;
  }
  Eigen::Matrix<double, 9, 12> T = Eigen::Matrix<double, 9, 12>::Zero();
  for (int i = 0; i < 3; ++i) {
    T.block<3, 3>(3 * i, 0) = -Eigen::Matrix3d::Identity();
    T.block<3, 3>(3 * i, 3 * (i + 1)) = Eigen::Matrix3d::Identity();
  }
  return T.transpose() * He * T;
}

double volume_energy(const std::array<Vec3, 4>& x, double rest_volume, double kappa) {
  const double dv = tet_signed_volume(x) - rest_volume;
  return 0.5 * kappa * dv * dv / std::abs(rest_volume);  // ½κV₀(V/V₀ − 1)²
}

Vec12 volume_gradient(const std::array<Vec3, 4>& x, double rest_volume, double kappa) {
  const double dv = tet_signed_volume(x) - rest_volume;
  return kappa * dv / std::abs(rest_volume) * tet_volume_gradient(x);
}

Mat12 volume_hessian(const std::array<Vec3, 4>& x, double rest_volume, double kappa,
                     bool project_psd) {
  const double v0 = std::abs(rest_volume);
  const double dv = tet_signed_volume(x) - rest_volume;
  const Vec12 gv = tet_volume_gradient(x);
  Mat12 H = kappa / v0 * gv * gv.transpose();
  if (dv != 0.0) H += kappa * dv / v0 * tet_volume_hessian(x);
  if (!project_psd) return H;
  return psd_projection(H);
}

VolumeTerm::VolumeTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, double kappa,
                       std::vector<double> tet_factors)
    : FourNodeTerm(static_cast<int>(nodes.size())),
      kappa_(kappa),
      tet_factors_(std::move(tet_factors)) {
  if (!std::isfinite(kappa)) {
    throw InputError("volume term: expected a finite bulk stiffness κ (Pa), got " +
                     std::to_string(kappa));
  }
  if (!tet_factors_.empty() && tet_factors_.size() != tets.size()) {
    throw InputError("volume term: expected one κ factor per tet (" + std::to_string(tets.size()) +
                     "), got " + std::to_string(tet_factors_.size()));
  }
  for (double f : tet_factors_) {
    if (!std::isfinite(f)) {
      throw InputError("volume term: expected finite per-tet κ factors, got " + std::to_string(f));
    }
  }
  const int num_nodes = static_cast<int>(nodes.size());
  rest_volumes_.reserve(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e) {
    const Tet& tet = tets[e];
    for (int v : tet) {
      if (v < 0 || v >= num_nodes) {
        throw InputError("volume term: tet " + std::to_string(e) + " refers to node " +
                         std::to_string(v) + ", expected an index below " +
                         std::to_string(num_nodes));
      }
    }
    const double v0 =
        tet_signed_volume({nodes[tet[0]], nodes[tet[1]], nodes[tet[2]], nodes[tet[3]]});
    if (!(std::abs(v0) > 0.0)) {
      throw InputError("volume term: tet " + std::to_string(e) +
                       " has zero rest volume; expected a non-degenerate tetrahedron");
    }
    rest_volumes_.push_back(v0);
  }
  set_elements(std::move(tets));
}

double VolumeTerm::element_energy(std::size_t k, const std::array<Vec3, 4>& x) const {
  return volume_energy(x, rest_volumes_[k], tet_kappa(k));
}

Vec12 VolumeTerm::element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const {
  return volume_gradient(x, rest_volumes_[k], tet_kappa(k));
}

Mat12 VolumeTerm::element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                  bool project_psd) const {
  return volume_hessian(x, rest_volumes_[k], tet_kappa(k), project_psd);
}

}  // namespace vessel::msm
