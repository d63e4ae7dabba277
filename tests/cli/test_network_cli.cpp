// `vesselverify msm --export-network` and the example in examples/network run end to end
// (`run`, then `report`), as a new user would from the README.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../test_helpers.hpp"

using namespace vessel::test;

namespace {

const std::string kExamples = VESSEL_EXAMPLES_DIR;

nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST(NetworkCli, ExportWritesTheBuiltNetworkInBothFormats) {
  TempDir dir;
  for (const char* name : {"net.json", "net.vtu"}) {
    const auto r = vv("msm --model volume --stiffness seed001 --mass seed001 --force 1e-4 "
                      "--no-cache --export-network " + (dir / name).string() + " --json " +
                      (dir / "run.json").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("wrote the network"), std::string::npos) << r.output;
    ASSERT_TRUE(std::filesystem::exists(dir / name));
  }
  const nlohmann::json net = read_json(dir / "net.json");
  const nlohmann::json run = read_json(dir / "run.json");
  EXPECT_EQ(net["format"], "vesselverify.network");
  EXPECT_EQ(net["follow_groups"], nlohmann::json::array({"inlet", "outlet"}));
  EXPECT_EQ(net["nodes"].size(), run["nodes"].get<std::size_t>());
  EXPECT_EQ(net["masses"].size(), net["nodes"].size());
  // The masses sum to ρ·V of the wall (seed001's mass rule is rescaled to the total mass):
  // the tube's volume π(b² − a²)L at level 0's faceted wall is within 2 % of it.
  double total = 0.0;
  for (const auto& m : net["masses"]) total += m.get<double>();
  const double a = 3e-3, b = 4e-3, L = 40e-3;
  EXPECT_NEAR(total, 1060.0 * M_PI * (b * b - a * a) * L, 0.02 * 1060.0 * M_PI * (b * b - a * a) * L);
}

TEST(NetworkCli, ExportRefusesTermsThatAreNotSprings) {
  TempDir dir;
  const auto r = vv("msm --model volume --volume-term --poisson-ratio 0.3 --no-cache "
                    "--export-network " + (dir / "h.json").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("holds springs only"), std::string::npos) << r.output;
  const auto bad = vv("msm --no-cache --export-network " + (dir / "h.txt").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("expected .json or .vtu"), std::string::npos) << bad.output;
}

TEST(NetworkCli, TheExampleRunsEndToEndAndItsReportListsTheNetwork) {
  TempDir dir;
  const std::string out = (dir / "results").string();
  // The reference at level 0 (the scene's is level 1: ~25 s here) keeps this in the default suite.
  const auto run = vv("run --no-cache --reference-level 0 --output-dir " + out + " " + kExamples +
                      "/network/scene.toml");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json results = read_json(dir / "results" / "results.json");
  const auto& outcomes = results["scenes"][0]["outcomes"];
  int network_rows = 0;
  double file_error = -1, builtin_error = -2;
  for (const auto& o : outcomes) {
    ASSERT_TRUE(o["ok"].get<bool>()) << o.dump();
    if (o["kind"] == "network") {
      ++network_rows;
      if (o["magnitude"].get<double>() == 5e-4) file_error = o["error"]["max_mm"].get<double>();
    }
    if (o["model"] == "surface_builtin" && o["magnitude"].get<double>() == 5e-4) {
      builtin_error = o["error"]["max_mm"].get<double>();
    }
  }
  EXPECT_EQ(network_rows, 2);
  // The committed file was exported from the built-in model beside it: the same error.
  EXPECT_NEAR(file_error, builtin_error, 1e-9 * builtin_error);
  const auto report = vv("report " + out + "/results.json");
  ASSERT_EQ(report.exit_code, 0) << report.output;
  const std::string md = read_text(dir / "results" / "report.md");
  EXPECT_NE(md.find("my_network"), std::string::npos);
}
