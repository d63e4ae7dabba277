#pragma once
/// Parametric vessels: a straight thick-walled tube and a 180° arch of the same cross-section;
/// and the user's own vessels from a file: a tet mesh (.msh) or a lumen surface (STL) the wall is
/// extruded from (meshes/lumen_mesh.hpp). Lengths in metres.
#include <filesystem>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// `mesh_file`: a tet mesh with the five groups, used as given (one level, 0). `lumen`: an STL
/// lumen surface extruded outward by wall_thickness; levels refine it (meshes/lumen_mesh.hpp).
enum class VesselKind { straight, arch, mesh_file, lumen };

/// How the wall is meshed: unstructured Delaunay tets of size h0/2^level, or a structured
/// (transfinite, extruded) grid of circumferential × axial × radial layers doubled per level.
enum class MeshStyle { unstructured, structured };

/// A lumen's ends as the user lists them (the scene's [vessel] inlet_centre and outlet_centres),
/// when check_lumen's criteria would refuse an end or take a hole for one, or pick another inlet:
/// each open loop must then be one of these, matched by its centre (meshes/lumen_mesh.hpp).
struct ListedEnds {
  Vec3 inlet = Vec3::Zero();  ///< m
  std::vector<Vec3> outlets;  ///< m; empty: no list (the ends are found by the criteria)
  [[nodiscard]] bool given() const { return !outlets.empty(); }
};

struct VesselParams {
  VesselKind kind = VesselKind::straight;
  double inner_radius = 3e-3;    ///< a, m
  double wall_thickness = 1e-3;  ///< t = b − a, m
  double length = 40e-3;         ///< straight tube length, m
  double bend_radius = 15e-3;    ///< arch centreline radius R, m (the arch spans 180°)
  MeshStyle style = MeshStyle::unstructured;
  int level = 0;  ///< refinement level 0..4; each level halves the element size
  /// mesh_file and lumen: the file (absolute, or relative to the working directory).
  std::filesystem::path file;
  /// lumen: the file's length unit in metres (1e-3 for an STL in millimetres).
  double file_scale = 1.0;
  /// lumen: its ends listed by the user (none: found by check_lumen's criteria).
  ListedEnds listed_ends;

  /// straight or arch: the vessel is given by the parameters above, not by a file.
  [[nodiscard]] bool parametric() const {
    return kind == VesselKind::straight || kind == VesselKind::arch;
  }
  [[nodiscard]] double outer_radius() const { return inner_radius + wall_thickness; }
  /// Length of the centreline, m: L for the tube, πR for the arch.
  [[nodiscard]] double centreline_length() const;
};

inline constexpr int kMaxMeshLevel = 4;

/// Throws InputError naming the parameter, the value and the allowed range when the vessel cannot
/// be built (non-positive or non-finite sizes, a wall reaching the bend's axis, a bad level; for a
/// file: no file, a level other than 0 for a mesh file, a bad thickness or unit scale of a lumen).
void validate(const VesselParams& params);

/// InputError naming `what` unless the vessel is parametric (straight or arch): for the things
/// that need its centreline or its closed-form geometry.
void require_parametric(const VesselParams& params, const std::string& what);

/// Closed-form wall volume, m³: π(b²−a²)L for the tube; for the arch, Pappus' theorem gives the
/// torus segment π(b²−a²)·πR.
double analytic_wall_volume(const VesselParams& params);
/// Closed-form area of the lateral wall of radius r (a or b), m²: 2πr·L, or 2πr·πR for the arch.
double analytic_lateral_area(const VesselParams& params, double radius);
/// Closed-form area of one end face, m²: π(b²−a²).
double analytic_end_area(const VesselParams& params);

/// Distance of a point from the vessel centreline, m (the local radius ρ of the cross-section).
double distance_from_centreline(const VesselParams& params, const Vec3& p);

/// A point's position relative to the parametric vessel's centreline (InputError for a file): arc length s along it (m; z for the
/// tube, Rφ for the arch with φ = atan2(y, x)), distance ρ from it (m), the angle θ around it
/// (rad, in (−π, π]; θ = 0 at +x for the tube and on the outer bend, away from the arch's centre)
/// and the unit vector e_ρ from the centreline to the point.
struct CentrelineCoordinates {
  double s = 0.0;
  double rho = 0.0;
  double theta = 0.0;
  Vec3 e_rho = Vec3::UnitX();
};
CentrelineCoordinates centreline_coordinates(const VesselParams& params, const Vec3& p);

/// Structured grid counts at the params' level.
struct StructuredCounts {
  int circumferential = 0;  ///< divisions around the circumference (multiple of 4)
  int axial = 0;            ///< divisions along the centreline
  int radial = 0;           ///< divisions through the wall
  [[nodiscard]] long expected_nodes() const {
    return static_cast<long>(circumferential) * (axial + 1) * (radial + 1);
  }
};
StructuredCounts structured_counts(const VesselParams& params);

/// Target element size of the unstructured mesh at the params' level, m: t / 2^level.
double unstructured_mesh_size(const VesselParams& params);

std::string to_string(VesselKind kind);
std::string to_string(MeshStyle style);
/// One line describing the vessel in mm, for logs and reports.
std::string describe(const VesselParams& params);

}  // namespace vessel
