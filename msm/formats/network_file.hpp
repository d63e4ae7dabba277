#pragma once
/// Spring networks from files, and built-in networks written to them (docs/user_guide/network_format.md):
/// a user's own mass-spring model as nodes (rest positions), springs (two nodes, stiffness, rest
/// length, optionally seed 001's bilinear k2 and threshold, axial damping), nodal masses, and
/// supports (fixed nodes, or the mesh groups whose supports the nodes on them follow).
///
/// Two formats with the same content, chosen by the file's extension:
/// - .json, schema "vesselverify.network" version 1 (msm/formats/network.schema.json);
/// - .vtu, line cells with the springs' cell data and the nodes' point data (ParaView opens it).
/// Reading is strict: every problem is an InputError naming the file, the item ("springs[12]",
/// "nodes[3]") and what was expected. SI units: m, kg, N/m, N·s/m.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/model/build_network.hpp"

namespace vessel::msm {

/// The format's name and version (the JSON's "format" and "version"; the VTU's field data).
inline constexpr std::string_view kNetworkFormat = "vesselverify.network";
inline constexpr int kNetworkFormatVersion = 1;

/// A spring network as a file holds it.
struct NetworkFile {
  std::string description;
  /// Nodes, springs (a, b, rest length, law, damping, family); source_node all −1, no triangles
  /// or tets.
  SpringNetwork network;
  std::vector<double> masses;  ///< kg per node
  NetworkSupports supports;
};

/// Checks a network: finite node positions, one mass > 0 per node, each spring joining two
/// different nodes in range with stiffness > 0, rest length > 0, a bilinear law given whole
/// (k2 > 0 and threshold > 0 m, both or neither), damping ≥ 0, no two springs on the same pair,
/// every node in some spring, fixed nodes in range and unique, group names non-empty and unique.
/// InputError "source: item: found ..., expected ...".
void validate_network(const NetworkFile& file, const std::string& source);

/// Reads a .json or .vtu network file (by extension; InputError otherwise) and validates it.
NetworkFile read_network_file(const std::filesystem::path& path);
/// The JSON format from text; `source` names it in messages.
NetworkFile parse_network_json(std::string_view text, const std::string& source);

/// Writes a validated network as .json or .vtu (by extension), atomically. InputError for another
/// extension or a network validate_network refuses.
void write_network_file(const std::filesystem::path& path, const NetworkFile& file);

/// The file of a built network, with the given supports. InputError if the network carries a
/// volume term or a bending term (the format holds springs only).
NetworkFile network_file_of(const BuiltNetwork& built, NetworkSupports supports,
                            std::string description);

/// Two points are the same node when closer than this fraction of the mesh's bounding-box
/// diagonal (coordinates printed with ~7 significant digits still match).
inline constexpr double kNodeMatchTolerance = 1e-6;

/// The network of a file placed on a vessel mesh: source_node[i] is the mesh node at node i's
/// position (within kNodeMatchTolerance of the mesh's size), else −1 (the scene's loads on mesh
/// nodes the network lacks go to the nearest network node, as for built-in networks); the file's
/// supports are recorded. Throws InputError naming the file if a fixed node or followed group is
/// wrong for this mesh (a group it does not have).
BuiltNetwork network_on_mesh(const NetworkFile& file, const TetMesh& mesh,
                             const std::string& source);

/// Throws InputError naming `source` if any node lies outside the mesh by more than `tolerance`
/// (barycentric, as the reference's point evaluation allows): the first few indices, how many,
/// and their largest distance from the mesh's boundary, mm.
void require_nodes_inside(const std::vector<Vec3>& nodes, const TetMesh& mesh, double tolerance,
                          const std::string& source);

}  // namespace vessel::msm
