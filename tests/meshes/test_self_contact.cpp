// The self-penetration check that stops the finite-strain reference: hand-placed points against
// two tetrahedra, and the default tube under a map that cannot overlap (affine, det > 0) and one
// that must (its upper half pushed down through the lower half).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/self_contact.hpp"

using namespace vessel;

namespace {

/// Two unit right tetrahedra, the second shifted by 2 along x; their 8 faces as boundary.
TetMesh two_tets() {
  TetMesh m;
  for (const double x0 : {0.0, 2.0}) {
    m.nodes.insert(m.nodes.end(), {Vec3(x0, 0, 0), Vec3(x0 + 1, 0, 0), Vec3(x0, 1, 0), Vec3(x0, 0, 1)});
  }
  m.tets = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  for (const Tet& t : m.tets) {
    m.triangles.push_back({t[0], t[2], t[1]});
    m.triangles.push_back({t[0], t[1], t[3]});
    m.triangles.push_back({t[0], t[3], t[2]});
    m.triangles.push_back({t[1], t[2], t[3]});
  }
  return m;
}

/// The second tet's first vertex, at rest (2, 0, 0), moved to `to`.
std::vector<Vec3> move_node_4(const TetMesh& m, const Vec3& to) {
  std::vector<Vec3> u(m.nodes.size(), Vec3::Zero());
  u[4] = to - m.nodes[4];
  return u;
}

const TetMesh& tube() {
  static const TetMesh mesh = [] {
    VesselParams p;
    p.style = MeshStyle::structured;
    return generate_vessel_mesh(p);
  }();
  return mesh;
}

}  // namespace

TEST(SelfPenetration, APointInsideAnotherTetIsFoundAndOneOutsideOrOnAFaceIsNot) {
  const TetMesh m = two_tets();
  EXPECT_TRUE(find_self_penetration(m, std::vector<Vec3>(m.nodes.size(), Vec3::Zero())).nodes.empty());
  // (0.2, 0.1, 0.1) has barycentric coordinates 0.6, 0.2, 0.1, 0.1 in the first tet.
  const SelfPenetration in = find_self_penetration(m, move_node_4(m, Vec3(0.2, 0.1, 0.1)));
  ASSERT_EQ(in.nodes, std::vector<int>{4});
  EXPECT_EQ(in.tets, std::vector<int>{0});
  // Beyond the slanted face x + y + z = 1, and on the face z = 0 (touching is not crossing).
  EXPECT_TRUE(find_self_penetration(m, move_node_4(m, Vec3(1.0, 0.1, 0.1))).nodes.empty());
  EXPECT_TRUE(find_self_penetration(m, move_node_4(m, Vec3(0.2, 0.2, 0.0))).nodes.empty());
  EXPECT_THROW((void)find_self_penetration(m, std::vector<Vec3>(3)), std::invalid_argument);
}

TEST(SelfPenetration, AnInvertedTetIsNotCountedAsTheWallElsewhere) {
  // The first tet's apex pushed through its base: it is inverted, and the point it now covers is
  // no other part of the wall (node 4 moved under the base lies in the inverted tet only).
  TetMesh m = two_tets();
  std::vector<Vec3> u = move_node_4(m, Vec3(0.2, 0.1, -0.1));
  u[3] = Vec3(0, 0, -2.0);  // apex (0, 0, 1) to (0, 0, -1)
  EXPECT_TRUE(find_self_penetration(m, u).nodes.empty());
}

TEST(SelfPenetration, TheTubeFlattenedAffinelyDoesNotPassThroughItself) {
  // x → (x, 0.05 y + 0.3 z, z): det 0.05 > 0, one-to-one, however flat.
  const TetMesh& m = tube();
  std::vector<Vec3> u(m.nodes.size());
  for (std::size_t i = 0; i < u.size(); ++i) {
    const Vec3& x = m.nodes[i];
    u[i] = Vec3(x.x(), 0.05 * x.y() + 0.3 * x.z(), x.z()) - x;
  }
  EXPECT_TRUE(find_self_penetration(m, u).nodes.empty());
}

TEST(ClosestApproach, IsTheLumensDiameterAtRestAndShrinksWithTheFlattenedTube) {
  // Inner-wall nodes at least the radius a = 3 mm apart at rest: the closest such pair lies on
  // the circle with a chord ≥ a, so at rest the approach is between a and the smallest chord of
  // the circle's nodes that reaches a (≤ 2a = the diameter). Scaled by 0.5 across (y), two nodes
  // diametrically opposite in y come 0.5 · 2a = a apart.
  const TetMesh& m = tube();
  const double a = 3e-3;
  const std::vector<Vec3> rest(m.nodes.size(), Vec3::Zero());
  const double d0 = closest_approach(m, rest, "inner_wall", a);
  EXPECT_GE(d0, a - 1e-12);
  EXPECT_LE(d0, 2 * a);
  std::vector<Vec3> u(m.nodes.size());
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = Vec3(0, -0.5 * m.nodes[i].y(), 0);
  EXPECT_LE(closest_approach(m, u, "inner_wall", a), a + 1e-12);
  EXPECT_THROW((void)closest_approach(m, rest, "lumen", a), InputError);
}

TEST(SelfPenetration, TheTubesUpperHalfPushedThroughTheLowerHalfIsFound) {
  // Nodes with y > 0 move by (0.13, −6.27, 0.07) mm: the inner wall's top line (0, 3 mm, z)
  // lands at (0.13, −3.27) mm, r = 3.27 mm, inside the lower wall (3 ≤ r ≤ 4 mm), off its node
  // layers and planes (a point on a face or node counts as touching, not inside).
  const TetMesh& m = tube();
  std::vector<Vec3> u(m.nodes.size(), Vec3::Zero());
  for (std::size_t i = 0; i < u.size(); ++i)
    if (m.nodes[i].y() > 1e-9) u[i] = Vec3(0.13e-3, -6.27e-3, 0.07e-3);
  const SelfPenetration p = find_self_penetration(m, u);
  double z0 = m.nodes[0].z(), z1 = z0;
  for (const Vec3& x : m.nodes) {
    z0 = std::min(z0, x.z());
    z1 = std::max(z1, x.z());
  }
  int top_inner = 0, found = 0;
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const Vec3& x = m.nodes[i];
    if (std::abs(x.x()) < 1e-9 && std::abs(x.y() - 3e-3) < 1e-9 && x.z() > z0 + 1e-3 &&
        x.z() < z1 - 1e-3) {
      ++top_inner;
      found += std::binary_search(p.nodes.begin(), p.nodes.end(), static_cast<int>(i));
    }
  }
  ASSERT_GT(top_inner, 0);
  EXPECT_EQ(found, top_inner);
}
