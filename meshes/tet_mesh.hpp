#pragma once
/// The mesh every model is built on: linear tetrahedra of the vessel wall plus the triangles of its
/// named boundary groups, sharing one node array (so the surface models, the volume model and the
/// FEM can be compared node by node). Lengths in metres.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products on Vec3 everywhere
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace vessel {

using Vec3 = Eigen::Vector3d;
using Tet = std::array<int, 4>;
using Triangle = std::array<int, 3>;

/// The physical-group names of a vessel mesh (the project's convention, also for user meshes).
namespace group_names {
inline constexpr std::string_view inlet = "inlet";
inline constexpr std::string_view outlet = "outlet";
inline constexpr std::string_view inner_wall = "inner_wall";
inline constexpr std::string_view outer_wall = "outer_wall";
inline constexpr std::string_view wall = "wall";
}  // namespace group_names

/// Name, dimension and gmsh physical tag of each group of a generated vessel mesh. deal.II reads
/// the surface tags as boundary ids and the volume tag as the material id.
struct GroupSpec {
  std::string_view name;
  int dim;
  int tag;
};
inline constexpr std::array<GroupSpec, 5> kVesselGroups{{{group_names::inlet, 2, 1},
                                                         {group_names::outlet, 2, 2},
                                                         {group_names::inner_wall, 2, 3},
                                                         {group_names::outer_wall, 2, 4},
                                                         {group_names::wall, 3, 10}}};

/// Throws InputError naming `source` unless every group of kVesselGroups is present and non-empty.
struct TetMesh;
void require_vessel_groups(const TetMesh& mesh, std::string_view source);

/// A named set of elements: triangles (dim 2) or tetrahedra (dim 3), as indices into
/// TetMesh::triangles or TetMesh::tets.
struct PhysicalGroup {
  std::string name;
  int dim = 0;
  int tag = 0;  ///< gmsh physical tag (deal.II reads it as boundary or material id)
  std::vector<int> elements;
};

struct TetMesh {
  std::vector<Vec3> nodes;
  std::vector<Tet> tets;            ///< positively oriented (signed volume > 0) unless inverted
  std::vector<Triangle> triangles;  ///< boundary triangles, outward after orient_boundary_outward
  std::vector<PhysicalGroup> groups;

  /// The group of that name and dimension, or nullptr.
  [[nodiscard]] const PhysicalGroup* find_group(std::string_view name, int dim) const;
  /// The group, or an InputError naming `source` (a file or "generated mesh") and what is missing.
  [[nodiscard]] const PhysicalGroup& require_group(std::string_view name, int dim,
                                                   std::string_view source) const;
  /// Sorted, unique node indices used by the group's elements.
  [[nodiscard]] std::vector<int> group_nodes(const PhysicalGroup& group) const;
  /// The group's triangles (std::invalid_argument unless the group has dim 2).
  [[nodiscard]] std::vector<Triangle> group_triangles(const PhysicalGroup& group) const;
};

/// Signed volume of a tetrahedron, m³ (positive when (b−a, c−a, d−a) is right-handed).
double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
/// Tets of `mesh` with non-positive signed volume when its nodes are at `x` (one per node).
std::size_t inverted_tets(const TetMesh& mesh, const std::vector<Vec3>& x);
/// Area of a triangle, m².
double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c);
/// The point of triangle (a, b, c) nearest to x: x's projection on the plane if it falls inside,
/// else the nearest point of the nearest edge.
Vec3 closest_point_on_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& x);

/// The point of the group's triangles nearest x (InputError naming `source` unless the group exists
/// with dimension 2 and has triangles): how a contact point given for a vessel from a file is put
/// on its wall.
Vec3 nearest_point_on_group(const TetMesh& mesh, std::string_view group, const Vec3& x,
                            std::string_view source);

/// The wall thickness of a vessel mesh, m: the median distance of the outer wall's nodes from the
/// inner wall's triangles (at most 400 nodes, evenly strided, so large meshes stay cheap). For a
/// mesh file whose scene gives no thickness (the surface models' shell thickness).
double estimate_wall_thickness(const TetMesh& mesh, std::string_view source);

/// The tetrahedra's edges, each once as (smaller, larger) node index, in ascending order.
std::vector<std::array<int, 2>> unique_edges(const TetMesh& mesh);

/// Total volume of the tetrahedra, m³.
double mesh_volume(const TetMesh& mesh);
/// Total area of the group's triangles, m².
double group_area(const TetMesh& mesh, const PhysicalGroup& group);

/// The faces of the tetrahedra that belong to exactly one tet, each oriented outward.
std::vector<Triangle> boundary_faces(const TetMesh& mesh);

/// If more tets have a negative signed volume than a positive one (a file's orientation
/// convention), swaps the last two vertices of each so that the majority is positive; returns
/// whether it did. A mesh with both signs keeps the minority: those are inverted elements, which
/// require_positive_volumes refuses and mesh quality reports.
bool orient_tets(TetMesh& mesh);

/// Where a tet came from in a file, for messages: its 1-based line, the file's element tag and its
/// node tags in the mesh's (oriented) vertex order.
struct ElementOrigin {
  long line = 0;
  std::size_t tag = 0;
  std::array<std::size_t, 4> node_tags{};
};

/// A tet has zero volume when |V| ≤ kZeroVolumeTolerance · ℓ³, ℓ its longest edge (a regular tet
/// has V = ℓ³/(6√2) ≈ 0.12 ℓ³; rounding of the coordinates gives |V| ~ 1e-16 ℓ³·|x|/ℓ): flat, or
/// with coincident nodes. Relative to each tet's own size, so graded meshes are judged fairly.
inline constexpr double kZeroVolumeTolerance = 1e-12;

/// Throws InputError unless every tet has a positive signed volume above the zero-volume
/// tolerance. The message names `source`, the first offending element (with `origins`, one per
/// tet: its line, element tag and node tags; else its index), its signed volume in m³, what was
/// expected, how many tets are bad and the next few of them. `file_flipped`: orient_tets flipped
/// the file's (negative) convention, so volumes are quoted in the file's sign.
void require_positive_volumes(const TetMesh& mesh, std::string_view source,
                              const std::vector<ElementOrigin>& origins = {},
                              bool file_flipped = false);
/// Orients each group triangle that is a face of a tet so its normal points out of that tet.
void orient_boundary_outward(TetMesh& mesh);
/// Canonical element order independent of the mesher's: each element's nodes ascending up to an
/// even permutation (orientation kept), elements sorted by their nodes, groups remapped.
void sort_elements(TetMesh& mesh);
/// Drops nodes not used by any element and renumbers the rest, keeping their order.
void remove_unused_nodes(TetMesh& mesh);

/// Edge-manifold check of a triangle set: every edge shared by exactly two triangles (closed) and
/// traversed once in each direction (consistently oriented).
struct SurfaceTopology {
  std::size_t boundary_edges = 0;        ///< edges with one triangle (0 for a closed surface)
  std::size_t non_manifold_edges = 0;    ///< edges with more than two triangles
  std::size_t inconsistent_edges = 0;    ///< edges traversed twice in the same direction
  [[nodiscard]] bool closed_and_oriented() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0;
  }
};
SurfaceTopology surface_topology(const std::vector<Triangle>& triangles);

/// Volume enclosed by a closed, outward-oriented triangle surface (divergence theorem), m³.
double enclosed_volume(const std::vector<Vec3>& nodes, const std::vector<Triangle>& triangles);

}  // namespace vessel
