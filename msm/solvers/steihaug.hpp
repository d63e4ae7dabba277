#pragma once
/// Steihaug–Toint truncated conjugate gradients: the trust-region step of a quadratic model whose
/// Hessian may be indefinite, preconditioned with a positive-definite matrix P that also defines
/// the trust region's norm (Steihaug 1983; Nocedal & Wright 2006, Algorithm 7.2; the
/// preconditioned form of Gould, Lucidi, Roma & Toint 1999). Written once for any operator: the
/// static trust-region Newton (static_solver.cpp) and the wire–wall contact minimiser
/// (verification/contact/wire_wall_potential.cpp) call it.
#include <algorithm>
#include <cmath>

#include "msm/form/form.hpp"

namespace vessel::msm {

/// The step s ≥ 0 at which ‖z + s·p‖_P = Δ (the positive root of a quadratic in s), given
/// zᵀPz, zᵀPp and pᵀPp.
inline double to_trust_boundary(double zz, double zp, double pp, double radius) {
  const double c = zz - radius * radius;  // ≤ 0: z is inside
  const double disc = std::max(zp * zp - pp * c, 0.0);
  // The positive root (−zp + √disc)/pp, written without cancellation.
  return zp > 0.0 ? -c / (zp + std::sqrt(disc)) : (-zp + std::sqrt(disc)) / pp;
}

struct SteihaugStep {
  VectorXd d;
  int iterations = 0;
  bool boundary = false;            ///< stopped on the trust-region boundary
  bool negative_curvature = false;  ///< stopped along a direction with pᵀHp ≤ 0
};

/// min m(d) = gᵀd + ½dᵀHd subject to ‖d‖_P ≤ Δ, approximately: CG on H d = −g from d = 0 with
/// the preconditioner P, stopped at the boundary, at a direction of non-positive curvature (then
/// followed to the boundary: the step uses the negative curvature a step on a positive-definite
/// model cannot see), or at the relative residual `forcing`. Its first iterate is the step on
/// P's model, −P⁻¹g, cut to the boundary; every iterate lowers m, so gᵀd < 0.
/// `apply_h(v, out)`: out = H v; `apply_p(v, out)`: out = P v (for the norm); `precondition(r,
/// out)`: out = P⁻¹ r.
template <class ApplyH, class ApplyP, class Precondition>
SteihaugStep steihaug_cg(const ApplyH& apply_h, const ApplyP& apply_p,
                         const Precondition& precondition, const VectorXd& g, double radius,
                         double forcing, int max_iterations) {
  SteihaugStep out;
  const Eigen::Index n = g.size();
  VectorXd z = VectorXd::Zero(n), r = g, y(n), Hp(n), Pp(n), Pz = VectorXd::Zero(n);
  precondition(r, y);
  VectorXd p = -y;
  double ry = r.dot(y);
  const double stop = forcing * g.norm();
  double zz = 0.0;
  for (out.iterations = 1; out.iterations <= max_iterations; ++out.iterations) {
    apply_h(p, Hp);
    apply_p(p, Pp);
    const double kappa = p.dot(Hp);
    const double pp = p.dot(Pp), zp = Pz.dot(p);
    if (!(kappa > 0.0)) {
      out.negative_curvature = out.boundary = true;
      out.d = z + to_trust_boundary(zz, zp, pp, radius) * p;
      return out;
    }
    const double alpha = ry / kappa;
    const double zz_next = zz + 2.0 * alpha * zp + alpha * alpha * pp;
    if (zz_next >= radius * radius) {
      out.boundary = true;
      out.d = z + to_trust_boundary(zz, zp, pp, radius) * p;
      return out;
    }
    z += alpha * p;
    Pz += alpha * Pp;
    zz = zz_next;
    r += alpha * Hp;
    if (r.norm() <= stop) break;
    precondition(r, y);
    const double ry_next = r.dot(y);
    p = -y + (ry_next / ry) * p;
    ry = ry_next;
  }
  out.iterations = std::min(out.iterations, max_iterations);
  out.d = std::move(z);
  return out;
}

}  // namespace vessel::msm
