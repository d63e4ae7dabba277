// Vessel parameters: validation messages and closed-form measures against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "meshes/foundation/errors.hpp"
#include "meshes/vessel_geometry.hpp"

using namespace vessel;

namespace {

std::string validation_message(const VesselParams& p) {
  try {
    validate(p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(VesselGeometry, DefaultsAreValid) { EXPECT_NO_THROW(validate(VesselParams{})); }

TEST(VesselGeometry, NegativeRadiusIsRefusedNamingTheParameter) {
  VesselParams p;
  p.inner_radius = -1e-3;
  const auto msg = validation_message(p);
  EXPECT_NE(msg.find("inner_radius"), std::string::npos) << msg;
  EXPECT_NE(msg.find("> 0"), std::string::npos) << msg;
}

TEST(VesselGeometry, NonFiniteOrZeroSizesAreRefused) {
  VesselParams p;
  p.length = std::nan("");
  EXPECT_NE(validation_message(p).find("length"), std::string::npos);
  p = VesselParams{};
  p.wall_thickness = 0.0;
  EXPECT_NE(validation_message(p).find("wall_thickness"), std::string::npos);
}

TEST(VesselGeometry, ArchWallReachingTheBendAxisIsRefused) {
  VesselParams p;
  p.kind = VesselKind::arch;
  p.bend_radius = 3.5e-3;  // outer radius 4 mm > R
  const auto msg = validation_message(p);
  EXPECT_NE(msg.find("too thick"), std::string::npos) << msg;
  EXPECT_NE(msg.find("bend_radius"), std::string::npos) << msg;
}

TEST(VesselGeometry, WallMuchThickerThanTheLumenIsRefused) {
  VesselParams p;
  p.inner_radius = 0.1e-3;
  p.wall_thickness = 2e-3;
  EXPECT_NE(validation_message(p).find("wall_thickness"), std::string::npos);
}

TEST(VesselGeometry, LevelOutOfRangeIsRefused) {
  VesselParams p;
  p.level = kMaxMeshLevel + 1;
  EXPECT_NE(validation_message(p).find("level"), std::string::npos);
  p.level = -1;
  EXPECT_NE(validation_message(p).find("level"), std::string::npos);
}

TEST(VesselGeometry, ClosedFormVolumesMatchHandValues) {
  // Straight: π (4² − 3²) mm² × 40 mm = 280π mm³.
  VesselParams tube;
  EXPECT_NEAR(analytic_wall_volume(tube), 280.0 * std::numbers::pi * 1e-9, 1e-18);
  // Arch (Pappus): π (4² − 3²) mm² × π × 15 mm = 105π² mm³.
  VesselParams arch;
  arch.kind = VesselKind::arch;
  EXPECT_NEAR(analytic_wall_volume(arch), 105.0 * std::numbers::pi * std::numbers::pi * 1e-9,
              1e-18);
  // Inner lateral area of the arch: 2π·3 mm × π·15 mm = 90π² mm².
  EXPECT_NEAR(analytic_lateral_area(arch, 3e-3), 90.0 * std::numbers::pi * std::numbers::pi * 1e-6,
              1e-15);
  EXPECT_NEAR(analytic_end_area(tube), 7.0 * std::numbers::pi * 1e-6, 1e-15);
}

TEST(VesselGeometry, DistanceFromCentreline) {
  VesselParams tube;
  EXPECT_DOUBLE_EQ(distance_from_centreline(tube, Vec3(3e-3, 4e-3, 7e-3)), 5e-3);
  VesselParams arch;
  arch.kind = VesselKind::arch;
  // On the y axis at radius R + 1 mm, 2 mm above the plane: sqrt(1² + 2²) mm.
  EXPECT_NEAR(distance_from_centreline(arch, Vec3(0.0, 16e-3, 2e-3)), std::sqrt(5.0) * 1e-3,
              1e-15);
}

TEST(VesselGeometry, StructuredCountsDoublePerLevel) {
  VesselParams p;
  p.style = MeshStyle::structured;
  const auto c0 = structured_counts(p);
  EXPECT_EQ(c0.circumferential % 4, 0);
  p.level = 2;
  const auto c2 = structured_counts(p);
  EXPECT_EQ(c2.circumferential, 4 * c0.circumferential);
  EXPECT_EQ(c2.axial, 4 * c0.axial);
  EXPECT_EQ(c2.radial, 4 * c0.radial);
  // Level 0 is coarse enough for unit tests: 1–3k nodes.
  EXPECT_GE(c0.expected_nodes(), 1000);
  EXPECT_LE(c0.expected_nodes(), 3000);
}

TEST(VesselGeometry, CentrelineCoordinatesOfHandPlacedPoints) {
  const VesselParams tube;
  const auto t = centreline_coordinates(tube, Vec3(0.0, 3e-3, 7e-3));
  EXPECT_DOUBLE_EQ(t.s, 7e-3);
  EXPECT_DOUBLE_EQ(t.rho, 3e-3);
  EXPECT_NEAR(t.theta, std::numbers::pi / 2.0, 1e-15);
  EXPECT_NEAR((t.e_rho - Vec3::UnitY()).norm(), 0.0, 1e-15);

  VesselParams arch;
  arch.kind = VesselKind::arch;  // centreline: radius R about z, φ from 0 to π
  const double R = arch.bend_radius;
  // The outer bend's apex at φ = π/2: θ = 0, e_ρ away from the arch's centre.
  const auto apex = centreline_coordinates(arch, Vec3(0.0, R + 3e-3, 0.0));
  EXPECT_NEAR(apex.s, R * std::numbers::pi / 2.0, 1e-15);
  EXPECT_NEAR(apex.rho, 3e-3, 1e-15);
  EXPECT_NEAR(apex.theta, 0.0, 1e-12);
  EXPECT_NEAR((apex.e_rho - Vec3::UnitY()).norm(), 0.0, 1e-12);
  // Above the centreline at φ = 0: θ = π/2; the inner bend: θ = π.
  EXPECT_NEAR(centreline_coordinates(arch, Vec3(R, 0.0, 2e-3)).theta, std::numbers::pi / 2.0, 1e-12);
  EXPECT_NEAR(std::abs(centreline_coordinates(arch, Vec3(R - 2e-3, 0.0, 0.0)).theta),
              std::numbers::pi, 1e-12);
}
