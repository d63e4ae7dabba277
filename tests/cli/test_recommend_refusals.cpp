// `vesselverify recommend` refuses conflicting or bad budgets before running anything.
#include <gtest/gtest.h>

#include "../test_helpers.hpp"

using vessel::test::CommandResult;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::write_text;
using vessel::test::vv;

namespace {

const char* kScene = R"(name = "small_contact"
[vessel]
kind = "straight"
level = 0
[load]
type = "contact"
magnitudes = [1.0e-4]
point = [3.0e-3, 0.0, 20.0e-3]
[[models]]
kind = "volume_msm"
[budget]
rate_hz = 30
)";

}  // namespace

TEST(RecommendCli, ConflictingOrBadBudgetsAreRefused) {
  TempDir dir;
  write_text(dir / "scene.toml", kScene);
  const std::string scene = (dir / "scene.toml").string();
  EXPECT_EQ(vv("recommend --rate 30 --time-budget 0.01 " + scene).exit_code, 2);
  EXPECT_EQ(vv("recommend --rate -5 " + scene).exit_code, 2);
  EXPECT_EQ(vv("recommend --tolerance 0 " + scene).exit_code, 2);
  std::string bad = kScene;
  bad.replace(bad.find("rate_hz = 30"), 12, "rate_hz = 0");
  write_text(dir / "bad.toml", bad);
  const CommandResult r = vv("recommend " + (dir / "bad.toml").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("budget.rate_hz"), std::string::npos) << r.output;
}
