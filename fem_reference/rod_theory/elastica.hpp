#pragma once
/// Continuum references for inextensible, unshearable Kirchhoff rods: closed forms with elliptic
/// integrals (Boost.Math) and planar shooting (Dormand–Prince with step control, Boost.Odeint).
/// Never computed from a discrete rod. Lengths are in units of the rod length L, loads in EI/L²,
/// moments in EI/L unless a function says otherwise.
#include <array>

namespace vessel::rod_theory {

/// Tip of a cantilever under a dead tip load P normal to the undeformed rod, α = PL²/EI
/// (Bisshopp & Drucker 1945): with tip angle θ₀, k² = (1 + sin θ₀)/2, sin φ₁ = 1/(√2 k),
/// √α = K(k) − F(φ₁, k); v/L = 1 − (2/√α)[E(k) − E(φ₁, k)]; x/L = √(2 sin θ₀/α).
struct ElasticaTip {
  double deflection = 0.0;  ///< v/L
  double shortening = 0.0;  ///< 1 − x/L
  double tip_angle = 0.0;   ///< θ₀, rad
};
ElasticaTip bisshopp_drucker(double alpha);

/// Planar Kirchhoff rod of unit length and EI = 1, clamped at the origin with tangent angle
/// `clamp_angle`, dead tip force (fx, fy) and tip moment `tip_moment`:
/// θ' = m, m' = fx sin θ − fy cos θ, (x, y)' = (cos θ, sin θ), m(1) = tip_moment, solved by
/// Newton on m(0) with continuation in the load (the branch joined to the unloaded rod).
struct PlanarShot {
  double x = 0.0, y = 0.0, theta = 0.0;  ///< tip position and tangent angle
  double clamp_moment = 0.0;             ///< m(0)
  double residual = 0.0;                 ///< |m(1) − tip_moment|
};
PlanarShot shoot_planar_cantilever(double fx, double fy, double tip_moment, double clamp_angle = 0.0,
                                   double length = 1.0);

/// Integrates the planar Kirchhoff ODE from s = 0 to `length`: state (x, y, θ, m), tolerance
/// 1e-13 (absolute and relative) per step.
std::array<double, 4> integrate_planar(const std::array<double, 4>& start, double fx, double fy,
                                       double length);

/// Euler buckling load of a clamped–free column, π²EI/(4L²) (in EI/L²).
double euler_cantilever_load();
/// Greenhill: the first non-zero root μ of tan(μ/2) = μ/2, M_t L/EI of a rod clamped at both ends.
double greenhill_clamped();
/// β_n L of a cantilever's n-th bending mode (n ≥ 1): the roots of cos β cosh β + 1 = 0.
double cantilever_beta(int n);

}  // namespace vessel::rod_theory
