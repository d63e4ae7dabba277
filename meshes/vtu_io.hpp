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

/// Writes the tets atomically as an ASCII .vtu. Each point field must have components × nodes
/// values and each cell field components × tets values (std::invalid_argument otherwise).
void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuField>& point_fields = {},
               const std::vector<VtuField>& cell_fields = {});

}  // namespace vessel
