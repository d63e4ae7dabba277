// The reference job end to end: `mpirun -np 2 vesselverify reference` fills the FEM solution
// cache, a serial `run` on that cache restores every reference (no FEM solve of its own), and its
// results.json agrees with a plain serial run's (its own direct solves) to 1e-8 relative
// (scripts/compare_results.py), for P2 (ν = 0.3) and Taylor–Hood (ν = 0.5), on the short tube of
// tests/fixtures/short_contact.toml.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "../test_helpers.hpp"

using vessel::test::CommandResult;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::vv;

namespace {

CommandResult mpi_vv(int ranks, const std::string& args) {
  return run_command(std::string(VESSEL_MPIRUN) + " " + std::to_string(ranks) + " " +
                     VESSELVERIFY_EXE + " " + args);
}
bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}


/// (hits, misses) from the run's "FEM solution cache (...): H hits, M misses" line.
std::pair<int, int> fem_cache_counts(const std::string& output) {
  std::smatch m;
  const std::regex line(R"(FEM solution cache \([^)]*\): (\d+) hits, (\d+) misses)");
  if (!std::regex_search(output, m, line)) return {-1, -1};
  return {std::stoi(m[1]), std::stoi(m[2])};
}

}  // namespace

TEST(ReferenceJobCli, TwoRankJobThenSerialRunGivesTheSerialRunsResults) {
  TempDir dir;
  const std::filesystem::path scene = SHORT_SCENE;
  const std::string job_cache = " --cache-dir " + (dir / "job_cache").string() + " ";

  const auto job = mpi_vv(2, "reference" + job_cache + scene.string());
  ASSERT_EQ(job.exit_code, 0) << job.output;
  EXPECT_TRUE(contains(job.output, "reference job on 2 MPI rank(s)")) << job.output;
  EXPECT_TRUE(contains(job.output, "P2-P1 (Taylor-Hood)")) << job.output;
  // Two ν × (level 1, level 0); rank 0 alone prints.
  EXPECT_TRUE(contains(job.output, "references: 4 solved and stored, 0 already in the cache"))
      << job.output;
  const auto again = mpi_vv(2, "reference" + job_cache + scene.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(contains(again.output, "references: 0 solved and stored, 4 already in the cache"))
      << again.output;

  const auto after_job = vv("run --fields none" + job_cache + "--output-dir " +
                            (dir / "after_job").string() + " " + scene.string());
  ASSERT_EQ(after_job.exit_code, 0) << after_job.output;
  EXPECT_EQ(fem_cache_counts(after_job.output), std::make_pair(4, 0)) << after_job.output;

  const auto serial = vv("run --fields none --cache-dir " + (dir / "serial_cache").string() +
                         " --output-dir " + (dir / "serial").string() + " " + scene.string());
  ASSERT_EQ(serial.exit_code, 0) << serial.output;
  EXPECT_EQ(fem_cache_counts(serial.output), std::make_pair(0, 4)) << serial.output;

  const auto compare = run_command("/usr/bin/python3 " + COMPARE_RESULTS + " " +
                                   (dir / "serial" / "results.json").string() + " " +
                                   (dir / "after_job" / "results.json").string() +
                                   " --rtol 1e-8");
  EXPECT_EQ(compare.exit_code, 0) << compare.output;
}

TEST(ReferenceJobCli, RefusesToRunWithoutTheCache) {
  const std::filesystem::path scene = SHORT_SCENE;
  const auto r = vv("reference --no-cache " + scene.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--no-cache leaves nothing")) << r.output;
}
