#pragma once
/// The distance from a point to a segment with its first and second derivatives with respect to
/// the point and both ends: the gap of a wall node to one segment of the wire's capsule, whose
/// exact Hessian lets a contact solve take full Newton steps on a potential.
///
/// With e = b − a, t = clamp((p − a)·e/|e|², 0, 1) and r = p − a − t e, d = |r|. Inside the
/// segment (0 < t < 1), t depends on (p, a, b) through r·e = 0; with q = (p, a, b),
/// A = [I, −(1−t)I, −tI] and B = [0, −rᵀ, rᵀ] (so dr = A dq − e dt and dt = (eᵀA + B) dq/|e|²):
///   ∇(½d²) = Aᵀr,  ∇²(½d²) = Aᵀ(I − êêᵀ)A − (AᵀeB + BᵀeᵀA + BᵀB)/|e|²,
/// and at an end (t clamped) the point-to-point forms with r = p − a or p − b. Then
/// ∇d = ∇(½d²)/d and ∇²d = (∇²(½d²) − ∇d∇dᵀ)/d.
#include <Eigen/Core>

namespace vessel::contact {

struct PointSegmentDistance {
  double distance = 0.0;  ///< d, m
  double t = 0.0;         ///< the nearest point's parameter on the segment, in [0, 1]
  Eigen::Matrix<double, 9, 1> gradient;  ///< ∂d/∂(p, a, b)
  Eigen::Matrix<double, 9, 9> hessian;   ///< ∂²d/∂(p, a, b)², 1/m (when asked)
};

/// d(p, [a, b]) and its derivatives. The gradient and Hessian are undefined (not computed) at
/// d = 0 or for a segment of zero length: std::invalid_argument.
PointSegmentDistance point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                            const Eigen::Vector3d& b, bool with_hessian);

}  // namespace vessel::contact
