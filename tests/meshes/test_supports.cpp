// End supports defined once for the FEM and the springs: which groups, which pins, and which
// dofs of a node set they hold, checked against the generated tube's known geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/supports.hpp"

using namespace vessel;

namespace {

VesselParams structured_tube() {
  VesselParams p;
  p.style = MeshStyle::structured;
  return p;
}

const TetMesh& tube() {
  static const TetMesh mesh = generate_vessel_mesh(structured_tube());
  return mesh;
}

std::vector<int> identity(std::size_t n) {
  std::vector<int> ids(n);
  std::iota(ids.begin(), ids.end(), 0);
  return ids;
}

std::size_t count_on_plane(const std::vector<Vec3>& nodes, double z) {
  return static_cast<std::size_t>(std::count_if(
      nodes.begin(), nodes.end(), [&](const Vec3& x) { return std::abs(x.z() - z) < 1e-9; }));
}

}  // namespace

TEST(Supports, ClampedEndsHoldEveryDofOfTheirNodesAndNeedNoPins) {
  const Supports s = end_supports(
      structured_tube(), {{"inlet", EndCondition::clamped}, {"outlet", EndCondition::clamped}}, "");
  EXPECT_TRUE(s.pins.empty());
  const auto held = held_dofs(tube(), tube().nodes, identity(tube().nodes.size()), s);
  const std::size_t end_nodes = count_on_plane(tube().nodes, 0.0) + count_on_plane(tube().nodes, 0.04);
  EXPECT_EQ(static_cast<std::size_t>(std::count(held.begin(), held.end(), 1)), 3 * end_nodes);
}

TEST(Supports, RollerEndsHoldTheAxialDofAndThreeInPlanePinsAtTheLameSymmetryPoints) {
  const Supports s = end_supports(
      structured_tube(), {{"inlet", EndCondition::roller}, {"outlet", EndCondition::roller}}, "");
  ASSERT_EQ(s.pins.size(), 3u);
  const auto& nodes = tube().nodes;
  const auto held = held_dofs(tube(), nodes, identity(nodes.size()), s);
  const std::size_t end_nodes = count_on_plane(nodes, 0.0) + count_on_plane(nodes, 0.04);
  EXPECT_EQ(static_cast<std::size_t>(std::count(held.begin(), held.end(), 1)), end_nodes + 3);
  // The structured tube has nodes exactly at (±a, 0, 0) and (0, a, 0): u_y, u_y and u_x held there.
  const double a = structured_tube().inner_radius;
  const std::pair<Vec3, int> expected[] = {
      {Vec3(a, 0, 0), 1}, {Vec3(-a, 0, 0), 1}, {Vec3(0, a, 0), 0}};
  for (const auto& [point, component] : expected) {
    const auto it = std::find_if(nodes.begin(), nodes.end(),
                                 [&](const Vec3& x) { return (x - point).norm() < 1e-12; });
    ASSERT_NE(it, nodes.end());
    EXPECT_EQ(held[3 * static_cast<std::size_t>(it - nodes.begin()) + component], 1);
  }
}

TEST(Supports, RollersOnTheArchAndMissingGroupsAreRefused) {
  VesselParams arch = structured_tube();
  arch.kind = VesselKind::arch;
  try {
    (void)end_supports(arch, {{"inlet", EndCondition::roller}}, "scene.toml");
    FAIL() << "rollers on the arch accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.toml: roller ends"), std::string::npos) << e.what();
  }
  const Supports s = end_supports(structured_tube(), {{"nowhere", EndCondition::clamped}}, "");
  EXPECT_THROW((void)held_dofs(tube(), tube().nodes, identity(tube().nodes.size()), s), InputError);
  EXPECT_TRUE(end_supports(structured_tube(), {{"inlet", EndCondition::free}}, "").holds_nothing());
}

TEST(Supports, PlaneAndOpenBoundarySelectionsOnHandMadeSurfaces) {
  // Two triangles forming a square: every node is on the open boundary; z splits it in two.
  const std::vector<Vec3> nodes{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  const std::vector<Triangle> square{{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(open_boundary_nodes(square), (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(nodes_beyond_plane_z(nodes, 0.5, true), (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(nodes_beyond_plane_z(nodes, 0.5, false), (std::vector<std::size_t>{2, 3}));
  // A closed tetrahedron's surface has no open boundary.
  const std::vector<Triangle> closed{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  EXPECT_TRUE(open_boundary_nodes(closed).empty());
}
