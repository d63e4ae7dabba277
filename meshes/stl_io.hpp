#pragma once
/// Triangulated STL surfaces (seed 000 reads its vessel from STL) for the surface models.
#include <filesystem>
#include <string>
#include <string_view>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// An indexed triangle surface. `source_node[i]` is the index of node i in the TetMesh it was cut
/// from (−1 when read from STL), so surface and volume results can be compared node by node.
struct TriangleSurface {
  std::vector<Vec3> nodes;
  std::vector<Triangle> triangles;
  std::vector<int> source_node;
};

/// Reads an ASCII or binary STL file, merging vertices with identical coordinates (STL stores each
/// facet's corners separately). Throws InputError naming the file and line (ASCII) or facet
/// (binary) for a missing, empty, truncated or malformed file, a non-finite coordinate or a
/// degenerate facet. Coordinates are taken as metres.
TriangleSurface read_stl(const std::filesystem::path& path);
/// Same, from the file's bytes; `source` names it in messages.
TriangleSurface parse_stl(std::string_view data, const std::string& source);

enum class StlFormat { ascii, binary };
/// Writes the surface atomically. Binary STL stores float32: coordinates round to ~1e-7 relative.
void write_stl(const std::filesystem::path& path, const TriangleSurface& surface,
               StlFormat format = StlFormat::binary);

/// The triangles of the named groups (dim 2) with their nodes compacted, keeping source_node.
TriangleSurface extract_surface(const TetMesh& mesh, const std::vector<std::string>& group_names,
                                std::string_view source);

/// Total area, m².
double surface_area(const TriangleSurface& surface);

/// A surface as a TetMesh without tets: its nodes and triangles, all triangles in one physical
/// group `group` (dimension 2), so the shared surface loads (contact patch, pressure) work on it
/// unchanged. Mesh node i is surface node i.
TetMesh surface_as_mesh(const TriangleSurface& surface, const std::string& group);

}  // namespace vessel
