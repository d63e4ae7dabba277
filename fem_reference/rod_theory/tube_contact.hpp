#pragma once
/// Continuum references of a wire (inextensible Kirchhoff rod) against a rigid, frictionless wall.
namespace vessel::rod_theory {

/// Straight tube: the wire clamped on the axis at the inlet, its tangent tilted by θ_in towards
/// the wall, its tip touching the wall (centreline offset c from the axis) at axial distance z_c,
/// the wall's force normal to the axis. Shooting in units z_c = 1, EI = 1 on (m(0), L, F) with
/// x(L) = 1, y(L) = c/z_c, m(L) = 0 (Newton, central-difference Jacobian).
struct StraightTubeContact {
  double force = 0.0;       ///< F·z_c²/EI
  double length = 0.0;      ///< L/z_c
  double tip_angle = 0.0;   ///< tangent angle at the tip, rad
  double clamp_moment = 0.0;  ///< m(0)·z_c/EI
};
StraightTubeContact straight_tube_contact(double theta_in, double offset_over_z);

/// The straight-tube contact of a wire of given length L (its insertion beyond the clamp) against
/// a tube of centreline offset c: the contact's axial distance z_c solves
/// L = straight_tube_contact(θ_in, c/z_c).length · z_c (secant from z_c = 0.98 L, 0.99 L, to
/// 1e-15 L). Returns z_c in the units of c and L; throws std::runtime_error without convergence.
double straight_tube_contact_distance(double theta_in, double offset, double length);

/// Arch apex: the wire clamped tangentially on the bend's centreline circle (radius R), its tip
/// bearing on the outer wall (radius R_o from the bend centre, the wire's radius already taken
/// off) a quarter turn on: a quarter-wave Euler elastica, crest at the clamp and inflection at the
/// tip; k solves (2E(k) − K(k))/(2k) = R_o/R; F R²/EI = 4k², L/R = K(k)/(2k).
struct ArchApexContact {
  double modulus = 0.0;  ///< k
  double force = 0.0;    ///< F·R²/EI
  double length = 0.0;   ///< L/R
};
ArchApexContact arch_apex_contact(double outer_over_bend_radius);

}  // namespace vessel::rod_theory
