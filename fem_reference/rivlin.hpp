#pragma once
/// Rivlin's inflation of a thick-walled incompressible neo-Hookean tube in plane strain: the
/// finite-strain reference's closed-form check. Derivation in docs/physics/finite_strain.md. SI units.
#include "meshes/tet_mesh.hpp"

namespace vessel::fem {

/// Tube A ≤ R ≤ B (reference), Ψ = μ/2 (I₁ − 3) with J = 1, internal pressure P on the deformed
/// inner wall r = a, outer wall traction-free, λ_z = 1. Incompressibility gives
/// r² − a² = R² − A² (Rivlin 1949; Ogden, Non-linear Elastic Deformations, §5.3.1).
struct RivlinTube {
  double inner_radius = 3e-3;            ///< A, m
  double outer_radius = 4e-3;            ///< B, m
  double shear_modulus = 14.24e3 / 3.0;  ///< μ, Pa (E/3 at ν = 0.5)

  /// The deformed radius r(R) = √(R² + a² − A²) of a tube whose inner radius became a.
  [[nodiscard]] double deformed_radius(double R, double a) const;
  /// P(a) = μ ∫_a^b (r²/R² − R²/r²) dr/r with R² = r² − (a² − A²), b = r(B), evaluated by
  /// adaptive Gauss–Kronrod (7–15) quadrature to a relative tolerance of 1e-13.
  [[nodiscard]] double pressure_by_quadrature(double a) const;
  /// The same integral in closed form: P(a) = μ [ln(aB/(Ab)) + (a² − A²)/2 (1/a² − 1/b²)].
  [[nodiscard]] double pressure(double a) const;
  /// sup P = μ ln(B/A) (a → ∞): larger pressures have no equilibrium.
  [[nodiscard]] double limit_pressure() const;
  /// The inner radius a at pressure P (bisection on the increasing P(a) to 1e-15 relative);
  /// std::domain_error unless 0 ≤ P < limit_pressure().
  [[nodiscard]] double inner_radius_at(double P) const;
  /// The displacement at a reference point x of a tube along z under pressure P:
  /// (r(R) − R) (x, y, 0)/R.
  [[nodiscard]] Vec3 displacement(const Vec3& x, double P) const;
};

}  // namespace vessel::fem
