#pragma once
/// End supports defined once, beside the shared loads (surface_loads.hpp), and used by the FEM
/// reference and the mass-spring models alike: which mesh groups are clamped, which are axial
/// rollers, and the single-dof pins that remove the in-plane rigid motion rollers leave. Free of
/// deal.II. SI units.
#include <map>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel {

/// What holds an end face (the `inlet` and `outlet` groups).
enum class EndCondition {
  clamped,  ///< u = 0
  roller,   ///< u_z = 0 on the end plane (plane strain: the Lamé set-up); straight tube only
  free,
};
std::string to_string(EndCondition condition);
/// "clamped" | "roller" | "free"; InputError naming the value otherwise.
EndCondition parse_end_condition(const std::string& name);

/// One displacement component held at a point (which must be a mesh node).
struct Pin {
  Vec3 point = Vec3::Zero();
  int component = 0;  ///< 0, 1, 2 = x, y, z
};

/// The supports of a problem, as groups and pins.
struct Supports {
  std::vector<std::string> clamped;  ///< groups held in every component
  std::vector<std::string> rollers;  ///< groups held in the axial component (z)
  std::vector<Pin> pins;             ///< single components held at points

  static constexpr int kRollerComponent = 2;  ///< z: the straight tube's axis

  [[nodiscard]] bool holds_nothing() const { return clamped.empty() && rollers.empty(); }
};

/// The three pins that remove the in-plane rigid motion (t_x − θy, t_y + θx) of a tube with roller
/// ends: u_y = 0 at (±a, 0, z) gives t_y = θ = 0, u_x = 0 at (0, a, z) then t_x = 0. A radial
/// field u_r(r) e_r satisfies all three, so they do not disturb Lamé's solution.
std::vector<Pin> tube_in_plane_pins(double inner_radius, double z);

/// The supports given each group's condition (groups missing from `ends` are free; any surface
/// group may be named). Rollers need the straight tube (its ends are normal to z); with rollers
/// and no clamped group the in-plane pins are added on the inlet plane. Throws InputError
/// (prefixed by `where`, e.g. the scene file) for rollers on the arch. Supports that hold nothing
/// are returned as such: the caller decides whether a free body is an error.
Supports end_supports(const VesselParams& vessel, const std::map<std::string, EndCondition>& ends,
                      const std::string& where);

/// The supports on a set of nodes that come from the mesh (`source_node[i]`: node i's mesh node,
/// −1 if none): per dof (3 per node), 1 where held. A node whose mesh node lies in a clamped group
/// is held in every component, in a roller group in z; each pin holds its component at the node
/// nearest the pin's point among the nodes of the roller groups (the network's own nodes on the
/// end plane). Throws InputError if a group is missing or a pin finds no node.
std::vector<char> held_dofs(const TetMesh& mesh, const std::vector<Vec3>& nodes,
                            const std::vector<int>& source_node, const Supports& supports);

/// The same supports on nodes that need not be mesh nodes (a spring network from a file): a node
/// is in a group when it lies within `tolerance` (m) of one of the group's triangles; clamped,
/// roller and pin rules as in held_dofs. Throws InputError if a group is missing or a pin finds
/// no node.
std::vector<char> held_dofs_by_position(const TetMesh& mesh, const std::vector<Vec3>& nodes,
                                        const Supports& supports, double tolerance);

/// The nodes at or below the plane z = `z` (`below`), else at or above it.
std::vector<std::size_t> nodes_beyond_plane_z(const std::vector<Vec3>& nodes, double z, bool below);

/// The nodes on the open boundary of a triangle surface: those of edges that belong to a single
/// triangle (a tube's ends). Empty for a closed surface.
std::vector<std::size_t> open_boundary_nodes(const std::vector<Triangle>& triangles);

}  // namespace vessel
