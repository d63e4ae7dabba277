// A vessel wall extruded from a lumen STL (meshes/lumen_mesh.hpp): closed-form volumes and areas on
// polygonal tubes, the gmsh-made bifurcation, and every refusal.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../lumen_fixture.hpp"
#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/lumen_mesh.hpp"
#include "meshes/mesh_cache.hpp"
#include "meshes/mesh_quality.hpp"

namespace vessel {
namespace {

using test::polygon_tube;
using test::TempDir;

constexpr double kPi = std::numbers::pi;

std::string refusal(const TriangleSurface& s, const std::string& source = "lumen.stl",
                    const ListedEnds& listed = {}) {
  try {
    check_lumen(s, source, listed);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double group_area_of(const TetMesh& m, std::string_view name) {
  return group_area(m, m.require_group(name, 2, "test"));
}

TEST(LumenMesh, PolygonTubeWallHasTheClosedFormVolumeAndAreas) {
  const int n = 24, rings = 10, layers = 2;
  const double a = 3e-3, L = 20e-3, t = 1e-3;
  const TriangleSurface lumen = polygon_tube(a, L, n, rings);
  const std::vector<LumenEnd> ends = check_lumen(lumen, "tube");
  ASSERT_EQ(ends.size(), 2u);
  const TetMesh m = extrude_lumen(lumen, ends, t, layers, "tube");
  // Vertex normals of a regular prism are radial: the outer wall is the n-gon of radius a + t.
  const double ngon = 0.5 * n * std::sin(2.0 * kPi / n);  // area of the unit-radius n-gon
  const double b = a + t;
  EXPECT_NEAR(mesh_volume(m), L * ngon * (b * b - a * a), 1e-12 * L * b * b);
  const double side = 2.0 * std::sin(kPi / n);
  EXPECT_NEAR(group_area_of(m, group_names::inner_wall), n * side * a * L, 1e-12);
  EXPECT_NEAR(group_area_of(m, group_names::outer_wall), n * side * b * L, 1e-12);
  EXPECT_NEAR(group_area_of(m, group_names::inlet), ngon * (b * b - a * a), 1e-14);
  EXPECT_NEAR(group_area_of(m, group_names::outlet), ngon * (b * b - a * a), 1e-14);
  // Equal ends: the inlet is the one through the first node (z = 0).
  for (int v : m.group_nodes(m.require_group(group_names::inlet, 2, "t"))) {
    EXPECT_NEAR(m.nodes[v].z(), 0.0, 1e-15);
  }
  EXPECT_EQ(m.tets.size(), static_cast<std::size_t>(3 * layers * 2 * n * rings));
  EXPECT_EQ(m.nodes.size(), static_cast<std::size_t>((layers + 1) * n * (rings + 1)));
  // Conforming: the tets' boundary is exactly the four groups, closed and consistently oriented.
  const std::vector<Triangle> faces = boundary_faces(m);
  EXPECT_EQ(faces.size(), static_cast<std::size_t>(2 * 2 * n * rings + 2 * 2 * n * layers));
  EXPECT_EQ(faces.size(), m.triangles.size());
  EXPECT_TRUE(surface_topology(faces).closed_and_oriented());
  EXPECT_EQ(compute_quality(m).inverted, 0u);
}

TEST(LumenMesh, LevelsSubdivideTheLumenAndDoubleTheLayers) {
  const int n = 12, rings = 4;
  const double a = 3e-3, L = 10e-3, t = 1e-3;
  TempDir dir;
  write_stl(dir / "tube.stl", polygon_tube(a, L, n, rings), StlFormat::ascii);
  const TetMesh m = lumen_wall_mesh({dir / "tube.stl", t, 1.0, 1});
  EXPECT_EQ(lumen_wall_layers(1), 4);
  EXPECT_EQ(m.tets.size(), static_cast<std::size_t>(3 * 4 * 4 * 2 * n * rings));
  // The midpoints lie on the chords, whose normal is the flat face's: the outer wall is the
  // 2n-gon alternating radius a + t (vertices) and a·cos(π/n) + t (chord midpoints).
  const double r1 = a + t, r2 = a * std::cos(kPi / n) + t;
  const double outer = n * r1 * r2 * std::sin(kPi / n);
  const double inner = 0.5 * n * a * a * std::sin(2.0 * kPi / n);
  EXPECT_NEAR(mesh_volume(m), L * (outer - inner), 1e-10 * L * outer);
  EXPECT_EQ(compute_quality(m).inverted, 0u);
}

TEST(LumenMesh, UnitsScaleAFileInMillimetres) {
  TriangleSurface mm_tube = polygon_tube(3.0, 20.0, 16, 6);  // millimetres
  TempDir dir;
  write_stl(dir / "mm.stl", mm_tube);
  try {
    (void)lumen_wall_mesh({dir / "mm.stl", 1e-3, 1.0, 0});
    FAIL() << "a lumen in millimetres read as metres was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mm.stl"), std::string::npos) << e.what();
    EXPECT_NE(
        std::string(e.what()).find("looks like millimetres; scale by 1e-3 or set units = \"mm\""),
        std::string::npos)
        << e.what();
  }
  const TetMesh m = lumen_wall_mesh({dir / "mm.stl", 1e-3, 1e-3, 0});
  const double ngon = 0.5 * 16 * std::sin(2.0 * kPi / 16);
  EXPECT_NEAR(mesh_volume(m), 20e-3 * ngon * (16e-6 - 9e-6), 1e-6 * mesh_volume(m));
}

TEST(LumenMesh, RefusesAFileInMetresReadAsMillimetres) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  for (Vec3& x : s.nodes) x *= 1e-3;
  EXPECT_NE(refusal(s).find("smaller than a vessel"), std::string::npos) << refusal(s);
}

TEST(LumenMesh, RefusesANonManifoldEdge) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  s.nodes.emplace_back(0.0, 0.0, 5e-3);  // a fin on the edge between nodes 0 and 16
  s.triangles.push_back({0, 16, static_cast<int>(s.nodes.size()) - 1});
  const std::string msg = refusal(s);
  EXPECT_NE(msg.find("lumen.stl: the surface is not manifold"), std::string::npos) << msg;
  EXPECT_NE(msg.find("shared by 3 facets"), std::string::npos) << msg;
}

TEST(LumenMesh, RefusesInconsistentlyOrientedFacets) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  std::swap(s.triangles[40][1], s.triangles[40][2]);
  const std::string msg = refusal(s);
  EXPECT_NE(msg.find("oriented inconsistently"), std::string::npos) << msg;
  EXPECT_NE(msg.find("41"), std::string::npos) << msg;  // 1-based facet number
}

TEST(LumenMesh, RefusesAnInsideOutLumen) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  for (Triangle& t : s.triangles) std::swap(t[1], t[2]);
  const std::string msg = refusal(s);
  EXPECT_NE(msg.find("inside out: its facet normals point into the lumen"), std::string::npos)
      << msg;
}

TEST(LumenMesh, RefusesAHoleInTheWall) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  s.triangles.erase(s.triangles.begin() + 50);  // a missing facet mid-tube: a loop of 3 edges
  const std::string msg = refusal(s);
  EXPECT_NE(msg.find("a hole where no end should be: an open loop of 3 edges"), std::string::npos)
      << msg;
}

TEST(LumenMesh, RefusesACrookedEnd) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  for (int i = 0; i < 16; i += 2) s.nodes[i].z() += 1.5e-3;  // the z = 0 end zig-zags by half t
  const std::string msg = refusal(s);
  EXPECT_NE(msg.find("a hole where no end should be"), std::string::npos) << msg;
  EXPECT_NE(msg.find("off its plane"), std::string::npos) << msg;
}

TEST(LumenMesh, RefusesAClosedSurfaceAndASingleEnd) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  // Cap the z = 20 mm end with a fan (each facet traverses its loop edge against the wall's).
  s.nodes.emplace_back(0.0, 0.0, 20e-3);
  const int c = static_cast<int>(s.nodes.size()) - 1;
  for (int i = 0; i < 16; ++i) s.triangles.push_back({96 + i, 96 + (i + 1) % 16, c});
  EXPECT_NE(refusal(s).find("one open end"), std::string::npos) << refusal(s);
  s.nodes.emplace_back(0.0, 0.0, 0.0);
  const int c0 = static_cast<int>(s.nodes.size()) - 1;
  for (int i = 0; i < 16; ++i) s.triangles.push_back({(i + 1) % 16, i, c0});
  EXPECT_NE(refusal(s).find("closed (no open end)"), std::string::npos) << refusal(s);
}

TEST(LumenMesh, RefusesASelfIntersectingSurface) {
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  // Push a node of the middle ring through the opposite wall.
  s.nodes[3 * 16] = Vec3(-4.5e-3, 0.0, 10e-3);
  const std::string msg = refusal(s);
  EXPECT_NE(msg.find("the surface intersects itself: facets"), std::string::npos) << msg;
}

TEST(LumenMesh, CrossingTrianglesFindsAPiercingPairOnly) {
  const std::vector<Vec3> x{{0, 0, 0},      {1, 0, 0},     {0, 1, 0},   // in z = 0
                            {0.2, 0.2, -1}, {0.2, 0.2, 1}, {3, 3, 1},   // pierces it
                            {5, 5, -1},     {5, 5, 1},     {6, 5, 0}};  // far away
  EXPECT_EQ(crossing_triangles(x, {{0, 1, 2}, {3, 4, 5}}).size(), 1u);
  EXPECT_TRUE(crossing_triangles(x, {{0, 1, 2}, {6, 7, 8}}).empty());
  EXPECT_TRUE(crossing_triangles(x, {{0, 1, 2}, {0, 4, 5}}).empty());  // shares a vertex
}

TEST(LumenMesh, RefusesAWallThickerThanTheLumenCurvatureAllows) {
  // Two parallel tubes 1 mm apart: any wall thicker than 0.5 mm makes their outer walls meet.
  TriangleSurface s = polygon_tube(3e-3, 20e-3, 16, 6);
  const TriangleSurface other = polygon_tube(3e-3, 20e-3, 16, 6);
  const int offset = static_cast<int>(s.nodes.size());
  for (const Vec3& x : other.nodes) s.nodes.push_back(x + Vec3(7e-3, 0.0, 0.0));
  for (const Triangle& t : other.triangles)
    s.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  s.source_node.resize(s.nodes.size(), -1);
  const std::vector<LumenEnd> ends = check_lumen(s, "two.stl");
  EXPECT_EQ(ends.size(), 4u);
  EXPECT_NO_THROW(extrude_lumen(s, ends, 0.3e-3, 2, "two.stl"));
  try {
    (void)extrude_lumen(s, ends, 1e-3, 2, "two.stl");
    FAIL() << "overlapping walls accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "two.stl: with wall_thickness = 1 mm the outer wall crosses itself"),
              std::string::npos)
        << e.what();
  }
}

TEST(LumenMesh, BifurcationFromGmshMeshesWithThreeEnds) {
  TempDir dir;
  const test::BifurcationSpec spec;
  test::write_bifurcation_stl(dir / "bifurcation.stl", spec);
  const TriangleSurface lumen = read_stl(dir / "bifurcation.stl");
  const std::vector<LumenEnd> ends = check_lumen(lumen, "bifurcation.stl");
  ASSERT_EQ(ends.size(), 3u);
  const double t = 0.5e-3;
  const TetMesh m = lumen_wall_mesh({dir / "bifurcation.stl", t, 1.0, 0});
  const MeshQuality q = compute_quality(m);
  EXPECT_EQ(q.inverted, 0u);
  EXPECT_GT(q.dihedral_deg.min, 1.0);
  std::cout << "bifurcation lumen: " << lumen.nodes.size() << " nodes, " << lumen.triangles.size()
            << " triangles; wall: " << m.nodes.size() << " nodes, " << m.tets.size() << " tets\n"
            << format_quality(q) << "\n";
  // A shell's volume is t times the mean of its two faces' areas (exact for a cylinder, to O(t³)
  // otherwise). The nodes move by t, so facets N to the round lie t·cos(π/N) apart: N ≈ 16 on the
  // main tube at this size makes the faceted wall ~2 % thinner; 4 % allows for it.
  const double inner = group_area_of(m, group_names::inner_wall);
  const double outer = group_area_of(m, group_names::outer_wall);
  EXPECT_NEAR(mesh_volume(m), 0.5 * t * (inner + outer), 0.04 * mesh_volume(m));
  // The lumen's area is the torus segment's plus the branch's, less the branch's footprint.
  const double torus = 2 * kPi * spec.radius * spec.bend_radius * spec.angle;
  EXPECT_NEAR(inner, torus + 2 * kPi * spec.branch_radius * spec.branch_length, 0.1 * torus);
  // Inlet: a main-tube end (the two are equal; the larger-by-1 % rule keeps the first); outlet:
  // the other main end and the branch's end.
  const double main_ring =
      kPi * ((spec.radius + t) * (spec.radius + t) - spec.radius * spec.radius);
  const double branch_ring = kPi * ((spec.branch_radius + t) * (spec.branch_radius + t) -
                                    spec.branch_radius * spec.branch_radius);
  // Rings of N-gons cover (N/2)·sin(2π/N)/π of the circles' ring: 97 % for N = 16 (main tube),
  // 94 % for N = 10 (branch).
  EXPECT_NEAR(group_area_of(m, group_names::inlet), main_ring, 0.05 * main_ring);
  EXPECT_NEAR(group_area_of(m, group_names::outlet), main_ring + branch_ring,
              0.08 * (main_ring + branch_ring));
  EXPECT_TRUE(surface_topology(boundary_faces(m)).closed_and_oriented());
  // Level 1: edges of ~0.6 mm against the 0.5 mm wall fold the prisms at the branch's crease
  // unless the normals there are smoothed; none is inverted or flat.
  const TetMesh fine = lumen_wall_mesh({dir / "bifurcation.stl", t, 1.0, 1});
  EXPECT_EQ(fine.tets.size(), 8 * m.tets.size());
  EXPECT_EQ(compute_quality(fine).inverted, 0u);
  EXPECT_EQ(compute_quality(fine).degenerate, 0u);
}

TEST(LumenMesh, CacheKeysTheFileContent) {
  TempDir dir;
  write_stl(dir / "tube.stl", polygon_tube(3e-3, 10e-3, 12, 4));
  VesselParams p;
  p.kind = VesselKind::lumen;
  p.file = dir / "tube.stl";
  p.wall_thickness = 1e-3;
  MeshSource first, second;
  const TetMesh a = load_or_generate_vessel(p, dir / "cache", {}, &first);
  const TetMesh b = load_or_generate_vessel(p, dir / "cache", {}, &second);
  EXPECT_FALSE(first.cache_hit);
  EXPECT_TRUE(second.cache_hit);
  EXPECT_EQ(a.tets.size(), b.tets.size());
  const std::string key = mesh_cache_key(p);
  write_stl(dir / "tube.stl", polygon_tube(3e-3, 12e-3, 12, 4));  // the file changes
  EXPECT_NE(mesh_cache_key(p), key);
}

TEST(LumenMesh, AMeshFileIsReadAsGivenAtLevelZeroOnly) {
  TempDir dir;
  VesselParams p;
  p.kind = VesselKind::mesh_file;
  p.file = dir / "none.msh";
  p.level = 1;
  try {
    validate(p);
    FAIL() << "level 1 of a mesh file accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("levels do not refine it"), std::string::npos) << e.what();
  }
}

TEST(LumenMesh, ProjectsAPointOntoTheChosenWall) {
  const double a = 3e-3, t = 1e-3, L = 20e-3;
  const TriangleSurface lumen = polygon_tube(a, L, 16, 8);
  const TetMesh m = extrude_lumen(lumen, check_lumen(lumen, "tube"), t, 2, "tube");
  // From far outside along θ = 0 (a vertex line of the 16-gon), the nearest point of the outer
  // wall is the vertex line itself; from the axis side the inner wall's.
  const Vec3 outer =
      nearest_point_on_group(m, group_names::outer_wall, Vec3(2 * (a + t), 0, L / 2), "t");
  EXPECT_NEAR((outer - Vec3(a + t, 0, L / 2)).norm(), 0.0, 1e-12);
  // Towards the middle of a face: that face's chord midpoint, at radius a·cos(π/16).
  const Vec3 towards(std::cos(kPi / 16), std::sin(kPi / 16), 0.0);
  const Vec3 inner =
      nearest_point_on_group(m, group_names::inner_wall, 1e-3 * towards + Vec3(0, 0, L / 2), "t");
  EXPECT_NEAR((inner - (a * std::cos(kPi / 16) * towards + Vec3(0, 0, L / 2))).norm(), 0.0, 1e-12);
  // The thickness estimate: radial offsets of t at the vertices, t + a(1 − cos π/16)·… ≥ t between.
  EXPECT_NEAR(estimate_wall_thickness(m, "t"), t, 0.02 * t);
}

TEST(LumenMesh, YBifurcationEndsAreItsThreeCutsWithTheirConstructedGeometry) {
  const test::YBifurcationSpec spec;
  const TriangleSurface lumen = test::y_bifurcation_lumen(spec);
  const std::vector<LumenEnd> ends = check_lumen(lumen, "y.stl");
  ASSERT_EQ(ends.size(), 3u);
  // The construction's ends: the parent at z = −L, the daughters L along ±half_angle from z.
  const double L = spec.length, a = spec.half_angle;
  const std::array<Vec3, 3> centres{Vec3(0, 0, -L), Vec3(-L * std::sin(a), 0, L * std::cos(a)),
                                    Vec3(L * std::sin(a), 0, L * std::cos(a))};
  const std::array<double, 3> radii{spec.parent_radius, spec.daughter_radius, spec.daughter_radius};
  for (int c = 0; c < 3; ++c) {
    int found = 0;
    for (const LumenEnd& e : ends) {
      if ((e.centre - centres[c]).norm() > 1e-6) continue;
      ++found;
      // Nodes on the circle: the mean distance is the radius; a polygon's area is under the
      // circle's.
      EXPECT_NEAR(e.radius, radii[c], 1e-6);
      EXPECT_NEAR(e.area, kPi * radii[c] * radii[c], 0.05 * kPi * radii[c] * radii[c]);
      EXPECT_NEAR(std::abs(e.normal.dot(centres[c].normalized())), 1.0, 1e-6);
      EXPECT_GT(e.steepness, 0.95);  // a square cut of a tube
    }
    EXPECT_EQ(found, 1) << "no end at the construction's end " << c;
  }
}

TEST(LumenMesh, YBifurcationWithHolesInItsJunctionIsRefusedNamingAHole) {
  test::YBifurcationSpec spec;
  spec.holes = true;
  const TriangleSurface lumen = test::y_bifurcation_lumen(spec);
  // Five loops: the three ends, and the two holes at y = ±√(R_j² − ρ²) of radius ρ, whose wall
  // meets their plane at asin(ρ / R_j) = 22° (the facets next to the loop tilt it by a few more).
  const double rho = spec.hole_radius, Rj = spec.junction_radius;
  const double cut = std::sqrt(Rj * Rj - rho * rho);
  int holes = 0, ends = 0;
  for (const auto& loop : boundary_loops(lumen, "holed.stl")) {
    const LumenEnd e = describe_end(lumen.nodes, loop, &lumen.triangles);
    if (std::abs(std::abs(e.centre.y()) - cut) < 1e-6) {
      ++holes;
      EXPECT_NEAR(e.radius, rho, 1e-6);
      EXPECT_NEAR(std::abs(e.normal.y()), 1.0, 1e-9);
      EXPECT_NEAR(e.steepness, rho / Rj, 0.15);
      EXPECT_LT(e.steepness, kMinEndSteepness);
    } else {
      ++ends;
      EXPECT_GT(e.steepness, 0.95);
    }
  }
  EXPECT_EQ(holes, 2);
  EXPECT_EQ(ends, 3);
  const std::string message = refusal(lumen, "holed.stl");
  // Both holes named, each by its centre (0, ±√(R_j² − ρ²), 0) = (0, ±3.25, 0) mm and radius.
  EXPECT_NE(message.find("holed.stl: 2 holes where no end should be: the open loop around (0, "),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("(0, 3.25, 0) mm, radius 1.3 mm"), std::string::npos) << message;
  EXPECT_NE(message.find("(0, -3.25, 0) mm, radius 1.3 mm"), std::string::npos) << message;
  EXPECT_NE(message.find("radius 1.3 mm, lies in the vessel's wall"), std::string::npos) << message;
  EXPECT_NE(message.find("fill the hole in the surface, or, if it is an end, cut it square"),
            std::string::npos)
      << message;
}

}  // namespace
namespace {

/// The Y's three true ends (the construction's), parent as the inlet.
ListedEnds y_ends(const test::YBifurcationSpec& spec) {
  const double L = spec.length, a = spec.half_angle;
  return {Vec3(0, 0, -L),
          {Vec3(-L * std::sin(a), 0, L * std::cos(a)), Vec3(L * std::sin(a), 0, L * std::cos(a))}};
}

/// The centroid of a surface group's triangles (unweighted).
Vec3 group_centroid(const TetMesh& m, std::string_view name) {
  Vec3 c = Vec3::Zero();
  const auto tris = m.group_triangles(m.require_group(name, 2, "test"));
  for (const Triangle& t : tris) c += (m.nodes[t[0]] + m.nodes[t[1]] + m.nodes[t[2]]) / 3.0;
  return c / static_cast<double>(tris.size());
}

}  // namespace

TEST(LumenMesh, ListedEndsChooseTheInletAndOverrideTheEndCriteria) {
  test::YBifurcationSpec spec;
  const ListedEnds truth = y_ends(spec);
  // The clean Y with a daughter listed as the inlet: that cut becomes `inlet`, not the largest.
  const TriangleSurface clean = test::y_bifurcation_lumen(spec);
  ListedEnds daughter_in{truth.outlets[1], {truth.inlet, truth.outlets[0]}};
  const std::vector<LumenEnd> ends = check_lumen(clean, "y.stl", daughter_in);
  ASSERT_EQ(ends.size(), 3u);
  EXPECT_LT((ends[inlet_end(ends, daughter_in)].centre - truth.outlets[1]).norm(), 1e-9);
  EXPECT_LT((ends[inlet_end(ends)].centre - truth.inlet).norm(), 1e-9);  // by area: the parent
  const TetMesh m = extrude_lumen(clean, ends, 0.4e-3, 2, "y.stl", daughter_in);
  EXPECT_LT((group_centroid(m, "inlet") - truth.outlets[1]).norm(), 0.2 * spec.daughter_radius);

  // The holed Y: its two holes, listed as outlets by a user who means them, are accepted as ends.
  spec.holes = true;
  const TriangleSurface holed = test::y_bifurcation_lumen(spec);
  const double cut =
      std::sqrt(spec.junction_radius * spec.junction_radius - spec.hole_radius * spec.hole_radius);
  ListedEnds with_holes = truth;
  with_holes.outlets.emplace_back(0, cut, 0);
  with_holes.outlets.emplace_back(0, -cut, 0);
  EXPECT_EQ(check_lumen(holed, "holed.stl", with_holes).size(), 5u);
  // Listing only the true ends still refuses the holes, each named as no listed end.
  const std::string unlisted = refusal(holed, "holed.stl", truth);
  EXPECT_NE(unlisted.find("the open loop around (0, 3.25, 0) mm, radius 1.3 mm, is none of the "
                          "listed ends"),
            std::string::npos)
      << unlisted;
  EXPECT_NE(unlisted.find("(0, -3.25, 0) mm, radius 1.3 mm, is none"), std::string::npos)
      << unlisted;
  // A listed centre off every loop is named.
  ListedEnds off = truth;
  off.outlets.emplace_back(0.05, 0.05, 0.05);
  const std::string missing = refusal(clean, "y.stl", off);
  EXPECT_NE(missing.find("outlet_centres[2] (50, 50, 50) mm is the centre of no open loop"),
            std::string::npos)
      << missing;
}

}  // namespace vessel
