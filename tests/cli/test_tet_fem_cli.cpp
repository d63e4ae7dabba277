// `vesselverify run` on the P1 tet models simulators use (scene kinds corotational_fem and
// xpbd_fem), checked against linear P1 FEM solved by the reference code (deal.II) on the same mesh
// in the same run: at small load both must agree with it to second order in the load.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "../test_helpers.hpp"

using namespace vessel::test;

namespace {

nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

/// contact_straight's tube and patch at level 0 (its reference at level 0 too), with `models`.
std::string tube_scene(const std::string& magnitudes, const std::string& models) {
  return R"(name = "tet_fem_tube"
[vessel]
kind = "straight"
inner_radius = 3.0e-3
wall_thickness = 1.0e-3
length = 40.0e-3
mesh = "structured"
level = 0
reference_level = 0
[material]
E = 14.24e3
nu = 0.45
density = 1060.0
[boundary]
inlet = "clamped"
outlet = "clamped"
[load]
type = "contact"
magnitudes = )" +
         magnitudes + R"(
point = [3.0e-3, 0.0, 20.0e-3]
patch_radius = 1.0e-3
surface = "inner_wall"
[[models]]
name = "p1"
kind = "fem"
degree = 1
)" + models;
}

}  // namespace

// Corotational P1 removes the rotation linear P1 lacks: under a small load the two differ by
// O(f²), so their contact-point displacements differ relatively by O(f). Linear P1 here is the
// reference code's own P1 (deal.II, its own assembly and solver) on the same mesh and loads.
TEST(TetFemCli, CorotationalAgreesWithLinearP1ToSecondOrderInTheLoad) {
  TempDir dir;
  write_text(dir / "scene.toml", tube_scene("[1.0e-6, 1.0e-5]", R"(
[[models]]
name = "corot"
kind = "corotational_fem"
)"));
  const auto run = vv("run --no-cache --output-dir " + (dir / "out").string() + " " +
                      (dir / "scene.toml").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json results = read_json(dir / "out" / "results.json");
  std::map<std::string, std::map<double, double>> qoi;  // model → load → QoI (mm)
  for (const auto& o : results["scenes"][0]["outcomes"]) {
    ASSERT_TRUE(o["ok"].get<bool>()) << o.dump();
    qoi[o["model"]][o["magnitude"].get<double>()] = o["qoi_displacement_mm"].get<double>();
    if (o["model"] == "corot") {
      EXPECT_EQ(o["kind"], "corotational_fem");
      EXPECT_GT(o["solve_seconds"].get<double>(), 0.0) << o.dump();
    }
  }
  ASSERT_EQ(qoi["corot"].size(), 2u);
  ASSERT_EQ(qoi["p1"].size(), 2u);
  const auto relative = [&](double f) {
    return std::abs(qoi["corot"][f] - qoi["p1"][f]) / qoi["p1"][f];
  };
  const double small = relative(1e-6), large = relative(1e-5);
  std::cout << "[ corotational vs P1 ] relative QoI difference " << small << " at 1 µN, " << large
            << " at 10 µN\n";
  // The load grows tenfold: a second-order difference grows tenfold relative to the answer.
  EXPECT_LT(small, 1e-3);
  EXPECT_GT(large / small, 5.0);
  EXPECT_LT(large / small, 20.0);
}

TEST(TetFemCli, AKeyOfAnotherKindIsRefusedNamingTheKeyAndLine) {
  TempDir dir;
  write_text(dir / "scene.toml", tube_scene("[1.0e-6]", R"(
[[models]]
name = "corot"
kind = "corotational_fem"
velocity_damping = 0.1
)"));
  const auto r = vv("scene " + (dir / "scene.toml").string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("scene.toml:31: key 'models[1].velocity_damping'"), std::string::npos)
      << r.output;
  // The same key on an xpbd_fem model is its own, and out of range is refused naming it.
  write_text(dir / "scene.toml", tube_scene("[1.0e-6]", R"(
[[models]]
name = "xpbd"
kind = "xpbd_fem"
velocity_damping = 1.5
)"));
  const auto x = vv("scene " + (dir / "scene.toml").string());
  EXPECT_NE(x.exit_code, 0) << x.output;
  EXPECT_NE(x.output.find("scene.toml:31: key 'models[1].velocity_damping'"), std::string::npos)
      << x.output;
}
