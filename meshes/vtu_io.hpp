#pragma once
/// VTU (VTK XML unstructured grid) output of a tetrahedral mesh with point and cell fields, for
/// ParaView, and a reader of ASCII .vtu files (any cell types) with their point and cell fields.
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

/// What an ASCII .vtu file holds: points, cells (of any VTK types), point and cell fields.
struct VtuData {
  std::vector<Vec3> points;
  std::vector<int> cell_types;            ///< VTK type of each cell
  std::vector<std::size_t> offsets;       ///< end of each cell in connectivity (VTK's offsets)
  std::vector<std::size_t> connectivity;  ///< point indices, cell after cell
  std::vector<VtuField> point_fields;
  std::vector<VtuField> cell_fields;
  /// The point field of that name, or nullptr.
  [[nodiscard]] const VtuField* point_field(const std::string& name) const;
  [[nodiscard]] const VtuField* cell_field(const std::string& name) const;
};

/// Reads a .vtu (UnstructuredGrid, one Piece, DataArrays in format="ascii"; every numeric type is
/// read as double). Throws InputError naming the file and what is wrong: missing or unreadable,
/// not an UnstructuredGrid, binary or appended data, a DataArray whose value count is not
/// components × points (or cells), a value that is not a number, a cell naming a missing point.
VtuData read_vtu(const std::filesystem::path& path);

}  // namespace vessel
