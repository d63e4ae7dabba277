#include "verification/contact/point_triangle_distance.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <stdexcept>

#include "verification/contact/point_segment_distance.hpp"

namespace vessel::contact {

namespace {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

/// The nearest point on the triangle's boundary: the nearest of its three edges, the edge's
/// derivatives placed on the point's and the edge's corners' blocks.
PointTriangleDistance nearest_edge(const Eigen::Vector3d& p,
                                   const std::array<Eigen::Vector3d, 3>& v, bool with_hessian) {
  PointTriangleDistance out;
  out.distance = -1.0;
  for (int k = 0; k < 3; ++k) {
    const int i = k, j = (k + 1) % 3;
    const PointSegmentDistance s = point_segment_distance(p, v[i], v[j], with_hessian);
    if (out.distance >= 0.0 && s.distance >= out.distance) continue;
    out.distance = s.distance;
    out.weights.setZero();
    out.weights[i] = 1.0 - s.t;
    out.weights[j] = s.t;
    // Block 0 is the point's, block 1 + n corner n's.
    const std::array<int, 3> block{0, 1 + i, 1 + j};
    out.gradient.setZero();
    out.hessian.setZero();
    for (int a = 0; a < 3; ++a) {
      out.gradient.segment<3>(3 * block[a]) = s.gradient.segment<3>(3 * a);
      if (!with_hessian) continue;
      for (int b = 0; b < 3; ++b) {
        out.hessian.block<3, 3>(3 * block[a], 3 * block[b]) = s.hessian.block<3, 3>(3 * a, 3 * b);
      }
    }
  }
  return out;
}

}  // namespace

PointTriangleDistance point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                              const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                              bool with_hessian) {
  Eigen::Matrix<double, 3, 2> E;
  E << b - a, c - a;
  const Eigen::Matrix2d G = E.transpose() * E;
  if (!(G.determinant() > 1e-12 * G.trace() * G.trace())) {
    throw std::invalid_argument("point_triangle_distance: a degenerate triangle");
  }
  const Eigen::Vector2d st = G.ldlt().solve(E.transpose() * (p - a));
  const double s = st[0], t = st[1];
  if (s < 0.0 || t < 0.0 || s + t > 1.0) return nearest_edge(p, {a, b, c}, with_hessian);
  PointTriangleDistance out;
  const Eigen::Vector3d r = p - a - E * st;
  out.distance = r.norm();
  if (!(out.distance > 1e-12 * std::sqrt(G.trace()))) {
    throw std::invalid_argument("point_triangle_distance: the point lies on the triangle");
  }
  out.weights << 1.0 - s - t, s, t;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 12> A;
  A << I, -out.weights[0] * I, -s * I, -t * I;
  const Vec12 half_gradient = A.transpose() * r;  // ∇(½d²), the nearest point held (envelope)
  out.gradient = half_gradient / out.distance;
  if (!with_hessian) return out;
  Eigen::Matrix<double, 2, 12> B;
  B << Eigen::RowVector3d::Zero(), r.transpose(), -r.transpose(), Eigen::RowVector3d::Zero(),
      Eigen::RowVector3d::Zero(), r.transpose(), Eigen::RowVector3d::Zero(), -r.transpose();
  const Eigen::Matrix<double, 2, 12> C = E.transpose() * A - B;
  const Mat12 half_hessian = A.transpose() * A - C.transpose() * G.inverse() * C;
  out.hessian = (half_hessian - out.gradient * out.gradient.transpose()) / out.distance;
  return out;
}

}  // namespace vessel::contact
