#pragma once
/// Quadrature over the part of a plane triangle that lies inside a disc: the exact region, with
/// its circular arcs, not a polygon approximating them. The contact patch (surface_loads) clips
/// each wall triangle to the contact disc with it, so a patch's area is the disc's at every mesh
/// level. Free of any mesh type; plain 2D geometry.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace vessel {

using Vec2 = Eigen::Vector2d;

/// A quadrature point in the plane: position and weight (area it stands for).
struct PlanePoint {
  Vec2 x = Vec2::Zero();
  double weight = 0.0;
};

/// Gauss–Legendre rule with n points on [0, 1] (nodes ascending, weights summing to 1); exact for
/// polynomials of degree ≤ 2n − 1. Nodes by Newton's method on the Legendre polynomial P_n.
std::vector<PlanePoint> gauss_legendre_01(int n);

/// Quadrature points covering T ∩ D, with T the triangle (a, b, c) given counter-clockwise and D
/// the disc of `radius` about `centre`. The region is convex; it is split into triangles and
/// curved triangles (an arc of the circle seen from a point inside the region), so every weight
/// is positive and every point lies in T ∩ D. Straight parts use the degree-2 exact 3-point rule;
/// curved parts Gauss–Legendre in the fan parameter (3 points, degree 5) and along the arc (6
/// points per sub-arc of at most π/4), which integrates polynomials of degree ≤ 2 over the region
/// to rounding. Empty if T and D do not overlap (or overlap on a set of zero area).
std::vector<PlanePoint> triangle_disc_quadrature(const std::array<Vec2, 3>& triangle,
                                                 const Vec2& centre, double radius);

}  // namespace vessel
