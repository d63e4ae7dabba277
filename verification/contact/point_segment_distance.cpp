#include "verification/contact/point_segment_distance.hpp"

#include <algorithm>
#include <stdexcept>

namespace vessel::contact {

PointSegmentDistance point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                            const Eigen::Vector3d& b, bool with_hessian) {
  using Mat39 = Eigen::Matrix<double, 3, 9>;
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  const Eigen::Vector3d e = b - a;
  const double ee = e.squaredNorm();
  if (!(ee > 0.0)) throw std::invalid_argument("point_segment_distance: a segment of zero length");
  PointSegmentDistance out;
  const double t_free = (p - a).dot(e) / ee;
  out.t = std::clamp(t_free, 0.0, 1.0);
  const bool interior = t_free > 0.0 && t_free < 1.0;
  const Eigen::Vector3d r = p - a - out.t * e;
  out.distance = r.norm();
  if (!(out.distance > 0.0)) {
    throw std::invalid_argument("point_segment_distance: the point lies on the segment");
  }
  // A: dr = A dq at fixed t (q = (p, a, b)); at an end t is fixed at 0 or 1.
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Mat39 A;
  A << I, -(1.0 - out.t) * I, -out.t * I;
  const Vec9 half_gradient = A.transpose() * r;  // ∇(½d²)
  out.gradient = half_gradient / out.distance;
  if (!with_hessian) return out;
  Mat9 half_hessian = A.transpose() * A;
  if (interior) {
    Eigen::Matrix<double, 1, 9> B;
    B << Eigen::RowVector3d::Zero(), -r.transpose(), r.transpose();
    const Eigen::Matrix<double, 9, 1> Ate = A.transpose() * e;
    half_hessian -= (Ate * Ate.transpose() + Ate * B + B.transpose() * Ate.transpose() +
                     B.transpose() * B) /
                    ee;
  }
  out.hessian = (half_hessian - out.gradient * out.gradient.transpose()) / out.distance;
  return out;
}

}  // namespace vessel::contact
