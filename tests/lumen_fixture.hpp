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

/// A straight open tube along z: a regular `sides`-gon of vertex radius `radius` (a vertex at
/// θ = 0) repeated at `rings` + 1 stations over `length`, two triangles per quad, normals outward.
TriangleSurface polygon_tube(double radius, double length, int sides, int rings);

}  // namespace vessel::test
