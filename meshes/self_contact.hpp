#pragma once
/// Whether a deformed mesh has passed through itself: the check that stops a finite-strain
/// reference, which models no contact between the wall's own surfaces, where the wall would
/// touch or cross the opposite wall (issue 17).
#include <string_view>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// Boundary nodes of `mesh` that, in the deformed configuration x = X + u, lie inside a
/// tetrahedron they do not belong to.
struct SelfPenetration {
  std::vector<int> nodes;  ///< ascending node indices (empty: no penetration found)
  /// Per entry of `nodes`, one tetrahedron that contains it.
  std::vector<int> tets;
};

/// Tests every node of `mesh.triangles` against the deformed tetrahedra not incident to it: a node
/// counts as inside when its smallest barycentric coordinate exceeds `tolerance` (so a node on a
/// face, where a wall merely touches, does not), and only positively oriented deformed tets are
/// tested (an inverted tet overlaps its neighbours without any contact). The deformed tets are
/// straight-sided, through the deformed vertices: with P2 the curved faces are replaced by their
/// chords. Only vertices are tested, so an edge crossing a face with no vertex through it is found
/// one step later, once a vertex has followed. `displacement`: one per mesh node (m);
/// std::invalid_argument otherwise.
SelfPenetration find_self_penetration(const TetMesh& mesh, const std::vector<Vec3>& displacement,
                                      double tolerance = 1e-6);

/// The smallest deformed distance between two nodes of the boundary group `group` whose rest
/// distance is at least `apart` (m): how close the wall comes to touching itself, e.g. across
/// the lumen with the inner wall and apart = the inner radius. Node to node, so it exceeds the
/// surfaces' true gap by up to about an element size. +∞ when no two nodes are that far apart.
/// InputError naming the group when the mesh has no such triangle group; std::invalid_argument
/// for a displacement count other than the node count.
double closest_approach(const TetMesh& mesh, const std::vector<Vec3>& displacement,
                        std::string_view group, double apart);

}  // namespace vessel
