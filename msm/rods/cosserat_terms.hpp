#pragma once
/// The strain measures shared by the quaternion rods (CORDE, XPBD Cosserat), over any scalar:
/// the discrete Darboux vector Ω = (2/l̄) Im(q̄_a q_b) (in q_a's frame; Spillmann & Teschner
/// 2007, Kugelstadt & Schömer 2016) and the stretch–shear strain Γ = (P1 − P0)/l − d3(q).
#include <array>

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

/// Γ from P0 = q[0..2], P1 = q[3..5], quaternion q[6..9].
template <class T>
V3<T> stretch_shear_strain(const std::array<T, 10>& q, double l) {
  const V3<T> e = V3<T>(q[3], q[4], q[5]) - V3<T>(q[0], q[1], q[2]);
  return (1.0 / l) * e - director3(q[6], q[7], q[8], q[9]);
}

}  // namespace vessel::msm::rods
