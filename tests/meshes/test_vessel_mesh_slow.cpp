// Slow (label `slow`): finer levels of the generated vessels.
#include <gtest/gtest.h>

#include "meshes/gmsh_vessel.hpp"

using namespace vessel;

TEST(SlowStructuredVessel, NodeCountsGrowTowards8xUpToLevel3) {
  VesselParams p;
  p.style = MeshStyle::structured;
  long previous = 0;
  for (int level = 0; level <= 3; ++level) {
    p.level = level;
    const TetMesh mesh = generate_vessel_mesh(p);
    const long n = static_cast<long>(mesh.nodes.size());
    EXPECT_EQ(n, structured_counts(p).expected_nodes());
    if (previous > 0) {
      const double ratio = static_cast<double>(n) / static_cast<double>(previous);
      EXPECT_GT(ratio, 6.0) << "level " << level;
      EXPECT_LT(ratio, 8.0) << "level " << level;
    }
    previous = n;
  }
}

TEST(SlowVesselMesh, Level2VolumeErrorKeepsFalling) {
  for (auto kind : {VesselKind::straight, VesselKind::arch}) {
    double previous = 1.0;
    for (int level = 0; level <= 2; ++level) {
      VesselParams p;
      p.kind = kind;
      p.level = level;
      const double err = std::abs(mesh_volume(generate_vessel_mesh(p)) /
                                      analytic_wall_volume(p) - 1.0);
      EXPECT_LT(err, previous / 2.0) << to_string(kind) << " level " << level;
      previous = err;
    }
  }
}
