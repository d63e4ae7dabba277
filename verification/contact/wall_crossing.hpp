#pragma once
/// Whether the wire's centreline crosses the wall's inner surface. The contact's slaves are the
/// wall's nodes, so a wall whose node spacing exceeds the wire's diameter where it bears lets the
/// capsule pass between nodes: every node's gap stays non-negative while the centreline is
/// through the wall, and the solve "converges" on a wire outside the lumen. A centreline segment
/// that intersects a (deformed) inner-wall triangle is that failure, seen directly.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel::contact {

/// Where segment [a, b] meets triangle (p, q, r), by Möller and Trumbore's test ("Fast,
/// minimum storage ray-triangle intersection", J. Graphics Tools 2, 1997): the segment's
/// parameter s ∈ [0, 1] of the crossing, or nullopt (also for a segment in the triangle's plane).
std::optional<double> segment_triangle_crossing(const Vec3& a, const Vec3& b, const Vec3& p,
                                                const Vec3& q, const Vec3& r);

struct WallCrossing {
  int segment = 0;            ///< the centreline segment's first node
  int triangle = 0;           ///< index into the triangles given
  Vec3 point = Vec3::Zero();  ///< where it crosses, m
  double longest_edge = 0.0;  ///< the crossed triangle's longest edge as displaced, m
};

/// The first centreline segment (nodes `centreline`, in order) crossing one of `triangles` of
/// `mesh` displaced by `displacement` (per mesh node, m), or nullopt.
std::optional<WallCrossing> first_wall_crossing(const TetMesh& mesh,
                                                const std::vector<Triangle>& triangles,
                                                const std::vector<Vec3>& displacement,
                                                const std::vector<Vec3>& centreline);

/// Why a solved (or iterated) centreline ends up across the wall: the gaps of the nodes it passed
/// between are open again on the far side, so nothing held it back. Whether the wall's nodes are
/// too far apart there (refine it) or its elements are dented past what they hold (a linear wall
/// far beyond its validity) the crossed triangle's deformed edge, against the wire's diameter,
/// tells.
inline constexpr const char* kPassedBetweenNodes = "it passed between the wall's nodes";

/// Where the crossing is, as a clause for a failed solve ("the wire's centreline crosses the wall
/// at (x, y, z) mm (segment k), through a triangle whose longest edge is e mm as deformed"); the
/// caller says why.
std::string describe(const WallCrossing& crossing);

/// Where `centreline` crosses `mesh`'s inner wall (group "inner_wall") displaced by
/// `displacement`, as a sentence for a failed solve ("the wire's centreline crosses the wall at
/// (x, y, z) mm (segment k): ..."), or nullopt when it stays inside the lumen.
std::optional<std::string> describe_wall_crossing(const TetMesh& mesh,
                                                  const std::vector<Vec3>& displacement,
                                                  const std::vector<Vec3>& centreline);

}  // namespace vessel::contact
