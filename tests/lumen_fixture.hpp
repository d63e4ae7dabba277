#pragma once
/// Lumen surfaces for the tests of vessels from files (meshes/lumen_mesh.hpp): a bifurcation made
/// by gmsh's OpenCASCADE kernel, and straight polygonal tubes built by hand whose wall has a
/// closed-form volume.
#include <filesystem>

#include "meshes/stl_io.hpp"

namespace vessel::test {

/// A curved tube (a torus segment of `angle` about the z axis, centreline radius `bend_radius`,
/// lumen radius `radius`) with a side branch (a cylinder of `branch_radius` leaving the outer bend
/// at half the angle, radially, `branch_length` beyond the main tube's wall). Metres.
struct BifurcationSpec {
  double radius = 3e-3;
  double bend_radius = 15e-3;
  double angle = 1.5707963267948966;  // 90°
  double branch_radius = 2e-3;
  double branch_length = 8e-3;
  double mesh_size = 1.2e-3;
};

/// The bifurcation's lumen: gmsh OCC fuses the torus segment and the cylinder, meshes the fused
/// volume's boundary, and the three planar caps are dropped. Each triangle is oriented away from
/// the axis of the part it lies on (outward, into the wall), decided from the construction's
/// geometry, not by the code under test.
TriangleSurface bifurcation_lumen(const BifurcationSpec& spec = {});

/// Writes bifurcation_lumen(spec) as a binary STL.
void write_bifurcation_stl(const std::filesystem::path& path, const BifurcationSpec& spec = {});

/// A Y-bifurcation: a parent tube of `parent_radius` along z from z = −`length` to the origin, a
/// junction ball of `junction_radius` at the origin, and two daughters of `daughter_radius`
/// leaving it in the xz plane at ±`half_angle` from z, `length` long. With `holes`, the ball's two
/// caps beyond |y| = √(junction_radius² − hole_radius²) are cut off by planes: two planar holes of
/// radius `hole_radius` in the junction's wall (only the ball reaches past |y| = 3 mm there), as a
/// segmentation may leave. Metres.
struct YBifurcationSpec {
  double parent_radius = 3e-3;
  double daughter_radius = 2.2e-3;
  double junction_radius = 3.5e-3;
  double half_angle = 0.6108652381980153;  // 35°
  double length = 12e-3;
  bool holes = false;
  double hole_radius = 1.3e-3;
  double mesh_size = 0.8e-3;
};

/// The Y-bifurcation's lumen meshed by gmsh OCC (the fused solids' planar faces, its three end caps
/// and the holes' discs, dropped), each triangle oriented away from the centre or axis of the part
/// it lies on.
TriangleSurface y_bifurcation_lumen(const YBifurcationSpec& spec = {});

/// A straight open tube along z: a regular `sides`-gon of vertex radius `radius` (a vertex at
/// θ = 0) repeated at `rings` + 1 stations over `length`, two triangles per quad, normals outward.
TriangleSurface polygon_tube(double radius, double length, int sides, int rings);

}  // namespace vessel::test
