// The fem and msm commands build their problems through the same scene builder: the same default
// contact point on both vessels, the same patch, and an absent load not built at all.
#include <gtest/gtest.h>

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
  // default R = 15 mm and a = 3 mm.
  const std::string arch = "--vessel arch --structured --level 0 ";
  const auto fem = run_json("fem " + arch + "--load contact --contact-radius 0.0015",
                            dir / "fem.json");
  const auto msm = run_json("msm " + arch + "--patch-radius 0.0015 --solver linear",
                            dir / "msm.json");
  for (const auto* j : {&fem, &msm}) {
    const auto& c = (*j)["contact"];
    EXPECT_NEAR(c["point_mm"][0].get<double>(), 0.0, 1e-12);
    EXPECT_NEAR(c["point_mm"][1].get<double>(), 18.0, 1e-12);
    EXPECT_NEAR(c["point_mm"][2].get<double>(), 0.0, 1e-12);
    // It pushes the wall outwards, away from the bend's centre: +y.
    EXPECT_GT(c["inward_normal"][1].get<double>(), 0.99);
  }
  EXPECT_EQ(fem["contact"]["patch_triangles"], msm["contact"]["patch_triangles"]);
  EXPECT_DOUBLE_EQ(fem["contact"]["patch_area_mm2"].get<double>(),
                   msm["contact"]["patch_area_mm2"].get<double>());
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
