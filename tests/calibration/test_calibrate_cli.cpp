// `vesselverify calibrate` end to end on a short tube (models at level 0, reference P2 at level 0
// to keep it short): the calibration file is written with its training loads, training and
// held-out errors are reported apart, the calibrated model improves on its training load (the
// P2 reference is the independent truth), a scene's model runs with the file, and the same file
// on another mesh level is refused with an error naming the mesh hash.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "schema_check.hpp"
#include "test_helpers.hpp"

using vessel::test::read_text;
using vessel::test::TempDir;
using vessel::test::vv;
using vessel::test::write_text;

namespace {

std::string scene_text(int level, const std::string& extra_model) {
  return R"(name = "short_contact"
[vessel]
kind = "straight"
length = 10.0e-3
mesh = "structured"
level = )" + std::to_string(level) + R"(
reference_level = 0
[material]
E = 14.24e3
nu = 0.45
[load]
type = "contact"
magnitudes = [1.0e-4, 5.0e-4]
point = [3.0e-3, 0.0, 5.0e-3]
patch_radius = 1.0e-3
[budget]
magnitude = 5.0e-4
rate_hz = 30
[[models]]
name = "volume_hybrid"
kind = "volume_msm"
volume_term = true
stiffness = "van-gelder"
)" + extra_model;
}

}  // namespace

TEST(CalibrateCli, FitsReportsHeldOutAndTheFileIsUsedOnItsMeshOnly) {
  const TempDir dir;
  write_text(dir / "scene.toml", scene_text(0, ""));
  const auto r = vv("calibrate " + (dir / "scene.toml").string() + " --output " +
                    (dir / "cal.json").string() + " --cache-dir " + (dir / "cache").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("## Training loads"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("## Held-out loads"), std::string::npos);
  EXPECT_NE(r.output.find("other contact point"), std::string::npos);
  EXPECT_NE(r.output.find("other load type"), std::string::npos);
  EXPECT_NE(r.output.find("other magnitude"), std::string::npos);
  const auto j = nlohmann::json::parse(read_text(dir / "cal.json"));
  EXPECT_EQ(j["schema"], "vesselverify.calibration");
  EXPECT_EQ(j["training_loads"].size(), 2u);
  // The study's document beside it, as its schema says, with the training cases the file names.
  const auto study = nlohmann::json::parse(read_text(dir / "cal.study.json"));
  const auto problems = vessel::test::schema_problems(
      study, nlohmann::json::parse(read_text(VESSEL_CALIBRATE_SCHEMA)));
  EXPECT_TRUE(problems.empty()) << vessel::test::joined(problems);
  EXPECT_EQ(study["calibration_file"], (dir / "cal.json").string());
  std::size_t training = 0;
  for (const auto& c : study["cases"]) training += c["training"].get<bool>() ? 1 : 0;
  EXPECT_EQ(training, j["training_loads"].size());
  EXPECT_EQ(j["model"]["name"], "volume_hybrid");
  ASSERT_TRUE(j["factors"].contains("kappa"));
  // The fit lowered the training loads' error (linearised model, against the P2 reference).
  for (const auto& c : j["fit"]["training_cases_linearised"]) {
    EXPECT_LT(c["relative_l2_after"].get<double>(), c["relative_l2_before"].get<double>());
  }

  const std::string calibrated = R"(
[[models]]
name = "volume_calibrated"
kind = "volume_msm"
volume_term = true
stiffness = "van-gelder"
calibration = "cal.json"
)";
  write_text(dir / "with_cal.toml", scene_text(0, calibrated));
  const auto run = vv("run --fields none --output-dir " + (dir / "out").string() + " --cache-dir " +
                      (dir / "cache").string() + " " + (dir / "with_cal.toml").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto results = nlohmann::json::parse(read_text(dir / "out" / "results.json"));
  EXPECT_NE(results.dump().find("calibrated (cal.json)"), std::string::npos);

  // On another mesh the calibration is refused (its mesh hash differs): the model fails alone,
  // naming the file and the key, and the run goes on and writes its results.
  write_text(dir / "level1.toml", scene_text(1, calibrated));
  const auto other = vv("run --fields none --output-dir " + (dir / "out1").string() +
                        " --cache-dir " + (dir / "cache").string() + " " +
                        (dir / "level1.toml").string());
  ASSERT_EQ(other.exit_code, 0) << other.output;
  const auto refused = nlohmann::json::parse(read_text(dir / "out1" / "results.json"));
  int failed = 0;
  for (const auto& o : refused["scenes"][0]["outcomes"]) {
    if (o["model"] != "volume_calibrated") continue;
    EXPECT_FALSE(o["ok"].get<bool>());
    const std::string why = o["failure"].get<std::string>();
    EXPECT_NE(why.find("mesh.hash"), std::string::npos) << why;
    EXPECT_NE(why.find("cal.json"), std::string::npos) << why;
    ++failed;
  }
  EXPECT_GT(failed, 0);
}

// The edge-types granularity end to end: its classes (edge type x wall layer, kappa per half of
// the wall) in the file, the gravity magnitude and the P1 weights as asked, the fit lowering the
// training loads' mean squared error (against the P2 reference), and the file transferring to
// another mesh level with calibration_transfer (its classes are defined by geometry).
TEST(CalibrateCli, EdgeTypesWithP1WeightsWritesItsClassesAndTransfers) {
  const TempDir dir;
  write_text(dir / "scene.toml", scene_text(0, ""));
  const auto r = vv("calibrate " + (dir / "scene.toml").string() +
                    " --granularity edge-types --weights p1 --gravity 0.1"
                    " --train contact,pressure,gravity --output " +
                    (dir / "cal.json").string() + " --cache-dir " + (dir / "cache").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("reference max strain"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("weighted by 1/(P1's relative L2 error)^2"), std::string::npos);
  const auto j = nlohmann::json::parse(read_text(dir / "cal.json"));
  EXPECT_EQ(j["granularity"], "edge_types");
  EXPECT_TRUE(j["factors"].contains("kappa/inner"));
  EXPECT_TRUE(j["factors"].contains("kappa/outer"));
  EXPECT_FALSE(j["factors"].contains("kappa"));
  bool diagonal = false;
  for (const auto& [name, f] : j["factors"].items()) {
    if (name.find('+') != std::string::npos) diagonal = true;
  }
  EXPECT_TRUE(diagonal) << j["factors"].dump();
  bool gravity_at_01 = false;
  for (const auto& l : j["training_loads"]) {
    if (l["type"] == "gravity") gravity_at_01 = l["magnitude"].get<double>() == 0.1;
  }
  EXPECT_TRUE(gravity_at_01) << j["training_loads"].dump();
  double before = 0.0, after = 0.0;
  for (const auto& c : j["fit"]["training_cases_linearised"]) {
    before += std::pow(c["relative_l2_before"].get<double>(), 2);
    after += std::pow(c["relative_l2_after"].get<double>(), 2);
  }
  EXPECT_LT(after, before);

  const std::string transferred = R"(
[[models]]
name = "volume_edge_types"
kind = "volume_msm"
volume_term = true
stiffness = "van-gelder"
calibration = "cal.json"
calibration_transfer = true
)";
  write_text(dir / "level1.toml", scene_text(1, transferred));
  const auto run = vv("run --fields none --magnitudes 5e-4 --output-dir " + (dir / "out1").string() +
                      " --cache-dir " + (dir / "cache").string() + " " +
                      (dir / "level1.toml").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto results = nlohmann::json::parse(read_text(dir / "out1" / "results.json"));
  EXPECT_NE(results.dump().find("cal.json"), std::string::npos);
}

// A per-spring fit on top of an edge-types one (--prior): it starts where the prior ended (the
// linearised training errors before the fit are the prior's after it), keeps the prior's two κ
// halves apart, does not end worse than it started, and says so in its method. A prior with
// another granularity than per-spring, or fitted on another mesh, is refused naming the option
// or the key.
TEST(CalibrateCli, PerSpringOnTopOfAnEdgeTypesCalibrationStartsFromIt) {
  const TempDir dir;
  write_text(dir / "scene.toml", scene_text(0, ""));
  const std::string common = " --gravity 0.1 --train contact,pressure --cache-dir " +
                             (dir / "cache").string();
  const auto prior = vv("calibrate " + (dir / "scene.toml").string() +
                        " --granularity edge-types --output " + (dir / "prior.json").string() +
                        common);
  ASSERT_EQ(prior.exit_code, 0) << prior.output;
  const auto r = vv("calibrate " + (dir / "scene.toml").string() +
                    " --granularity per-spring --smoothness 0.001 --iterations 30 --prior " +
                    (dir / "prior.json").string() + " --output " + (dir / "spring.json").string() +
                    common);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto p = nlohmann::json::parse(read_text(dir / "prior.json"));
  const auto j = nlohmann::json::parse(read_text(dir / "spring.json"));
  EXPECT_EQ(j["granularity"], "per_spring");
  ASSERT_TRUE(j.contains("kappa_factors"));
  EXPECT_TRUE(j["kappa_factors"].contains("kappa/inner"));
  EXPECT_NE(j["fit"]["method"].get<std::string>().find("regularised towards"), std::string::npos);
  const auto& pc = p["fit"]["training_cases_linearised"];
  const auto& sc = j["fit"]["training_cases_linearised"];
  ASSERT_EQ(pc.size(), sc.size());
  double before = 0.0, after = 0.0;
  for (std::size_t i = 0; i < pc.size(); ++i) {
    EXPECT_NEAR(sc[i]["relative_l2_before"].get<double>(), pc[i]["relative_l2_after"].get<double>(),
                1e-9)
        << sc[i]["case"];
    before += std::pow(sc[i]["relative_l2_before"].get<double>(), 2);
    after += std::pow(sc[i]["relative_l2_after"].get<double>(), 2);
  }
  EXPECT_LE(after, before);

  const auto wrong = vv("calibrate " + (dir / "scene.toml").string() + " --prior " +
                        (dir / "prior.json").string() + " --output " +
                        (dir / "x.json").string() + common);
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_NE(wrong.output.find("--prior"), std::string::npos) << wrong.output;
  write_text(dir / "level1.toml", scene_text(1, ""));
  const auto other_mesh = vv("calibrate " + (dir / "level1.toml").string() +
                             " --granularity per-spring --prior " + (dir / "prior.json").string() +
                             " --output " + (dir / "y.json").string() + common);
  EXPECT_NE(other_mesh.exit_code, 0);
  EXPECT_NE(other_mesh.output.find("mesh.hash"), std::string::npos) << other_mesh.output;
}
