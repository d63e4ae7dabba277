#pragma once
/// Spring networks: which node pairs are connected, in which family, with which rest length.
/// Built on a tetrahedral mesh (seed 001, volume model) or on a wall surface (seeds 000 and 002,
/// surface model). Stiffness and masses are assigned separately (stiffness/, mass/).
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "meshes/stl_io.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel::msm {

/// Material law of one spring: Hooke (seed 000 eq. 3.2) when `threshold` is infinite, else the
/// bilinear spring of seed 001 eq. (1): stiffness k1 up to the threshold elongation Δx_c (m),
/// k2 beyond it. Compression (negative elongation) always uses k1, as in the seed, whose
/// threshold is on the elongation.
struct SpringLaw {
  double k1 = 0.0;                                             ///< N/m
  double k2 = 0.0;                                             ///< N/m, used beyond the threshold
  double threshold = std::numeric_limits<double>::infinity();  ///< Δx_c, m
};

/// Spring families. Surface model (seed 000 §II.B): structural (grid neighbours / mesh edges),
/// shear ("twisted", grid diagonals), bend ("stretch", grid neighbours one node apart; on a
/// triangle mesh the two opposite vertices of two triangles sharing an edge), optional two-ring.
/// Volume model (seed 001, Mollemans): one spring per tetrahedron edge.
enum class SpringFamily { structural, shear, bend, two_ring, volume };
inline constexpr std::array<SpringFamily, 5> kAllFamilies{
    SpringFamily::structural, SpringFamily::shear, SpringFamily::bend, SpringFamily::two_ring,
    SpringFamily::volume};
std::string to_string(SpringFamily family);

struct Spring {
  int a = 0;
  int b = 0;
  double rest_length = 0.0;  ///< m
  SpringFamily family = SpringFamily::structural;
  SpringLaw law;         ///< stiffness (set by a stiffness rule)
  double damping = 0.0;  ///< axial damping k_d, N·s/m (seed 000 eq. 3.4)
};

/// A spring network on its own node array (the mesh's nodes for the volume model, the surface's
/// nodes for a surface model). `source_node[i]` is node i's index in the TetMesh (−1 if none).
struct SpringNetwork {
  std::vector<Vec3> nodes;  ///< rest positions, m
  std::vector<int> source_node;
  std::vector<Spring> springs;
  /// Triangles of the surface model (empty for the volume model), for masses and PBD bending.
  std::vector<Triangle> triangles;
  std::vector<Tet> tets;   ///< tets of the volume model (empty for surfaces)
  /// Per tet, a factor on the volume term's κ (the homogenised rule's stability clip,
  /// msm/terms/volume_term_homogenised.hpp); empty: all 1.
  std::vector<double> tet_kappa_factors;
  double thickness = 0.0;  ///< wall thickness t carried by a surface model, m
  [[nodiscard]] std::size_t count(SpringFamily family) const;
};

/// Volume model, seed 001 (after Mollemans): every edge of the tetrahedral mesh exactly once.
SpringNetwork build_volume_network(const TetMesh& mesh);

/// Surface model on any triangle mesh (gmsh surface or STL): structural = the edges; bend = the
/// two opposite vertices of each pair of triangles sharing an edge; with `two_ring`, also every
/// pair of nodes two edges apart not already connected.
SpringNetwork build_triangle_network(const TriangleSurface& surface, double thickness,
                                     bool two_ring = false);

/// (i, j) grid indices of the nodes of a structured tube surface: i circumferential (periodic,
/// 0..n_circ−1), j axial (0..n_axial).
struct GridIndex {
  int i = 0;
  int j = 0;
};

/// Recovers the grid indices of the surface nodes of a structured vessel mesh from their
/// circumferential angle and axial position (straight tube: atan2(y, x) and z; arch: the angle
/// about the arch axis and the section angle). Throws InputError if the nodes do not form the
/// n_circ × (n_axial+1) grid (an unstructured mesh, or another level).
std::vector<GridIndex> recover_tube_grid(const std::vector<Vec3>& nodes, const VesselParams& params,
                                         int n_circ, int n_axial);

/// Surface model on a structured tube grid with seed 000's three families exactly: structural
/// (i±1, j) and (i, j±1); shear ("twisted") the diagonals (i+1, j+1) and (i+1, j−1); bend
/// ("stretch") (i±2, j) and (i, j±2). The circumferential direction is periodic.
SpringNetwork build_tube_grid_network(const TriangleSurface& surface, const VesselParams& params,
                                      double thickness);

/// Which wall surface a surface model is built on.
enum class WallSurface { inner, outer, mid };
WallSurface parse_wall_surface(const std::string& name);
std::string to_string(WallSurface surface);  ///< "inner" | "outer" | "mid"

/// The wall surface of a vessel mesh: inner or outer wall triangles, or the mid-surface (the
/// inner-wall triangles with their nodes moved radially to the centreline distance a + t/2).
/// source_node always refers to the mesh nodes of the chosen wall (inner wall for mid).
TriangleSurface wall_surface(const TetMesh& mesh, const VesselParams& params, WallSurface which);

/// Position on the vessel's centreline closest to p and the unit radial direction from it.
struct TubeCoordinates {
  double axial = 0.0;  ///< arc length along the centreline, m
  double theta = 0.0;  ///< section angle, rad in (−π, π]
  double rho = 0.0;    ///< distance from the centreline, m
  Vec3 centre = Vec3::Zero();
  Vec3 radial = Vec3::Zero();
};
TubeCoordinates tube_coordinates(const VesselParams& params, const Vec3& p);

}  // namespace vessel::msm
