#include "msm/terms/edge_pair_term.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/volume_term.hpp"

namespace vessel::msm {

std::string edge_pair_refusal(double E, double nu) {
  if (!(E > 0) || !std::isfinite(E)) {
    return "edge pairs (StVK): expected Young's modulus E > 0 Pa, got " + std::to_string(E);
  }
  if (!(nu >= 0.0 && nu < 0.5)) {
    return "edge pairs (StVK): poisson_ratio ν must be in [0, 0.5), got " + std::to_string(nu) +
           (nu >= 0.5 ? "; at ν = 0.5 λ is infinite (displacement-only P1 FEM, which "
                        "this model equals, cannot represent incompressibility)"
                      : "");
  }
  return {};
}

LameParameters lame_parameters(double E, double nu) {
  if (std::string why = edge_pair_refusal(E, nu); !why.empty()) throw InputError(why);
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
    : FourNodeTerm(static_cast<int>(nodes.size())), lame_(lame) {
  const int n = static_cast<int>(nodes.size());
  rest_corners_.reserve(tets.size());
  coefficients_.reserve(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e) {
    for (int v : tets[e]) {
      if (v < 0 || v >= n) {
        throw InputError("edge pairs: tet " + std::to_string(e) + " refers to node " +
                         std::to_string(v) + ", expected an index below " + std::to_string(n));
      }
    }
    const Tet& t = tets[e];
    rest_corners_.push_back({nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]});
    try {
      coefficients_.push_back(edge_pair_coefficients(rest_corners_.back(), lame_));
    } catch (const InputError&) {
      throw InputError("edge pairs: tet " + std::to_string(e) +
                       " has zero rest volume; expected a non-degenerate tetrahedron");
    }
  }
  set_elements(std::move(tets));
}

double EdgePairTerm::element_energy(std::size_t k, const std::array<Vec3, 4>& x) const {
  return edge_pair_energy(x, rest_corners_[k], coefficients_[k]);
}

Vec12 EdgePairTerm::element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const {
  return edge_pair_gradient(x, rest_corners_[k], coefficients_[k]);
}

Mat12 EdgePairTerm::element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                    bool project_psd) const {
  return edge_pair_hessian(x, rest_corners_[k], coefficients_[k], project_psd);
}

double EdgePairTerm::max_strain(const VectorXd& x) const {
  double m = 0.0;
  for (std::size_t k = 0; k < elements().size(); ++k) {
    const std::array<Vec3, 4> c = corners(x, k);
    const std::array<Vec3, 4>& r = rest_corners_[k];
    for (const auto& [a, b] : kTetEdges) {
      const double L = (r[b] - r[a]).norm();
      m = std::max(m, std::abs((c[b] - c[a]).norm() - L) / L);
    }
  }
  return m;
}

}  // namespace vessel::msm
