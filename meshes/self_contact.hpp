#pragma once
/// Whether a deformed mesh has passed through itself: the check that stops a finite-strain
/// reference, which models no contact between the wall's own surfaces, where the wall would
/// touch or cross the opposite wall (issue 17).
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

}  // namespace vessel
