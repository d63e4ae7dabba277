#pragma once
/// A vessel wall built from the user's lumen surface (an STL segmented from CT, seed 000's input):
/// the surface is checked (manifold, not self-intersecting, normals outward, every hole an end,
/// metres), refined per level, and extruded outward along its normals by the wall thickness into
/// prisms split into tetrahedra. Its open ends become `inlet` (the largest) and `outlet` (all the
/// others, one group). Lengths in metres.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "meshes/stl_io.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel {

/// An open end of a lumen: one boundary loop of the surface.
struct LumenEnd {
  std::vector<int> loop;  ///< lumen node indices in order, following the triangles' orientation
  Vec3 centre = Vec3::Zero();  ///< mean of the loop's nodes, m
  Vec3 normal = Vec3::Zero();  ///< unit normal of the loop's best-fit plane
  double radius = 0.0;      ///< mean distance of the loop's nodes from its centre, m
  double area = 0.0;        ///< area of the loop's (vector) polygon, m²
  double planarity = 0.0;   ///< largest distance of a node from the best-fit plane / radius
  /// How steeply the surface leaves the loop: the mean (weighted by edge length) of |n · d|, d the
  /// unit direction from each loop edge into its triangle, across the edge. 1 where the wall runs
  /// along the normal (a tube cut square), sin α where the surface meets the plane at α (a hole cut
  /// in a wall: the wall around it lies nearly in its plane).
  double steepness = 0.0;
};

/// Criteria that tell an end from a hole (a boundary loop where no end should be). An end is a
/// roughly planar cut across the vessel: at least kMinEndEdges edges, its nodes within
/// kMaxEndPlanarity × its radius of one plane, a radius at least kMinEndRadiusRatio × the
/// largest loop's (a missing facet or a tear leaves a small or crooked loop), and a steepness of
/// at least kMinEndSteepness: the wall leaves an end's plane at more than 45° (a tube cut square:
/// 90°), while around a hole cut in the wall the surface lies near the hole's plane (a planar hole
/// of radius ρ in a wall of radius R meets its plane at asin(ρ/R): 26° for 1.3 mm in 3 mm). The
/// steepness is local (the triangles along the loop), so it holds for any vessel's shape; a hole
/// wider than 0.7 R (a stub of a branch) passes it.
inline constexpr int kMinEndEdges = 6;
inline constexpr double kMaxEndPlanarity = 0.15;
inline constexpr double kMinEndRadiusRatio = 0.1;
inline constexpr double kMinEndSteepness = 0.7071067811865476;  // sin 45°

/// A vessel is expected to fit in kMaxVesselSize metres (bounding-box diagonal): a file larger
/// than that was almost certainly written in millimetres. Below kMinVesselSize it is too small to
/// be a vessel in metres (a file in metres read with units = "mm").
inline constexpr double kMaxVesselSize = 0.5;
inline constexpr double kMinVesselSize = 1e-3;

/// Checks a lumen surface (coordinates in metres) and returns its ends. Throws InputError naming
/// `source` and what is wrong, in this order:
/// - size: bounding-box diagonal above kMaxVesselSize ("looks like millimetres: scale by 1e-3 or
///   set units = \"mm\"") or below kMinVesselSize;
/// - not manifold: an edge shared by more than two triangles, or a vertex where two boundary loops
///   touch;
/// - inconsistently oriented: two triangles traversing a shared edge in the same direction;
/// - closed: no open end (an inlet and at least one outlet are needed);
/// - holes: every boundary loop that fails the end criteria above, each named (centre, radius);
///   or fewer than two ends;
/// - inside out: with every end closed by a fan, the enclosed volume is negative (the normals
///   point into the lumen; expected outward, into the wall);
/// - self-intersecting: two triangles that share no vertex cross (an edge of one passes through
///   the other), found through a uniform grid of their bounding boxes.
/// Facets are named 1-based in file order (read_stl keeps it).
/// With `listed` given, the loops are the listed ends instead of what the end criteria say: every
/// loop must match one listed centre (listed_end), every listed centre one loop, else InputError
/// naming the loop or the listed centre.
std::vector<LumenEnd> check_lumen(const TriangleSurface& lumen, std::string_view source,
                                  const ListedEnds& listed = {});

/// A listed centre matches a loop within kListedEndTolerance × the loop's radius of its centre.
inline constexpr double kListedEndTolerance = 0.5;
/// Which listed end the loop is: 0 the inlet, k ≥ 1 outlets[k − 1], −1 none (or no list).
int listed_end(const LumenEnd& end, const ListedEnds& listed);

/// The boundary loops of an edge-manifold, consistently oriented triangle surface, each in the
/// direction its triangles traverse it; InputError naming `source` for a vertex on more than one
/// loop. Loops start at their smallest node index and are sorted by it.
std::vector<std::vector<int>> boundary_loops(const TriangleSurface& surface,
                                             std::string_view source);

/// The loop's centre, plane, radius, area, planarity and (given the surface's triangles; without
/// them 0) steepness.
LumenEnd describe_end(const std::vector<Vec3>& nodes, std::vector<int> loop,
                      const std::vector<Triangle>* triangles = nullptr);

/// "(x, y, z) mm, radius r mm, normal (nx, ny, nz), area A mm²": one end, for listings.
std::string format_end(const LumenEnd& end);

/// Pairs of triangles that share no vertex and cross (an edge of one passes strictly through the
/// other), at most `limit` of them, each as (i, j) with i < j. Coplanar overlaps are not found.
std::vector<std::pair<int, int>> crossing_triangles(const std::vector<Vec3>& nodes,
                                                    const std::vector<Triangle>& triangles,
                                                    std::size_t limit = 1);

/// Areas within this factor count as equal when the inlet is chosen.
inline constexpr double kInletAreaTie = 1.01;
/// The end that becomes the inlet: the largest area, where a later end must be more than 1 % larger
/// than the one chosen so far to replace it (ends are listed by their smallest node index, so of
/// two equal ends the one whose node comes first in the file is the inlet). All others: outlet.
/// With `listed` given: the loop matching its inlet.
int inlet_end(const std::vector<LumenEnd>& ends, const ListedEnds& listed = {});

/// Splits every triangle into four at its edge midpoints, `times` times (each halves the edges).
TriangleSurface subdivide_surface(const TriangleSurface& surface, int times);

/// A prism's tet is nearly flat when its volume is at most this × its longest edge³ (a regular tet
/// has 0.118): the extrusion then smooths the normals of its nodes and their neighbours, pass after
/// pass, at most kMaxNormalSmoothingPasses times.
inline constexpr double kNearFlatPrismTet = 1e-3;
inline constexpr int kMaxNormalSmoothingPasses = 100;

/// Extrudes a checked lumen (outward normals, `ends` from check_lumen on this surface) outward by
/// `thickness` (m) in `layers` layers of prisms, each split into three tets by the vertex-index
/// rule of Dompierre et al. 1999 (conforming across prisms). A node moves along its angle-weighted
/// normal; on an end's loop the normal is projected into the end's plane, so each end face stays
/// in its plane. Where a prism's tet would be nearly flat or inverted (a crease, e.g. where a
/// branch leaves, turns the normals within less than the thickness), the normals of its nodes and
/// their neighbours are averaged with their neighbours', pass after pass, until none is (the wall
/// there is thinner than t by the cosine of the tilt). Groups of kVesselGroups: inner_wall (the lumen), outer_wall, inlet (the end of
/// largest area), outlet (every other end), wall. Throws InputError naming `source` if a tet
/// inverts (the lumen curves more tightly than the wall is thick) or the outer wall crosses itself
/// (two parts of the vessel closer than the thickness).
TetMesh extrude_lumen(const TriangleSurface& lumen, const std::vector<LumenEnd>& ends,
                      double thickness, int layers, std::string_view source,
                      const ListedEnds& listed = {});

/// Everything that determines the wall mesh of a lumen file.
struct LumenWallParams {
  std::filesystem::path file;
  double thickness = 0.0;  ///< m
  double scale = 1.0;      ///< file units → m (1e-3 for a file in millimetres)
  int level = 0;           ///< 0..kMaxMeshLevel: subdivided `level` times, 2·2^level layers
  ListedEnds listed;       ///< the ends as the user lists them (none: by the end criteria)
};

/// The ends of the lumen file (read, scaled by `scale` to metres, checked by check_lumen), each
/// with its group: inlet (inlet_end) or outlet. InputError as check_lumen.
std::vector<std::pair<std::string, LumenEnd>> lumen_file_ends(const std::filesystem::path& file,
                                                              double scale,
                                                              const ListedEnds& listed = {});

/// Layers through the wall at `level`: 2·2^level (the generated vessels' t/2 at level 0).
int lumen_wall_layers(int level);

/// Reads the STL, scales it, checks it (check_lumen), subdivides it `level` times and extrudes it.
/// InputError naming the file for anything wrong with it or with the thickness.
TetMesh lumen_wall_mesh(const LumenWallParams& params);

}  // namespace vessel
