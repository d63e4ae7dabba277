#pragma once
/// Tetrahedral mesh quality: dihedral angles, radius ratio, edge lengths, volumes.
#include <string>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// min / max / mean / standard deviation of a quantity over elements or edges.
struct Stats {
  double min = 0.0;
  double max = 0.0;
  double mean = 0.0;
  double stddev = 0.0;
  std::size_t count = 0;
};

struct MeshQuality {
  Stats dihedral_deg;    ///< all six dihedral angles of every tet, degrees (regular tet: 70.53°)
  Stats radius_ratio;    ///< 3·inradius/circumradius per tet (1 regular, → 0 degenerate)
  Stats edge_length;     ///< unique edges, m
  Stats volume;          ///< signed tet volumes, m³
  double total_volume = 0.0;
  std::size_t inverted = 0;    ///< tets with negative signed volume
  std::size_t degenerate = 0;  ///< tets with |V| < 1e-8 × (mean edge)³ (zero volume)
};

/// Per-tet quality values (for VTU output).
struct TetQuality {
  double volume = 0.0;
  double radius_ratio = 0.0;
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
};
/// The six interior dihedral angles of a tet, degrees.
std::array<double, 6> dihedral_angles_deg(const Vec3& a, const Vec3& b, const Vec3& c,
                                          const Vec3& d);
TetQuality tet_quality(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

MeshQuality compute_quality(const TetMesh& mesh);

/// Multi-line human-readable summary in mm, mm³ and degrees.
std::string format_quality(const MeshQuality& q);

/// A tet is a sliver when a dihedral angle is below kSliverMinDihedralDeg or above
/// kSliverMaxDihedralDeg. Near 180° the P1 gradient's error grows without bound (the maximum-angle
/// condition, Babuška & Aziz 1976, SIAM J. Numer. Anal. 13(2)); near 0° the stiffness matrix's
/// condition grows as 1/sin θ. At these bounds a wall's P1 solution can be far from its P2 one
/// (38 % relative L2 on a bifurcation with 0.46° and 178.4° tets), so results on such a mesh
/// include the mesh's error.
inline constexpr double kSliverMinDihedralDeg = 2.0;
inline constexpr double kSliverMaxDihedralDeg = 175.0;

/// The slivers of a mesh: how many, and the worst (the sliver with the smallest dihedral angle),
/// beside the mesh's extreme dihedral angles over all tets.
struct SliverReport {
  std::size_t count = 0;
  double min_dihedral_deg = 180.0;     ///< smallest dihedral angle of any tet, degrees
  double max_dihedral_deg = 0.0;       ///< largest dihedral angle of any tet, degrees
  Vec3 worst_centroid = Vec3::Zero();  ///< m
  double worst_min_dihedral_deg = 180.0;
  double worst_max_dihedral_deg = 0.0;  ///< the worst tet's largest angle
};
SliverReport find_slivers(const TetMesh& mesh);

/// "WARNING: ..." naming the count, the worst tet's angles and position (mm) and the thresholds;
/// empty when the mesh has no sliver.
std::string sliver_warning(const SliverReport& slivers);

}  // namespace vessel
