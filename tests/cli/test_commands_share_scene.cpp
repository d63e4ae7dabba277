// The fem and msm commands build their problems through the same scene builder: the same default
// contact point on both vessels, the same patch, and an absent load not built at all.
#include <gtest/gtest.h>

#include <numbers>

#include <nlohmann/json.hpp>

#include "../test_helpers.hpp"

using vessel::test::read_text;
using vessel::test::TempDir;
using vessel::test::vv;

namespace {

nlohmann::json run_json(const std::string& args, const std::filesystem::path& out) {
  const auto r = vv(args + " --json " + out.string());
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
  return nlohmann::json::parse(read_text(out));
}

}  // namespace

TEST(CommandsShareTheScene, FemAndMsmPushTheArchAtTheSameDefaultPointOverTheSamePatch) {
  TempDir dir;
  // The arch's default contact: its outer bend's apex on the inner wall, (0, R + a, 0) with the
  // default R = 15 mm and a = 3 mm, with the default patch radius 0.5 mm at level 0 (which the
  // centroid-selected patch could not load), on the unstructured and the structured mesh.
  for (const std::string mesh : {"", "--structured "}) {
    const std::string arch = "--vessel arch --level 0 " + mesh;
    const auto fem = run_json("fem " + arch + "--load contact", dir / "fem.json");
    const auto msm = run_json("msm " + arch + "--solver linear", dir / "msm.json");
    for (const auto* j : {&fem, &msm}) {
      const auto& c = (*j)["contact"];
      // Projected onto the faceted wall: within a chord's sagitta (< 0.05 mm here) of the apex.
      EXPECT_NEAR(c["point_mm"][0].get<double>(), 0.0, 0.05) << mesh;
      EXPECT_NEAR(c["point_mm"][1].get<double>(), 18.0, 0.05) << mesh;
      EXPECT_NEAR(c["point_mm"][2].get<double>(), 0.0, 0.05) << mesh;
      EXPECT_DOUBLE_EQ(c["radius_mm"].get<double>(), 0.5) << mesh;
      // It pushes the wall outwards, away from the bend's centre: +y.
      EXPECT_GT(c["inward_normal"][1].get<double>(), 0.99) << mesh;
      // The exact disc: π (0.5 mm)² = 0.785 mm², up to the wall's curvature and the level-0
      // facets' tilt to the tangent plane (about 1 %).
      EXPECT_NEAR(c["patch_area_mm2"].get<double>() / (std::numbers::pi * 0.25), 1.0, 0.02) << mesh;
    }
    EXPECT_EQ(fem["contact"]["point_mm"], msm["contact"]["point_mm"]) << mesh;
    EXPECT_EQ(fem["contact"]["patch_triangles"], msm["contact"]["patch_triangles"]) << mesh;
    EXPECT_DOUBLE_EQ(fem["contact"]["patch_area_mm2"].get<double>(),
                     msm["contact"]["patch_area_mm2"].get<double>()) << mesh;
  }
}

TEST(CommandsShareTheScene, AnAbsentContactIsNotBuiltSoPressureAloneRuns) {
  TempDir dir;
  // The structured level-0 tube's cells are larger than the default patch: a contact patch
  // there would be refused, but a zero force builds none.
  const auto j = run_json("msm --structured --force 0 --pressure 200 --solver linear",
                          dir / "p.json");
  EXPECT_FALSE(j.contains("contact"));
  EXPECT_GT(j["max_displacement_mm"].get<double>(), 0.0);
}
