#pragma once
/// Critical time step of the explicit integrators, predicted from the spectrum of M⁻¹K at rest.
///
/// Linearised about rest, m ẍ = −K u − C u̇ decouples (when C is mass-proportional, e.g. point
/// damping with uniform masses) into modes ẍ + γ ẋ + ω² x = 0 with ω² an eigenvalue of M⁻¹K and
/// γ = φᵀCφ / φᵀMφ the mode's damping rate (ζ = γ/(2ω)). Each integrator maps one mode's state
/// (x, v) to A(h)·(x, v); it is stable when the spectral radius of A(h) is ≤ 1. The bounds of
/// critical_step_mode are derived in critical_step.cpp from those amplification matrices.
/// For non-uniform masses the modes only approximately decouple under point damping: γ is then
/// the Rayleigh quotient of the damping on the mode (a first-order estimate), which the stability
/// search (stability_search.hpp) checks by running.
#include "msm/form/form.hpp"
#include "msm/solvers/integrators.hpp"

namespace vessel::msm {

/// Largest step h (s) for which `integrator` is stable on one mode ẍ + γẋ + ω²x = 0
/// (ω rad/s, γ 1/s, both ≥ 0). 0 for explicit Euler without damping (unstable at every step);
/// +infinity for implicit Euler (unconditionally stable) and for ω = 0 with γ = 0.
double critical_step_mode(Integrator integrator, double omega, double gamma);

/// The lowest and highest modes of the linearised model at rest.
struct Spectrum {
  int free_dofs = 0;
  double omega_max = 0.0;   ///< rad/s, Lanczos (Spectra) on M^{-1/2} K M^{-1/2}
  double gamma_max = 0.0;   ///< damping rate φᵀCφ/φᵀMφ of the top mode, 1/s
  double omega_min = 0.0;   ///< rad/s (0 when K has a null space: a mechanism)
  double gamma_min = 0.0;   ///< damping rate of the lowest mode, 1/s
  bool has_lowest = false;  ///< omega_min/gamma_min computed
  /// Bounds of the damping rate γ(x) = x*Cx / x*Mx over every (complex) vector of the free
  /// dofs, 1/s: the extreme eigenvalues of M⁻¹C. Exact (min/max of C_ii/m_i) when C is diagonal,
  /// as for point damping; Gershgorin bounds of M^{-1/2} C M^{-1/2} (γ_lo ≥ 0) otherwise.
  double gamma_lo = 0.0;
  double gamma_hi = 0.0;
  double gershgorin = 0.0;  ///< max_frequency_bound(): an upper bound of omega_max, rad/s
  int lanczos_iterations = 0;
  double seconds = 0.0;
};

struct SpectrumOptions {
  /// Also compute the lowest mode (shift-invert Lanczos with a CHOLMOD factorisation of K); only
  /// needed for explicit Euler with damping, whose most restrictive mode can be the lowest one.
  bool lowest = true;
  double tolerance = 1e-10;  ///< Spectra's relative eigenvalue tolerance
  int max_iterations = 2000;
};

/// Spectrum of M⁻¹K at rest with the fixed dofs removed (K the exact Hessian at rest, C the
/// damping Jacobian, M the lumped masses). Throws std::runtime_error if Lanczos does not converge.
Spectrum analyse_spectrum(const Problem& problem, const SpectrumOptions& options = {});

/// ω_max (rad/s) of M⁻¹K at rest (K the exact Hessian, fixed dofs removed) by power iteration on
/// M^{-1/2} K M^{-1/2} from a fixed pseudo-random start, until the Rayleigh quotient changes by
/// less than `tolerance` (relative) in an iteration or after `max_iterations`: a check of the
/// Lanczos ω_max by another method (its Rayleigh quotient never exceeds the top eigenvalue, so
/// it can only under-estimate ω_max, and 2/ω over-estimate the critical step).
double power_iteration_omega_max(const Problem& problem, double tolerance = 1e-9,
                                 int max_iterations = 20000);

/// Predicted critical step (s) of an integrator for that spectrum: the most restrictive of the
/// highest and (when computed) lowest mode. 0 / +infinity as in critical_step_mode. With damping
/// that is not mass-proportional (point damping with non-uniform masses) this is an estimate
/// that can exceed the true limit (measured: up to 2.3×); see guaranteed_critical_step.
double predicted_critical_step(Integrator integrator, const Spectrum& spectrum);

/// A step (s) at and below which the linearised model is provably stable, for any damping
/// matrix C (symmetric, positive semi-definite) and lumped masses M; NaN where no bound is proven.
/// Argument (the Rayleigh-quotient reduction of the quadratic eigenvalue problem, e.g. Tisseur &
/// Meerbergen, "The quadratic eigenvalue problem", SIAM Review 43 (2001), §3): an eigenvalue λ of
/// ẍ = −M⁻¹Kx − M⁻¹Cẋ has an eigenvector x with (λ²M + λC + K)x = 0, so x*(·)x/x*Mx gives
/// λ² + γλ + ω² = 0 with ω² = x*Kx/x*Mx ∈ [ω_min², ω_max²] and γ = x*Cx/x*Mx ∈ [γ_lo, γ_hi]:
/// every λ is a root of some scalar mode in that rectangle. For explicit Euler (amplification
/// 1 + hλ) and symplectic Euler (its amplification factors μ satisfy (μ − 1)²M + h(μ − 1)C +
/// h²μK singular, so the same reduction gives the scalar mode's characteristic polynomial), the
/// step is stable if every scalar mode in the rectangle is: the minimum of critical_step_mode over
/// it, which lies at a corner (critical_step.cpp). Undamped (γ_hi = 0) it equals the prediction,
/// 2/ω_max. Velocity Verlet with damping mixes M⁻¹C and M⁻¹K products that this reduction does
/// not separate: NaN (no bound) unless undamped. Implicit Euler: +infinity.
double guaranteed_critical_step(Integrator integrator, const Spectrum& spectrum);

}  // namespace vessel::msm
