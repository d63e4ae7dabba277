#pragma once
/// VTU (VTK XML unstructured grid) files for ParaView: output of points with cells of one type
/// (tets, triangles, lines) and named point, cell and field data arrays, and input of the ASCII
/// files of that kind (this writer's, or ParaView's with "Data Mode: Ascii").
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
/// connectivity entry must name a point (std::invalid_argument otherwise). `field_data`: arrays
/// of the whole dataset (VTK's FieldData; components × tuples values, any count).
void write_vtu(const std::filesystem::path& path, const std::vector<Vec3>& points,
               const VtuCells& cells, const std::vector<VtuField>& point_fields = {},
               const std::vector<VtuField>& cell_fields = {},
               const std::vector<VtuField>& field_data = {});

/// An ASCII .vtu as read: points, cells of any types (VTK's connectivity, offsets and types
/// arrays) and every named data array as Float64 values (integers converted).
struct VtuData {
  std::vector<Vec3> points;
  std::vector<std::size_t> connectivity;
  std::vector<std::size_t> offsets;  ///< end of each cell in connectivity (VTK's convention)
  std::vector<int> types;            ///< VTK cell type per cell
  std::vector<VtuField> point_fields, cell_fields, field_data;

  /// The array of that name among `fields`, or nullptr.
  static const VtuField* find(const std::vector<VtuField>& fields, const std::string& name);
};

/// Reads an UnstructuredGrid .vtu with one piece and ASCII data arrays. Throws InputError naming
/// the file and what was found where something else was expected: not a VTU, binary or appended
/// data (expected format="ascii"), a value that is not a number, an array whose value count does
/// not match the points or cells, offsets that do not fit the connectivity, a connectivity entry
/// beyond the points.
VtuData read_vtu(const std::filesystem::path& path);

/// The mesh's tets as VTK tetrahedra (write_vtu above).
void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuField>& point_fields = {},
               const std::vector<VtuField>& cell_fields = {});

}  // namespace vessel
