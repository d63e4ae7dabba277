// Shared load definitions against closed forms: totals, patch area, directions.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "meshes/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"

using namespace vessel;

namespace {
const TetMesh& tube() {
  static const TetMesh mesh = generate_vessel_mesh(VesselParams{});
  return mesh;
}
}  // namespace

TEST(SurfaceLoads, ContactPatchCarriesExactlyTheForceInwardIntoTheWall) {
  // Contact on the inner wall at mid-length, on the +x side: the wall is pushed towards +x.
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0.0, 20e-3);
  spec.radius = 2e-3;
  spec.force = 0.05;
  const TractionPatch patch = contact_patch(tube(), spec);
  EXPECT_GT(patch.triangles.size(), 3u);
  // The patch is a disc of radius ≈ r_c on the cylinder: area ≈ π r_c² (within the centroid
  // selection's granularity at h ≈ 1 mm).
  EXPECT_NEAR(patch.area / (std::numbers::pi * 4e-6), 1.0, 0.35);
  EXPECT_NEAR(patch.outward_normal.x(), -1.0, 0.02);  // inner wall faces the axis
  const Vec3 total = total_load(traction_nodal_loads(tube(), patch));
  EXPECT_NEAR(total.x(), 0.05 * -patch.outward_normal.x(), 1e-14);
  EXPECT_NEAR((total - (-0.05) * patch.outward_normal).norm(), 0.0, 1e-14);
}

TEST(SurfaceLoads, ContactPointOffTheWallIsRefused) {
  ContactPatchSpec spec;
  spec.point = Vec3(0.0, 0.0, 20e-3);  // on the axis, 3 mm from the wall
  spec.force = 0.01;
  try {
    (void)contact_patch(tube(), spec);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("off the wall"), std::string::npos) << e.what();
  }
  spec.point = Vec3(3e-3, 0.0, 20e-3);
  spec.radius = -1.0;
  EXPECT_THROW((void)contact_patch(tube(), spec), InputError);
}

TEST(SurfaceLoads, InternalPressureCancelsAndPushesOutwardWithPTimesArea) {
  // Pressure on the inner wall alone: Σ −p n A over a surface closed around the circumference
  // (an open tube) is zero up to the rims' contribution, which is axial and also zero: total ≈ 0.
  const auto f = pressure_nodal_loads(tube(), "inner_wall", 100.0);
  EXPECT_LT(total_load(f).norm(), 1e-12);
  // The radial components push outward: Σ f·r̂ = p × (inner wall area).
  double radial = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const Vec3& x = tube().nodes[i];
    const double r = std::hypot(x.x(), x.y());
    if (r > 0) radial += (f[i].x() * x.x() + f[i].y() * x.y()) / r;
  }
  double area = group_area(tube(), *tube().find_group("inner_wall", 2));
  EXPECT_NEAR(radial / (100.0 * area), 1.0, 0.01);
}

TEST(SurfaceLoads, GravitySumsToWeight) {
  const Vec3 g(0, -9.81, 0);
  const double rho = 1060.0;
  const Vec3 total = total_load(body_force_nodal_loads(tube(), rho * g));
  EXPECT_NEAR(total.y(), -9.81 * rho * mesh_volume(tube()), 1e-15);
  EXPECT_NEAR(total.x(), 0.0, 1e-18);
}
