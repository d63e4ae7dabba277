// `vesselverify stability` end to end (the critical-step table at level 0 only) and the bad
// inputs of issue 6 at the command line: non-zero exit, a message naming the file and line or
// the key, and earlier results in the output directory left untouched.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "../test_helpers.hpp"

using vessel::test::CommandResult;
using vessel::test::read_text;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::write_text;
using vessel::test::vv;

namespace {

bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}

}  // namespace

TEST(StabilityCli, LevelZeroTableFindsTheUndampedLimitAtTheLanczosPrediction) {
  TempDir dir;
  const auto r = vv("stability --quick --no-hard-cases --max-level 0 --trial-steps 300 "
                    "--output-dir " + dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(read_text(dir / "stability.json"));
  EXPECT_EQ(j["schema"], "vesselverify.stability");
  ASSERT_EQ(j["critical_steps"].size(), 12u);  // 3 models × 4 integrator configurations
  for (const auto& row : j["critical_steps"]) {
    EXPECT_LT(row["omega_max"].get<double>(), row["omega_gershgorin"].get<double>());
    if (row["zeta"].get<double>() == 0.0) {
      // Undamped symplectic Euler and Verlet: 2/ω_max, independent of the masses' distribution.
      EXPECT_NEAR(row["predicted_dt"].get<double>() * row["omega_max"].get<double>(), 2.0, 1e-9);
      const double ratio = row["found_over_predicted"].get<double>();
      EXPECT_GT(ratio, 0.98) << row.dump();
      // A few trials past the limit stay below the energy bound in 300 steps: allow 0.5 %.
      EXPECT_LT(ratio, 1.005) << row.dump();
    }
  }
  const std::string md = read_text(dir / "stability.md");
  EXPECT_EQ(md.rfind("## Numerical stability", 0), 0u);
}

TEST(StabilityCli, LongRunKeepsSymplecticEulerAndVerletBoundedAndExplicitEulerDiverges) {
  TempDir dir;
  const auto r = vv("stability --quick --max-level 0 --trial-steps 100 --hard-case long_run "
                    "--long-run-steps 5000 --output-dir " + dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(read_text(dir / "stability.json"));
  ASSERT_EQ(j["hard_cases"].size(), 1u);  // --hard-case runs only that case
  const auto& hc = j["hard_cases"][0];
  EXPECT_EQ(hc["id"], "long_run");
  ASSERT_EQ(hc["outcomes"].size(), 4u);
  // Symplectic Euler and Verlet, undamped, at h = 0.9 × 2/ω_max. On a linear mode each conserves
  // a modified energy Ĥ exactly, and H = ½v² + ½ω²x² stays within fixed bounds of it: with
  // a = hω/2 ≤ 0.9, H/H₀ ≤ (1 + a)/(1 − a) = 19 for symplectic Euler (Ĥ = H − ½hω²xv) and
  // ≤ 1/(1 − a²) = 5.26 for velocity Verlet (Ĥ = ½v² + ½(1 − a²)ω²x²), for any number of steps
  // (both bounds are reached by a single mode from its worst phase; checked numerically).
  const double bound[] = {19.0, 1.0 / (1.0 - 0.81)};
  for (int k : {0, 1}) {
    const auto& oc = hc["outcomes"][k];
    SCOPED_TRACE(oc.dump());
    EXPECT_TRUE(oc["finished"].get<bool>());
    EXPECT_TRUE(oc["bounded"].get<bool>());
    EXPECT_EQ(oc["values"]["steps"].get<double>(), 5000.0);
    EXPECT_GE(oc["values"]["energy_max_over_initial"].get<double>(), 1.0);
    EXPECT_LT(oc["values"]["energy_max_over_initial"].get<double>(), bound[k]);
  }
  // Undamped explicit Euler multiplies each mode's energy by exactly 1 + h²ω² per step
  // (h = 0.1 × 2/ω_max: at most 1.04), so reaching the 1000 × H₀ blow-up limit takes at least
  // ln 1000 / ln 1.04 ≈ 176 steps; it must stop there, long before 5000.
  const auto& ee = hc["outcomes"][3];
  EXPECT_FALSE(ee["finished"].get<bool>()) << ee.dump();
  EXPECT_FALSE(ee["bounded"].get<bool>()) << ee.dump();
  EXPECT_GE(ee["values"]["diverged_at_step"].get<double>(), 170.0) << ee.dump();
  EXPECT_LT(ee["values"]["diverged_at_step"].get<double>(), 5000.0) << ee.dump();

  const auto bad = vv("stability --quick --hard-case long_walk --output-dir " + dir.path().string());
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_TRUE(contains(bad.output, "--hard-case: unknown case 'long_walk'")) << bad.output;
  EXPECT_TRUE(contains(bad.output, "long_run")) << bad.output;
  EXPECT_FALSE(contains(bad.output, "[stability]")) << bad.output;  // refused before any work
}

TEST(StabilityCli, UnwritableOutputDirectoryFailsBeforeAnyWorkAndBadOptionsLeaveResults) {
  TempDir dir;
  write_text(dir / "file", "x");
  auto r = vv("stability --quick --output-dir " + (dir / "file" / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--output-dir")) << r.output;
  EXPECT_TRUE(contains(r.output, (dir / "file" / "out").string())) << r.output;
  EXPECT_FALSE(contains(r.output, "[stability]")) << r.output;  // refused before any work
  write_text(dir / "stability.json", "earlier");
  r = vv("stability --trial-steps -3 --output-dir " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--trial-steps")) << r.output;
  EXPECT_EQ(read_text(dir / "stability.json"), "earlier");
}

TEST(BadInputCli, EmptyMalformedAndNonFiniteMeshFilesNameTheFileAndLine) {
  TempDir dir;
  write_text(dir / "empty.msh", "");
  auto r = vv("mesh --input " + (dir / "empty.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "empty.msh: mesh file is empty")) << r.output;
  write_text(dir / "empty.stl", "");
  r = vv("mesh --input " + (dir / "empty.stl").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "empty.stl: STL file is empty")) << r.output;
  write_text(dir / "cut.stl",
             "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n");
  r = vv("mesh --input " + (dir / "cut.stl").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "cut.stl:5: expected 'vertex x y z'")) << r.output;
  // A NaN coordinate in an otherwise valid vessel mesh written by the program itself.
  r = vv("mesh --no-cache -o " + (dir / "full.msh").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::string text = read_text(dir / "full.msh");
  const auto nodes = text.find("$Nodes");
  // Node block: "$Nodes", the header, the entity header, the tags, then the coordinates.
  std::size_t line = nodes;
  for (int k = 0; k < 3; ++k) line = text.find('\n', line) + 1;
  const int count = std::stoi(text.substr(text.find_last_of(' ', text.find('\n', line - 2)) + 1));
  for (int k = 0; k < count; ++k) line = text.find('\n', line) + 1;
  const auto end = text.find('\n', line);
  text.replace(line, end - line, "nan 0 0");
  write_text(dir / "nan.msh", text);
  r = vv("mesh --input " + (dir / "nan.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "nan.msh:")) << r.output;
  EXPECT_TRUE(contains(r.output, "non-finite x coordinate 'nan'")) << r.output;
}

TEST(BadInputCli, SceneWrongTypesAndRangesNameFileLineAndKeyAndRunLeavesEarlierResults) {
  TempDir dir;
  const std::string base = read_text(std::string(VESSEL_SCENES_DIR) + "/contact_straight.toml");
  struct Case {
    std::string from, to, expect;
  };
  const Case cases[] = {
      {"E = 14.24e3", "E = \"soft\"", "key 'material.E'"},
      {"E = 14.24e3", "E = -1.0", "key 'material.E'"},
      {"nu = ", "nu = 0.7 #", "material.nu"},
  };
  write_text(dir / "results.json", "earlier");
  for (const auto& c : cases) {
    std::string s = base;
    const auto at = s.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    s.replace(at, c.from.size(), c.to);
    write_text(dir / "bad.toml", s);
    auto r = vv("scene " + (dir / "bad.toml").string());
    EXPECT_EQ(r.exit_code, 1) << c.to << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "bad.toml:")) << r.output;
    EXPECT_TRUE(contains(r.output, c.expect)) << r.output;
    r = vv("run --quick --output-dir " + dir.path().string() + " " + (dir / "bad.toml").string());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(read_text(dir / "results.json"), "earlier");
  }
}

TEST(BadInputCli, ContactPointOffTheWallIsRefusedByTheMassSpringCommand) {
  TempDir dir;
  const auto r = vv("msm --contact-point 0 0 0.02 --json " + (dir / "x.json").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "off the wall")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}
