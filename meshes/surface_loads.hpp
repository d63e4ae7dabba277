#pragma once
/// Loads defined once on the mesh's own surface triangles and tets, shared by the FEM reference
/// (which integrates the same tractions) and the mass-spring models (which receive the consistent
/// nodal loads), so both see the same total force over the same area. Free of deal.II. SI units.
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// A catheter-tip contact: normal force `force` (N) spread uniformly over the disc of `radius` (m)
/// about `point` on the wall `surface_group`. A point force would give infinite displacement in
/// the continuum (Kelvin's solution ~ 1/r); a patch does not.
struct ContactPatchSpec {
  Vec3 point = Vec3::Zero();
  double radius = 0.5e-3;
  double force = 0.0;  ///< N, pushing into the wall (positive) along the patch's inward normal
  /// The force's direction into the wall, when it is given by what pushes (a guidewire pushes
  /// along the exact lumen's normal); zero: the patch's inward mean normal.
  Vec3 direction = Vec3::Zero();
  std::string surface_group = "inner_wall";
};

/// A quadrature point of a surface load on one boundary triangle: barycentric coordinates with
/// respect to the triangle's nodes (in TetMesh::triangles order) and a weight (m², the area it
/// stands for). The FEM and the mass-spring models integrate a patch's traction over the same
/// points, so both see the same force distribution: ∫ t N_i dA ≈ Σ_q w_q t N_i(ξ_q).
struct SurfacePoint {
  int triangle = -1;                 ///< index into TetMesh::triangles
  Vec3 barycentric = Vec3::Zero();   ///< (λ0, λ1, λ2), summing to 1
  double weight = 0.0;               ///< m²
};

/// A uniform traction (Pa, a vector) over part of the boundary, given by quadrature points.
struct TractionPatch {
  std::vector<int> triangles;        ///< indices into TetMesh::triangles the patch touches
  std::vector<SurfacePoint> points;  ///< the quadrature of the loaded region
  Vec3 traction = Vec3::Zero();
  double area = 0.0;                 ///< m², the sum of the points' weights
  Vec3 outward_normal = Vec3::Zero();  ///< area-weighted mean outward unit normal of the patch
  Vec3 centre = Vec3::Zero();          ///< the contact point on the wall (contact patches)
  /// m², a contact patch's area projected on the wall's tangent plane at the centre: π r_c²
  /// unless the disc reaches past the wall's edge (an end of the vessel).
  double projected_area = 0.0;
};

/// Quadrature points covering whole triangle `triangle` (area `area`, m²): the symmetric 3-point
/// rule, exact for polynomials of degree 2 (Strang & Fix), so P1 and P2 load vectors equal the
/// exact integrals of a uniform traction.
std::vector<SurfacePoint> whole_triangle_points(int triangle, double area);

/// The contact patch: the exact disc of radius r_c on the wall, and its traction t = −F n̂ / A (n̂
/// the patch's mean outward normal, A its area), so ∫ t dA = −F n̂ exactly.
/// - The centre is the point of the group's surface nearest `spec.point` (a point given off the
///   faceted wall, e.g. on the exact cylinder, is projected onto it).
/// - The disc lies in the wall's tangent plane at the centre (normal: the mean outward normal of
///   the triangles within r_c). Each facing triangle is projected onto that plane, clipped to the
///   disc with its arcs (triangle_disc_quadrature) and the quadrature points are carried back to
///   the triangle with their barycentric coordinates and weights divided by the projection's
///   cosine. So the patch covers exactly π r_c² of the tangent plane at every mesh level, and its
///   wall area exceeds that only by the wall's curvature within the disc (1 + O(r_c²/R²)).
/// Throws InputError naming the group if it is missing, if the nearest point of the wall is
/// farther than r_c from `spec.point` (a contact point off the wall), if the wall covers the disc
/// more than once (it folds back within r_c), or if radius or force is not finite or radius ≤ 0.
TractionPatch contact_patch(const TetMesh& mesh, const ContactPatchSpec& spec);

/// The triangles a pressure acts on (the group's, InputError if missing). Pressure p (Pa) gives
/// traction −p n on each, n the outward normal, pushing the inner wall away from the lumen for
/// p > 0; the FEM integrates that, the nodal version is pressure_nodal_loads.
std::vector<int> pressure_triangles(const TetMesh& mesh, const std::string& group);

/// Consistent nodal loads (N per node, indexed like mesh.nodes) of linear triangles under the
/// patch's uniform traction: Σ_q w_q t λ_k(ξ_q) to node k of each point's triangle (t·A/3 per
/// node for a whole triangle).
std::vector<Vec3> traction_nodal_loads(const TetMesh& mesh, const TractionPatch& patch);
/// Consistent nodal loads of pressure p on the group's triangles: −p n A/3 per triangle node.
std::vector<Vec3> pressure_nodal_loads(const TetMesh& mesh, const std::string& group, double p);
/// Consistent nodal loads of a uniform body force density ρg (N/m³): ρg V/4 per tet node.
std::vector<Vec3> body_force_nodal_loads(const TetMesh& mesh, const Vec3& force_density);

/// Sum of nodal loads (N).
Vec3 total_load(const std::vector<Vec3>& loads);

}  // namespace vessel
