#pragma once
/// The distance from a point to a triangle with its first and second derivatives with respect to
/// the point and the three corners: the gap of the wire's tip (the centre of its hemisphere) to a
/// face of the wall, which a wall whose nodes are farther apart than the wire is thick can wrap
/// round without any node touching the wire.
///
/// With e₁ = b − a, e₂ = c − a, E = [e₁ e₂], G = EᵀE and (s, t) = G⁻¹Eᵀ(p − a): if the projection
/// lies in the triangle (s, t ≥ 0, s + t ≤ 1), r = p − a − s e₁ − t e₂ with r·e₁ = r·e₂ = 0, and
/// with q = (p, a, b, c), A = [I, −(1−s−t)I, −sI, −tI], B = [[0, rᵀ, −rᵀ, 0], [0, rᵀ, 0, −rᵀ]]
/// (so d(s, t) = G⁻¹(EᵀA − B) dq):
///   ∇(½d²) = Aᵀr,  ∇²(½d²) = AᵀA − (EᵀA − B)ᵀ G⁻¹ (EᵀA − B);
/// otherwise the nearest point is on an edge (point_segment_distance's exact forms, a corner
/// included). Then ∇d = ∇(½d²)/d and ∇²d = (∇²(½d²) − ∇d∇dᵀ)/d.
#include <Eigen/Core>

namespace vessel::contact {

struct PointTriangleDistance {
  double distance = 0.0;  ///< d, m
  Eigen::Vector3d weights =
      Eigen::Vector3d::Zero();  ///< the nearest point's barycentric coordinates on (a, b, c)
  Eigen::Matrix<double, 12, 1> gradient =
      Eigen::Matrix<double, 12, 1>::Zero();  ///< ∂d/∂(p, a, b, c)
  /// ∂²d/∂(p, a, b, c)², 1/m (when asked)
  Eigen::Matrix<double, 12, 12> hessian = Eigen::Matrix<double, 12, 12>::Zero();
};

/// d(p, triangle abc) and its derivatives. std::invalid_argument for a degenerate triangle or a
/// point on the triangle (d at round-off of its size), where they are undefined.
PointTriangleDistance point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                              const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                              bool with_hessian);

}  // namespace vessel::contact
