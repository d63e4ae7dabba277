#pragma once
/// Vessel meshes generated with the gmsh C++ API (built-in kernel: the annular cross-section, made
/// of four quarter patches, is extruded along the tube or revolved around the arch's axis).
#include "meshes/tet_mesh.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel {

struct MeshingOptions {
  bool verbose = false;  ///< let gmsh print its own log
};

/// Generates the tetrahedral wall mesh with the groups of kVesselGroups, tets positively oriented
/// and boundary triangles outward, elements in canonical order. The same params give the same
/// mesh, whatever the process has meshed before and however many threads it runs. Throws
/// InputError for invalid params (see validate) and std::runtime_error if gmsh fails.
TetMesh generate_vessel_mesh(const VesselParams& params, const MeshingOptions& options = {});

/// A parametric vessel with its element size graded from `fine` (m) within `radius` (m) of `point`
/// up to the vessel's nominal size (unstructured_mesh_size, its level) over a 2 mm transition: a
/// finely refined contact patch, as the stability study's hard case and the contact reference
/// use. The straight tube is meshed with gmsh's OpenCASCADE kernel (a cylinder cut from a
/// cylinder; faces classified by their bounding boxes: OCC renumbers them), the arch with the
/// built-in kernel's revolution (as generate_vessel_mesh, unstructured). Groups as in
/// kVesselGroups, tets positively oriented, boundary outward. Throws InputError for invalid params,
/// a vessel from a file or a non-positive fine size; std::runtime_error if gmsh fails.
TetMesh refined_patch_mesh(const VesselParams& params, const Vec3& point, double fine,
                           double radius);

/// A ball the mesh is refined in (m).
struct RefinedBall {
  Vec3 centre = Vec3::Zero();
  double radius = 0.0;
  double size = 0.0;  ///< the element size within it (0: the mesh's fine size)
};

/// As refined_patch_mesh, refined to `fine` (or the ball's own size) within every ball (each
/// graded to the nominal size over 2 mm; the smallest size wins): a contact that bears in several
/// places, or along a wire. InputError also for no ball, a negative radius or a negative size.
TetMesh refined_balls_mesh(const VesselParams& params, const std::vector<RefinedBall>& balls,
                           double fine);

/// The gmsh API version string ("4.8.0"), part of the mesh cache key.
std::string gmsh_version();

}  // namespace vessel
