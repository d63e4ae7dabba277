#include "msm/model/edge_pair_term.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "meshes/errors.hpp"
#include "msm/model/volume_term.hpp"

namespace vessel::msm {

LameParameters lame_parameters(double E, double nu) {
  if (!(E > 0) || !std::isfinite(E)) {
    throw InputError("edge pairs (StVK): expected Young's modulus E > 0 Pa, got " +
                     std::to_string(E));
  }
  if (!(nu >= 0.0 && nu < 0.5)) {
    throw InputError("edge pairs (StVK): poisson_ratio ν must be in [0, 0.5), got " +
                     std::to_string(nu) +
                     (nu >= 0.5 ? "; at ν = 0.5 λ is infinite (displacement-only P1 FEM, which "
                                  "this model equals, cannot represent incompressibility)"
                                : ""));
  }
  return {E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))};
}

Mat6 edge_pair_coefficients(const std::array<Vec3, 4>& X, const LameParameters& lame) {
  const double v0 = std::abs(tet_signed_volume(X));
  if (!(v0 > 0.0)) {
    throw InputError("edge pairs: a tet has zero rest volume; expected a non-degenerate tetrahedron");
  }
  Mat6 A;  // δ_k = A_k·e, e = (E11, E22, E33, E23, E13, E12)
  for (int k = 0; k < 6; ++k) {
    const Vec3 D = X[kTetEdges[k][1]] - X[kTetEdges[k][0]];
    A.row(k) << D.x() * D.x(), D.y() * D.y(), D.z() * D.z(), 2 * D.y() * D.z(),
        2 * D.x() * D.z(), 2 * D.x() * D.y();
  }
  Mat6 S = Mat6::Zero();  // W/V₀ = ½ eᵀ S e
  S.topLeftCorner<3, 3>().setConstant(lame.lambda);
  S.diagonal() += 2 * lame.mu * (Vec6() << 1, 1, 1, 2, 2, 2).finished();
  const Mat6 A_inv = A.partialPivLu().inverse();
  Mat6 C = v0 * A_inv.transpose() * S * A_inv;
  return 0.5 * (C + C.transpose());  // symmetric to round-off
}

Vec6 edge_squared_length_changes(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X) {
  Vec6 delta;
  for (int k = 0; k < 6; ++k) {
    const auto [a, b] = kTetEdges[k];
    delta[k] = 0.5 * ((x[b] - x[a]).squaredNorm() - (X[b] - X[a]).squaredNorm());
  }
  return delta;
}

namespace {

/// B: the rows ∇δ_kᵀ (−d_k at node a, +d_k at node b).
Eigen::Matrix<double, 6, 12> edge_gradients(const std::array<Vec3, 4>& x) {
  Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
  for (int k = 0; k < 6; ++k) {
    const auto [a, b] = kTetEdges[k];
    const Vec3 d = x[b] - x[a];
    B.block<1, 3>(k, 3 * a) = -d.transpose();
    B.block<1, 3>(k, 3 * b) = d.transpose();
  }
  return B;
}

}  // namespace

double edge_pair_energy(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X,
                        const Mat6& C) {
  const Vec6 delta = edge_squared_length_changes(x, X);
  return 0.5 * delta.dot(C * delta);
}

Vec12 edge_pair_gradient(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X,
                         const Mat6& C) {
  const Vec6 t = C * edge_squared_length_changes(x, X);
  return edge_gradients(x).transpose() * t;
}

Mat12 edge_pair_hessian(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X, const Mat6& C,
                        bool project_psd) {
  const Eigen::Matrix<double, 6, 12> B = edge_gradients(x);
  const Vec6 t = C * edge_squared_length_changes(x, X);
  Mat12 H = B.transpose() * C * B;
  for (int k = 0; k < 6; ++k) {  // t_k G_k
    const auto [a, b] = kTetEdges[k];
    for (int i = 0; i < 3; ++i) {
      H(3 * a + i, 3 * a + i) += t[k];
      H(3 * b + i, 3 * b + i) += t[k];
      H(3 * a + i, 3 * b + i) -= t[k];
      H(3 * b + i, 3 * a + i) -= t[k];
    }
  }
  return project_psd ? psd_projection(H) : H;
}

EdgePairTerm::EdgePairTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets,
                           const LameParameters& lame)
    : rest_(nodes), tets_(std::move(tets)), lame_(lame) {
  coefficients_.reserve(tets_.size());
  const int n = static_cast<int>(rest_.size());
  for (std::size_t e = 0; e < tets_.size(); ++e) {
    for (int v : tets_[e]) {
      if (v < 0 || v >= n) {
        throw InputError("edge pairs: tet " + std::to_string(e) + " refers to node " +
                         std::to_string(v) + ", expected an index below " + std::to_string(n));
      }
    }
    try {
      coefficients_.push_back(edge_pair_coefficients(rest_corners(tets_[e]), lame_));
    } catch (const InputError&) {
      throw InputError("edge pairs: tet " + std::to_string(e) +
                       " has zero rest volume; expected a non-degenerate tetrahedron");
    }
  }
  pattern_ = four_node_block_pattern(num_dofs(), tets_);
  slots_ = slots_in(pattern_);
}

std::array<Vec3, 4> EdgePairTerm::corners(const VectorXd& x, const Tet& t) const {
  return {x.segment<3>(3 * t[0]), x.segment<3>(3 * t[1]), x.segment<3>(3 * t[2]),
          x.segment<3>(3 * t[3])};
}

std::array<Vec3, 4> EdgePairTerm::rest_corners(const Tet& t) const {
  return {rest_[t[0]], rest_[t[1]], rest_[t[2]], rest_[t[3]]};
}

double EdgePairTerm::energy(const VectorXd& x) const {
  double e = 0.0;
  for (std::size_t k = 0; k < tets_.size(); ++k) {
    e += edge_pair_energy(corners(x, tets_[k]), rest_corners(tets_[k]), coefficients_[k]);
  }
  return e;
}

void EdgePairTerm::add_gradient(const VectorXd& x, VectorXd& g) const {
  for (std::size_t k = 0; k < tets_.size(); ++k) {
    const Tet& t = tets_[k];
    const Vec12 gk = edge_pair_gradient(corners(x, t), rest_corners(t), coefficients_[k]);
    for (int a = 0; a < 4; ++a) g.segment<3>(3 * t[a]) += gk.segment<3>(3 * a);
  }
}

void EdgePairTerm::gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs());
  add_gradient(x, g);
}

std::vector<int> EdgePairTerm::slots_in(const SparseMatrix& pattern) const {
  return four_node_block_slots(pattern, tets_);
}

void EdgePairTerm::add_hessian(const VectorXd& x, double* values, const std::vector<int>& slots,
                               bool project_psd) const {
  const int* s = slots.data();
  for (std::size_t k = 0; k < tets_.size(); ++k) {
    const Tet& t = tets_[k];
    add_four_node_block(
        edge_pair_hessian(corners(x, t), rest_corners(t), coefficients_[k], project_psd), s,
        values);
  }
}

void EdgePairTerm::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  H = pattern_;
  std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  add_hessian(x, H.valuePtr(), slots_, project_psd);
}

double EdgePairTerm::max_strain(const VectorXd& x) const {
  double m = 0.0;
  for (const Tet& t : tets_) {
    for (const auto& [a, b] : kTetEdges) {
      const double L = (rest_[t[b]] - rest_[t[a]]).norm();
      const double l = (x.segment<3>(3 * t[b]) - x.segment<3>(3 * t[a])).norm();
      m = std::max(m, std::abs(l - L) / L);
    }
  }
  return m;
}

}  // namespace vessel::msm
