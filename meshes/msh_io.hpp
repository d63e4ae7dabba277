#pragma once
/// Reading and writing gmsh `.msh` files (ASCII formats 2.2 and 4.1) without the gmsh library, so
/// every parse error can name the file and line. Linear tetrahedra (type 4) and triangles (type 2)
/// are kept; points and lines are skipped; any other element type is an error.
#include <filesystem>
#include <istream>
#include <string>

#include "meshes/tet_mesh.hpp"

namespace vessel {

enum class MshVersion { v22, v41 };

/// Reads an ASCII `.msh` 2.2 or 4.1 file. Node indices are renumbered 0.. in file order, unused
/// nodes dropped, tets flipped if the file's convention makes most of them negative, and group
/// triangles that are tet faces oriented outward. Throws InputError naming the file and line for a missing, truncated, binary or
/// malformed file, a non-finite coordinate, an unknown node tag, or an inverted or zero-volume
/// tet (require_positive_volumes: its line, element tag and signed volume). Does not require any group:
/// call require_vessel_groups for that.
TetMesh read_msh(const std::filesystem::path& path);
/// Same, from a stream; `source` names it in messages.
TetMesh parse_msh(std::istream& in, const std::string& source);

/// Writes the mesh atomically as ASCII `.msh` (one entity per physical group).
void write_msh(const std::filesystem::path& path, const TetMesh& mesh,
               MshVersion version = MshVersion::v41);

/// Writes the mesh as ASCII `.msh` to a stream.
void write_msh(std::ostream& out, const TetMesh& mesh, MshVersion version = MshVersion::v41);

/// The mesh exactly as write_msh then read_msh give it back (triangles in group order, faces
/// oriented outward, coordinates bitwise): a generated mesh used in this form is the same mesh,
/// element for element, as the one a later run reads from the cache, so both key and solve the
/// same FEM problem.
TetMesh as_stored(const TetMesh& mesh);

}  // namespace vessel
