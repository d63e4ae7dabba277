#pragma once
/// VTU (VTK XML unstructured grid) output of a tetrahedral mesh with point and cell fields, for
/// ParaView.
#include <filesystem>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// A field with `components` values per point (or per tet), stored point-major.
struct VtuField {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// Cells of one VTK type, each with the same number of points, stored cell-major.
struct VtuCells {
  int vtk_type = 10;        ///< 3 line, 5 triangle, 10 tetrahedron (VTK's cell type numbers)
  int points_per_cell = 4;
  std::vector<std::size_t> connectivity;
};

/// Tets as VTK tetrahedra.
VtuCells tet_cells(const std::vector<Tet>& tets);

/// Writes the points and cells atomically as an ASCII .vtu. Each point field must have
/// components × points values and each cell field components × cells values, and every
/// connectivity entry must name a point (std::invalid_argument otherwise).
void write_vtu(const std::filesystem::path& path, const std::vector<Vec3>& points,
               const VtuCells& cells, const std::vector<VtuField>& point_fields = {},
               const std::vector<VtuField>& cell_fields = {});

/// The mesh's tets as VTK tetrahedra (write_vtu above).
void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuField>& point_fields = {},
               const std::vector<VtuField>& cell_fields = {});

}  // namespace vessel
