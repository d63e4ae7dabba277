// `vesselverify recommend` end to end on a small level-0 contact scene (every generated candidate
// against a level-0 reference: a few seconds). The answer is checked against the budget's
// definition from the written evidence: the recommended candidate meets the tolerance and the
// time per update, and every candidate faster than it (beyond the 5 % timing tie) misses one;
// the report embeds the section. The first test's time budget (10 s per update) is one every
// candidate meets, so what it checks does not depend on the machine's speed.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "../schema_check.hpp"
#include "../test_helpers.hpp"

using vessel::test::CommandResult;
using vessel::test::read_text;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::write_text;
using vessel::test::vv;

namespace {

const char* kScene = R"(name = "small_contact"
[vessel]
kind = "straight"
mesh = "structured"
level = 0
reference_level = 0
[load]
type = "contact"
magnitudes = [1.0e-5, 1.0e-4]
point = [3.0e-3, 0.0, 20.0e-3]
patch_radius = 1.0e-3
[[models]]
name = "volume"
kind = "volume_msm"
solver = "static"
[budget]
quantity = "patch"
radius = 0.003
tolerance_mm = 0.05
rate_hz = 30
)";

}  // namespace

TEST(RecommendCli, NamesACandidateThatMeetsTheBudgetWithItsEvidence) {
  TempDir dir;
  std::string scene = kScene;
  scene.replace(scene.find("rate_hz = 30"), 12, "time_budget_s = 10");
  write_text(dir / "scene.toml", scene);
  const auto out = dir / "rec";
  const CommandResult r = vv("recommend --quick --repeats 1 --roi-radii 0.004 --output-dir " +
                             out.string() + " " + (dir / "scene.toml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(read_text(out / "recommend.json"));
  EXPECT_EQ(j["schema"], "vesselverify.recommend");
  const auto problems = vessel::test::schema_problems(
      j, nlohmann::json::parse(read_text(VESSEL_RECOMMEND_SCHEMA)));
  EXPECT_TRUE(problems.empty()) << vessel::test::joined(problems);
  EXPECT_EQ(j["budget"]["quantity"], "patch");
  EXPECT_DOUBLE_EQ(j["budget"]["seconds_per_update"].get<double>(), 10.0);
  // FEM P1, corotational P1, XPBD FEM + (2 kinds × 6 rules + the hybrid volume model under its
  // two moduli rules + the edge-pair volume model + the discrete-shells surface model) ×
  // (static, linear, R = 4 mm), level 0.
  ASSERT_EQ(j["candidates"].size(), 51u);
  // At this small load corotational P1 is linear P1 to second order in the load: its patch error
  // against the P2 reference is P1's within 1 %.
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& c : j["candidates"]) by_name[c["name"]] = c;
  const auto& p1 = by_name["fem_p1 @ L0"];
  const auto& corotational = by_name["fem/corotational-p1/static @ L0"];
  ASSERT_TRUE(corotational["ok"].get<bool>()) << corotational.dump();
  EXPECT_NEAR(corotational["error"].get<double>(), p1["error"].get<double>(),
              0.01 * p1["error"].get<double>());
  const double tol = 0.05, budget = 10.0;
  ASSERT_FALSE(j["recommended"].is_null()) << read_text(out / "recommend.md");
  const std::string best = j["recommended"];
  double best_time = 0.0;
  for (const auto& c : j["candidates"]) {
    if (c["name"] == best) {
      EXPECT_EQ(c["verdict"], "recommended");
      EXPECT_LE(c["error"].get<double>(), tol);
      best_time = c["update_seconds"];
      EXPECT_LE(best_time, budget);
    }
  }
  for (const auto& c : j["candidates"]) {
    if (!c["ok"].get<bool>() || c["error"].is_null()) continue;
    const double e = c["error"], t = c["update_seconds"];
    if (t < best_time / 1.05) EXPECT_TRUE(e > tol || t > budget) << c.dump();
  }
  const std::string md = read_text(out / "recommend.md");
  EXPECT_NE(md.find("## Model recommendation: small_contact"), std::string::npos);
  EXPECT_NE(md.find("**Recommended: `" + best + "`**"), std::string::npos) << md;
  // The candidates' results carry the budget quantity for every outcome, at one load.
  const nlohmann::json res = nlohmann::json::parse(read_text(out / "results.json"));
  for (const auto& o : res["scenes"][0]["outcomes"]) {
    EXPECT_DOUBLE_EQ(o["magnitude"].get<double>(),
                     res["scenes"][0]["references"][0]["budget_magnitude"].get<double>());
    if (o["ok"].get<bool>()) EXPECT_TRUE(o["budget_error"].is_number()) << o["model"];
  }
  // The report draws the section from recommend.json.
  const CommandResult rep = vv("report " + (out / "results.json").string() + " --recommend " +
                               (out / "recommend.json").string());
  ASSERT_EQ(rep.exit_code, 0) << rep.output;
  const std::string report = read_text(out / "report.md");
  EXPECT_NE(report.find("## Model recommendation: small_contact"), std::string::npos);
  EXPECT_NE(report.find("**Recommended: `" + best + "`**"), std::string::npos) << report;
}

TEST(RecommendCli, SeveralRatesRunTheCandidatesOnceAndJudgeThemAtEachRate) {
  TempDir dir;
  write_text(dir / "scene.toml", kScene);
  const auto out = dir / "rec";
  const CommandResult r =
      vv("recommend --quick --repeats 1 --roi-radii 0.004 --rate 30,1000 --output-dir " +
         out.string() + " " + (dir / "scene.toml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::size_t runs = 0;  // "recommend small_contact: N candidate models ..." once per harness run
  for (std::size_t at = r.output.find("recommend small_contact:"); at != std::string::npos;
       at = r.output.find("recommend small_contact:", at + 1)) {
    ++runs;
  }
  EXPECT_EQ(runs, 1u) << r.output;
  const nlohmann::json slow = nlohmann::json::parse(read_text(out / "30hz" / "recommend.json"));
  const nlohmann::json fast = nlohmann::json::parse(read_text(out / "1000hz" / "recommend.json"));
  EXPECT_DOUBLE_EQ(slow["budget"]["seconds_per_update"].get<double>(), 1.0 / 30.0);
  EXPECT_DOUBLE_EQ(fast["budget"]["seconds_per_update"].get<double>(), 1e-3);
  ASSERT_EQ(slow["candidates"].size(), fast["candidates"].size());
  for (std::size_t i = 0; i < slow["candidates"].size(); ++i) {
    const auto &a = slow["candidates"][i], &b = fast["candidates"][i];
    EXPECT_EQ(a["name"], b["name"]);
    if (!a["ok"].get<bool>() || a["error"].is_null()) continue;
    EXPECT_EQ(a["update_seconds"], b["update_seconds"]);  // the same measurement
    EXPECT_EQ(a["error"], b["error"]);
    // At 1 kHz every candidate slower than 1 ms is too slow, whatever it was at 30 Hz.
    if (b["update_seconds"].get<double>() > 1e-3) {
      EXPECT_NE(b["verdict"].get<std::string>().find("too slow"), std::string::npos) << b.dump();
    }
  }
  // The candidates ran once: the later rate's recommend.json names the first rate's results.json
  // (no copy), and the report reads the run from there.
  EXPECT_EQ(slow["results"], "results.json");
  EXPECT_EQ(fast["results"], "../30hz/results.json");
  EXPECT_FALSE(std::filesystem::exists(out / "1000hz" / "results.json"));
  const CommandResult rep = vv("report " + (out / "30hz" / "results.json").string() +
                               " --recommend " + (out / "1000hz" / "recommend.json").string() +
                               " --output-dir " + (out / "1000hz").string());
  ASSERT_EQ(rep.exit_code, 0) << rep.output;
  // The load unit came from the named results.json (without it the budget's load would read
  // "(the scene's load unit)").
  const std::string md = read_text(out / "1000hz" / "report.md");
  EXPECT_NE(md.find("1000 Hz"), std::string::npos);
  EXPECT_EQ(md.find("the scene's load unit"), std::string::npos);
  EXPECT_NE(read_text(out / "1000hz" / "report.md").find("1000 Hz"), std::string::npos);
}
