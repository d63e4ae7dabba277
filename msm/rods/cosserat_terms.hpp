#pragma once
/// The strain measures shared by the quaternion rods (CORDE, XPBD Cosserat), over any scalar:
/// the discrete Darboux vector Ω = (2/l̄) Im(q̄_a q_b) (in q_a's frame; Spillmann & Teschner
/// 2007, Kugelstadt & Schömer 2016), its rotation-vector form (the turning angle), and the
/// stretch–shear strain Γ = (P1 − P0)/l − d3(q).
#include <Eigen/Core>
#include <array>
#include <cmath>

#include "msm/rods/jet.hpp"
#include "msm/rods/vec3.hpp"

namespace vessel::msm::rods {

/// d3 of quaternion (w, x, y, z): its rotation of e3.
template <class T>
V3<T> director3(const T& w, const T& x, const T& y, const T& z) {
  return {2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)};
}

/// Ω from q_a = q[0..3], q_b = q[4..7] (w first): (2/l̄)(w_a v_b − w_b v_a − v_a × v_b).
template <class T>
V3<T> darboux_vector(const std::array<T, 8>& q, double lbar) {
  const V3<T> va(q[1], q[2], q[3]), vb(q[5], q[6], q[7]);
  return (2.0 / lbar) * (q[0] * vb - q[4] * va - cross(va, vb));
}

/// g(u) = atan(√u)/√u and its first two derivatives in u (u ≥ 0; the series
/// Σ (−u)^k/(2k+1) below u = 1e-2, where the closed forms lose digits). atan(s/w)/s =
/// g(s²/w²)/w is the half rotation angle over |Im(q̄_a q_b)| = s, with Re(q̄_a q_b) = w > 0.
inline std::array<double, 3> atan_ratio(double u) {
  if (u < 1e-2) {
    // g = Σ c_k (−u)^k, c_k = 1/(2k+1); g' = Σ −c_k k (−u)^(k−1); g'' = Σ c_k k(k−1) (−u)^(k−2).
    std::array<double, 3> r{0.0, 0.0, 0.0};
    double p0 = 1.0, p1 = 0.0, p2 = 0.0;  // (−u)^k, (−u)^(k−1), (−u)^(k−2)
    for (int k = 0; k <= 12; ++k) {
      const double c = 1.0 / (2.0 * k + 1.0);
      r[0] += c * p0;
      r[1] -= c * k * p1;
      r[2] += c * k * (k - 1) * p2;
      p2 = k == 0 ? 0.0 : (k == 1 ? 1.0 : p1);
      p1 = p0;
      p0 *= -u;
    }
    return r;
  }
  const double t = std::sqrt(u), a = std::atan(t), p = 1.0 + u;
  const double n = t / p - a;                     // d(atan t / t)/dt · t²
  const double dn = -2.0 * u / (p * p);           // dn/dt
  const double h = n / (2.0 * t * t * t);         // g'(u)
  const double dh = dn / (2.0 * t * t * t) - 3.0 * n / (2.0 * u * u);  // dh/dt
  return {a / t, h, dh / (2.0 * t)};
}
inline double atan_ratio_of(double u) { return atan_ratio(u)[0]; }
template <class J>
J atan_ratio_of(const J& u) {
  const auto r = atan_ratio(u.v);
  return chain(u, r[0], r[1], r[2]);
}

/// The rotation-vector Darboux vector Ω = (φ/l̄) n, φ and n the angle and axis of q̄_a q_b (in
/// q_a's frame): the turning angle where darboux_vector has 2 sin(φ/2). Requires Re(q̄_a q_b) > 0
/// (φ < π between neighbouring frames).
template <class T>
V3<T> rotation_darboux_vector(const std::array<T, 8>& q, double lbar) {
  const V3<T> va(q[1], q[2], q[3]), vb(q[5], q[6], q[7]);
  const V3<T> v = q[0] * vb - q[4] * va - cross(va, vb);  // Im(q̄_a q_b)
  const T w = q[0] * q[4] + dot(va, vb);                   // Re(q̄_a q_b)
  const T ratio = atan_ratio_of(dot(v, v) / (w * w)) / w;  // atan(|v|/w)/|v|
  return (2.0 / lbar) * (ratio * v);
}

/// Γ from P0 = q[0..2], P1 = q[3..5], quaternion q[6..9].
template <class T>
V3<T> stretch_shear_strain(const std::array<T, 10>& q, double l) {
  const V3<T> e = V3<T>(q[3], q[4], q[5]) - V3<T>(q[0], q[1], q[2]);
  return (1.0 / l) * e - director3(q[6], q[7], q[8], q[9]);
}


/// Γ and ∂Γ/∂(P0, P1, q) (3 × 10) in closed form, for the XPBD sweeps (the templated
/// stretch_shear_strain above is the same formula; tests compare the two).
///
/// With Tangent, the quaternion columns are projected onto the unit sphere's tangent space,
/// J_q (I − q qᵀ) (what the XPBD rod solves with); J_q q is then taken in closed form,
/// J_q q = (−2 d3x, −2 d3y, 4(x² + y²)) (so J_q (I − q qᵀ) q = 0 when |q| = 1). Each entry is
/// computed once and stored once (no read-back of J).
template <bool Tangent = false>
inline void stretch_shear_with_jacobian(const Eigen::Matrix<double, 10, 1>& q, double l,
                                        Eigen::Vector3d& c, Eigen::Matrix<double, 3, 10>& J) {
  const double w = q[6], x = q[7], y = q[8], z = q[9];
  const double d0 = 2.0 * (x * z + w * y), d1 = 2.0 * (y * z - w * x);
  const double d2 = 1.0 - 2.0 * (x * x + y * y);
  const double il = 1.0 / l;
  c = Eigen::Vector3d((q[3] - q[0]) * il - d0, (q[4] - q[1]) * il - d1, (q[5] - q[2]) * il - d2);
  // −∂d3/∂w, −∂d3/∂x, −∂d3/∂y, −∂d3/∂z, row by row
  double g[3][4] = {{-2.0 * y, -2.0 * z, -2.0 * w, -2.0 * x},
                    {2.0 * x, 2.0 * w, -2.0 * z, -2.0 * y},
                    {0.0, 4.0 * x, 4.0 * y, 0.0}};
  if constexpr (Tangent) {
    const double radial[3] = {-2.0 * d0, -2.0 * d1, 4.0 * (x * x + y * y)};
    const double qv[4] = {w, x, y, z};
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 4; ++k) g[r][k] -= radial[r] * qv[k];
    }
  }
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      J(r, k) = r == k ? -il : 0.0;
      J(r, 3 + k) = r == k ? il : 0.0;
    }
    for (int k = 0; k < 4; ++k) J(r, 6 + k) = g[r][k];
  }
}

/// Ω and ∂Ω/∂(q_a, q_b) (3 × 8, in J's first 8 columns) in closed form: with
/// Ω = (2/l̄)(w_a v_b − w_b v_a − v_a × v_b),
/// ∂Ω/∂w_a = (2/l̄) v_b, ∂Ω/∂v_a = (2/l̄)(−w_b I + [v_b]×), ∂Ω/∂w_b = −(2/l̄) v_a,
/// ∂Ω/∂v_b = (2/l̄)(w_a I − [v_a]×).
/// With Tangent, each quaternion's columns are projected onto the unit sphere's tangent space,
/// J_a (I − q_a q_aᵀ) and J_b (I − q_b q_bᵀ); J_a q_a = J_b q_b = Ω (Ω is bilinear in q_a, q_b).
template <bool Tangent = false, class Jacobian>
inline void darboux_with_jacobian(const Eigen::Matrix<double, 8, 1>& q, double lbar,
                                  Eigen::Vector3d& c, Jacobian& J) {
  const double s = 2.0 / lbar;
  const double wa = q[0], ax = q[1], ay = q[2], az = q[3];
  const double wb = q[4], bx = q[5], by = q[6], bz = q[7];
  // va × vb
  const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
  const double o[3] = {s * (wa * bx - wb * ax - cx), s * (wa * by - wb * ay - cy),
                       s * (wa * bz - wb * az - cz)};
  c = Eigen::Vector3d(o[0], o[1], o[2]);
  // rows of [∂Ω/∂q_a | ∂Ω/∂q_b] / s; [v]× = [[0, −vz, vy], [vz, 0, −vx], [−vy, vx, 0]]
  double g[3][8] = {{bx, -wb, -bz, by, -ax, wa, az, -ay},
                    {by, bz, -wb, -bx, -ay, -az, wa, ax},
                    {bz, -by, bx, -wb, -az, ay, -ax, wa}};
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 8; ++k) g[r][k] *= s;
  }
  if constexpr (Tangent) {
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 8; ++k) g[r][k] -= o[r] * q[k];
    }
  }
  for (int k = 0; k < 8; ++k) {
    for (int r = 0; r < 3; ++r) J(r, k) = g[r][k];
  }
}

}  // namespace vessel::msm::rods
