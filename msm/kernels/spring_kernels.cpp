#include "msm/kernels/spring_kernels.hpp"

#include <cmath>

namespace vessel::msm {

LengthProfile hooke_profile(double length, double rest_length, double k) {
  const double delta = length - rest_length;
  // seed 000 eq. (3.2): |f| = k_s (|xa − xb| − l), the derivative of ½ k (L − l)².
  return {0.5 * k * delta * delta, k * delta, k};
}

LengthProfile bilinear_profile(double length, double rest_length, const SpringLaw& law) {
  const double delta = length - rest_length;
  const double dc = law.threshold;
  if (!(delta >= dc)) return hooke_profile(length, rest_length, law.k1);
  // seed 001 eq. (1), second branch: |F| = k1 Δx_c + k2 (δ − Δx_c).
  const double beyond = delta - dc;
  return {0.5 * law.k1 * dc * dc + law.k1 * dc * beyond + 0.5 * law.k2 * beyond * beyond,
          law.k1 * dc + law.k2 * beyond, law.k2};
}

LengthProfile spring_profile(double length, double rest_length, const SpringLaw& law) {
  if (std::isinf(law.threshold)) return hooke_profile(length, rest_length, law.k1);
  return bilinear_profile(length, rest_length, law);
}

double spring_energy(const Vec3& xa, const Vec3& xb, double rest_length, const SpringLaw& law) {
  return spring_profile((xa - xb).norm(), rest_length, law).psi;
}

Vec6 spring_gradient(const Vec3& xa, const Vec3& xb, double rest_length, const SpringLaw& law) {
  const Vec3 e = xa - xb;
  const double L = e.norm();
  Vec6 g = Vec6::Zero();
  if (L <= 0.0) return g;  // coincident ends: direction undefined, force taken as zero
  const Vec3 d = e / L;
  const double dpsi = spring_profile(L, rest_length, law).dpsi;
  g.head<3>() = dpsi * d;
  g.tail<3>() = -dpsi * d;
  return g;
}

Mat6 spring_hessian(const Vec3& xa, const Vec3& xb, double rest_length, const SpringLaw& law,
                    bool project_psd) {
  const Vec3 e = xa - xb;
  const double L = e.norm();
  Mat6 H = Mat6::Zero();
  if (L <= 0.0) {
    // Coincident ends. A zero-rest-length spring is ½k|e|² there, Hessian k[I −I; −I I]; with a
    // positive rest length the energy has a cone point and no Hessian: zero is returned.
    if (rest_length > 0.0) return H;
    const double k = spring_profile(0.0, 0.0, law).ddpsi;
    const Eigen::Matrix3d K = k * Eigen::Matrix3d::Identity();
    H << K, -K, -K, K;
    return H;
  }
  const Vec3 d = e / L;
  const LengthProfile p = spring_profile(L, rest_length, law);
  double axial = p.ddpsi;
  double transverse = p.dpsi / L;
  if (project_psd) {
    axial = std::max(axial, 0.0);
    transverse = std::max(transverse, 0.0);
  }
  const Eigen::Matrix3d D = d * d.transpose();
  const Eigen::Matrix3d K = axial * D + transverse * (Eigen::Matrix3d::Identity() - D);
  H.topLeftCorner<3, 3>() = K;
  H.bottomRightCorner<3, 3>() = K;
  H.topRightCorner<3, 3>() = -K;
  H.bottomLeftCorner<3, 3>() = -K;
  return H;
}

Vec6 axial_damping_force(const Vec3& xa, const Vec3& xb, const Vec3& va, const Vec3& vb,
                         double kd) {
  Vec6 f = Vec6::Zero();
  const Vec3 e = xa - xb;
  const double L = e.norm();
  if (L <= 0.0) return f;
  const Vec3 d = e / L;
  // seed 000 eq. (3.4), dissipative sign (see header).
  const Vec3 fa = -kd * (va - vb).dot(d) * d;
  f.head<3>() = fa;
  f.tail<3>() = -fa;
  return f;
}

Mat6 axial_damping_jacobian(const Vec3& xa, const Vec3& xb, double kd) {
  Mat6 J = Mat6::Zero();
  const Vec3 e = xa - xb;
  const double L = e.norm();
  if (L <= 0.0) return J;
  const Vec3 d = e / L;
  const Eigen::Matrix3d D = kd * d * d.transpose();
  J.topLeftCorner<3, 3>() = D;
  J.bottomRightCorner<3, 3>() = D;
  J.topRightCorner<3, 3>() = -D;
  J.bottomLeftCorner<3, 3>() = -D;
  return J;
}

}  // namespace vessel::msm
