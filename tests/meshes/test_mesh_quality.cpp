// Tet quality measures against hand-derived values.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "meshes/mesh_quality.hpp"

using namespace vessel;

namespace {
constexpr double kDeg = 180.0 / std::numbers::pi;
}

TEST(MeshQuality, RegularTetHasDihedralAcosOneThirdAndRadiusRatioOne) {
  const Vec3 a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  const TetQuality q = tet_quality(a, b, c, d);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1.0 / 3.0) * kDeg, 1e-10);
  EXPECT_NEAR(q.max_dihedral_deg, std::acos(1.0 / 3.0) * kDeg, 1e-10);
  EXPECT_NEAR(q.radius_ratio, 1.0, 1e-12);
  // Edge 2√2: V = (2√2)³ / (6√2) = 8/3.
  EXPECT_NEAR(std::abs(q.volume), 8.0 / 3.0, 1e-12);
}

TEST(MeshQuality, CornerTetByHand) {
  // Tet (0, e1, e2, e3): dihedral 90° at the three axis edges and acos(1/√3) at the others;
  // r_in = 3V/A = (1/2)/((3+√3)/2), R = √3/2, so 3 r_in / R = √3 − 1.
  const TetQuality q = tet_quality(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1));
  EXPECT_NEAR(q.max_dihedral_deg, 90.0, 1e-10);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1.0 / std::sqrt(3.0)) * kDeg, 1e-10);
  EXPECT_NEAR(q.radius_ratio, std::sqrt(3.0) - 1.0, 1e-12);
  EXPECT_NEAR(q.volume, 1.0 / 6.0, 1e-15);
}

TEST(MeshQuality, MeshStatisticsFlagInvertedAndDegenerateTets) {
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1),
                Vec3(1, 1, 0)};
  mesh.tets = {{0, 1, 2, 3},   // positive, V = 1/6
               {0, 1, 2, 4},   // negative: inverted relative to the first
               {0, 1, 2, 5}};  // coplanar: zero volume
  const MeshQuality q = compute_quality(mesh);
  EXPECT_EQ(q.inverted, 1u);
  EXPECT_EQ(q.degenerate, 1u);
  EXPECT_NEAR(q.total_volume, 0.0, 1e-15);
  EXPECT_NEAR(q.dihedral_deg.min, 0.0, 1e-6);
  // Unique edges: 6 + 3 (to node 4) + 3 (to node 5) = 12, of lengths 1 and √2.
  EXPECT_EQ(q.edge_length.count, 12u);
  EXPECT_NEAR(q.edge_length.max, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(q.edge_length.min, 1.0, 1e-12);
}

TEST(MeshQuality, OrientTetsFlipsOnlyAnAllNegativeConvention) {
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)};
  mesh.tets = {{0, 2, 1, 3}, {0, 1, 2, 4}};  // both negative
  orient_tets(mesh);
  EXPECT_GT(mesh_volume(mesh), 0.0);
  EXPECT_EQ(compute_quality(mesh).inverted, 0u);
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 1, 3}};  // mixed: an inverted element stays visible
  orient_tets(mesh);
  EXPECT_EQ(compute_quality(mesh).inverted, 1u);
}

TEST(MeshQuality, ASliverIsFoundWithItsAnglesAndPositionAndAGoodMeshIsNot) {
  // Corner tets of the unit cube (dihedral 54.7° to 90°) and, 10 m away, a sliver: a = (±1, 0, 0),
  // c, d = (0, ±1, h). Across edge ab the faces' directions (0, 1, h) and (0, −1, h) make
  // 180° − 2·atan(h) (and across cd likewise); the other four are near 0°.
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  mesh.tets = {{0, 1, 2, 3}, {4, 2, 1, 3}};
  SliverReport none = find_slivers(mesh);
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(sliver_warning(none), "");
  // The mesh's extremes: the corner tet's 90° (at the origin's edges) and acos(1/√3) = 54.74°
  // (at its slanted face's edges); the regular tet's 70.53° lies between.
  EXPECT_NEAR(none.min_dihedral_deg, std::acos(1.0 / std::sqrt(3.0)) * kDeg, 1e-9);
  EXPECT_NEAR(none.max_dihedral_deg, 90.0, 1e-9);
  const double h = 0.01;
  const Vec3 o(10, 0, 0);
  const int base = static_cast<int>(mesh.nodes.size());
  for (const Vec3& p : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, h), Vec3(0, -1, h)}) {
    mesh.nodes.push_back(o + p);
  }
  mesh.tets.push_back({base, base + 1, base + 2, base + 3});
  const SliverReport one = find_slivers(mesh);
  EXPECT_EQ(one.count, 1u);
  EXPECT_NEAR(one.worst_max_dihedral_deg, 180.0 - 2.0 * std::atan(h) * kDeg, 1e-9);
  EXPECT_LT(one.worst_min_dihedral_deg, kSliverMinDihedralDeg);
  EXPECT_EQ(one.min_dihedral_deg, one.worst_min_dihedral_deg);
  EXPECT_EQ(one.max_dihedral_deg, one.worst_max_dihedral_deg);
  EXPECT_NEAR((one.worst_centroid - (o + Vec3(0, 0, 0.5 * h))).norm(), 0.0, 1e-12);
  const std::string w = sliver_warning(one);
  EXPECT_NE(w.find("WARNING: 1 sliver tets"), std::string::npos) << w;
  EXPECT_NE(w.find("at (1e+04, 0, 5) mm"), std::string::npos) << w;
  EXPECT_NE(w.find("include the mesh's error"), std::string::npos) << w;
}
