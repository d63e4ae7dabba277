#pragma once
/// Lamé's closed form for a thick-walled cylinder under internal pressure in plane strain: the
/// reference's own verification problem. SI units.
#include "meshes/tet_mesh.hpp"

namespace vessel::fem {

struct LameCylinder {
  double inner_radius = 3e-3;       ///< a, m
  double outer_radius = 4e-3;       ///< b, m
  double pressure = 1.0;            ///< p on r = a, Pa (outer surface traction-free)
  double youngs_modulus = 14.24e3;  ///< E, Pa
  double poisson_ratio = 0.3;       ///< ν

  /// Radial displacement u_r(r), m, plane strain (u_z = 0):
  /// u_r = p a² / (E (b² − a²)) · ((1+ν)(1−2ν) r + (1+ν) b² / r)
  /// (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., §28, with plane-strain constants;
  /// valid for ν = 0.5 too).
  [[nodiscard]] double radial_displacement(double r) const;
  /// The displacement vector at x for a tube along z: u_r(r) (x, y, 0)/r, r = √(x² + y²).
  [[nodiscard]] Vec3 displacement(const Vec3& x) const;
};

}  // namespace vessel::fem
