#pragma once
/// Per-spring kernels: energy, gradient and Hessian side by side (ipc-toolkit style), as small
/// fixed-size free functions. Every spring is a function of its length L = |xa − xb| only:
/// E = ψ(L), ∇_xa E = ψ'(L) d, ∇_xb E = −ψ'(L) d with d = (xa − xb)/L, and
/// ∇²_{xa xa} E = ψ''(L) d dᵀ + ψ'(L)/L (I − d dᵀ) = −∇²_{xa xb} E = ∇²_{xb xb} E.
/// Units: positions m, stiffness N/m, energy J, force N.
#include <Eigen/Core>
#include <limits>

#include "msm/topology/springs.hpp"

namespace vessel::msm {

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

/// ψ, ψ', ψ'' of a spring's energy as a function of its length (J, N, N/m).
struct LengthProfile {
  double psi = 0.0;
  double dpsi = 0.0;
  double ddpsi = 0.0;
};


/// Hooke's spring: ψ = ½ k (L − l)², whose force −∇ψ is seed 000 eq. (3.2):
/// f_a = −k_s (xa − xb)/|xa − xb| (|xa − xb| − l).
LengthProfile hooke_profile(double length, double rest_length, double k);

/// Bilinear spring of seed 001 eq. (1) (after Mollemans), with δ = L − L_ij:
///   |F| = k1 δ                          for δ < Δx_c
///   |F| = k1 Δx_c + k2 (δ − Δx_c)       for δ ≥ Δx_c
/// whose energy is ψ = ½k1δ² below the threshold and ½k1Δx_c² + k1Δx_c(δ−Δx_c) + ½k2(δ−Δx_c)²
/// above it (C¹; ψ'' jumps from k1 to k2 at the threshold).
LengthProfile bilinear_profile(double length, double rest_length, const SpringLaw& law);

/// The spring's profile under its law (Hooke when law.threshold is infinite).
LengthProfile spring_profile(double length, double rest_length, const SpringLaw& law);

/// Energy of a spring between xa and xb, J.
double spring_energy(const Vec3& xa, const Vec3& xb, double rest_length, const SpringLaw& law);
/// Gradient (∂E/∂xa, ∂E/∂xb) stacked, N. The force on the nodes is its negative.
Vec6 spring_gradient(const Vec3& xa, const Vec3& xb, double rest_length, const SpringLaw& law);
/// Hessian (6×6, N/m). With project_psd, the eigenvalues ψ'' (axial) and ψ'/L (transverse,
/// negative in compression) are clamped at zero, which is the exact projection onto the positive
/// semi-definite cone (the 6×6 block [[K, −K], [−K, K]] has eigenvalues 2·eig(K) and 0).
Mat6 spring_hessian(const Vec3& xa, const Vec3& xb, double rest_length, const SpringLaw& law,
                    bool project_psd = false);

/// Axial spring damping, seed 000 eq. (3.4): f_a = −k_d ((va − vb)·d) d, f_b = −f_a, with
/// d = (xa − xb)/|xa − xb|. The seed prints (v_b − v_a)·d, which with its d = (xa − xb)/|…| would
/// push a moving node further along and inject energy; the dissipative sign is used here (the
/// damping power is −k_d ((va − vb)·d)² ≤ 0). Returns (f_a, f_b) stacked, N.
Vec6 axial_damping_force(const Vec3& xa, const Vec3& xb, const Vec3& va, const Vec3& vb, double kd);
/// −∂f/∂v of the axial damping force (6×6, PSD), N·s/m: k_d [[D, −D], [−D, D]], D = d dᵀ.
Mat6 axial_damping_jacobian(const Vec3& xa, const Vec3& xb, double kd);

/// Point damping, seed 000 eq. (3.3): f = −k_v v (N), k_v in N·s/m.
inline Vec3 point_damping_force(const Vec3& v, double kv) { return -kv * v; }

}  // namespace vessel::msm
