// Point location and barycentric coordinates (meshes/tet_locator.hpp) against hand values.
#include <gtest/gtest.h>

#include "meshes/tet_locator.hpp"

namespace vessel {
namespace {

/// The unit corner tet (0, e_x, e_y, e_z) and its mirror across x + y + z = 1 sharing a face.
TetMesh two_tets() {
  TetMesh m;
  m.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  m.tets = {{0, 1, 2, 3}, {4, 1, 3, 2}};
  return m;
}

TEST(TetLocator, BarycentricCoordinatesReproduceThePointAndFindPicksItsTet) {
  const TetMesh m = two_tets();
  // x = (0.1, 0.2, 0.3) in the corner tet: λ = (1 − 0.6, 0.1, 0.2, 0.3).
  const Vec3 x(0.1, 0.2, 0.3);
  const Eigen::Vector4d l = barycentric(m, m.tets[0], x);
  EXPECT_NEAR(l[0], 0.4, 1e-14);
  EXPECT_NEAR(l[1], 0.1, 1e-14);
  EXPECT_NEAR(l[2], 0.2, 1e-14);
  EXPECT_NEAR(l[3], 0.3, 1e-14);
  EXPECT_NEAR(min_barycentric(m, m.tets[0], x), 0.1, 1e-14);
  // Beyond the shared face (x + y + z > 1) the corner tet's first coordinate is negative, and
  // the point is in the other tet, whose coordinates rebuild it.
  const Vec3 y(0.5, 0.4, 0.4);
  EXPECT_NEAR(barycentric(m, m.tets[0], y)[0], -0.3, 1e-14);
  const TetLocator locator(m);
  EXPECT_EQ(locator.find(x), 0);
  ASSERT_EQ(locator.find(y), 1);
  const Eigen::Vector4d k = barycentric(m, m.tets[1], y);
  Vec3 rebuilt = Vec3::Zero();
  for (int i = 0; i < 4; ++i) rebuilt += k[i] * m.nodes[static_cast<std::size_t>(m.tets[1][i])];
  EXPECT_LT((rebuilt - y).norm(), 1e-14);
  EXPECT_NEAR(k.sum(), 1.0, 1e-14);
  EXPECT_EQ(locator.find(Vec3(2, 2, 2)), -1);
}

}  // namespace
}  // namespace vessel
