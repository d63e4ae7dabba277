// `mpirun -np 2 vesselverify fem --distributed` end to end: its JSON against the serial program's
// (CHOLMOD), one printed report (rank 0 only), and input it cannot run refused with exit code 1.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

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
std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}
double rel(const nlohmann::json& a, const nlohmann::json& b) {
  double d = 0.0, m = 0.0;
  for (int c = 0; c < 3; ++c) {
    d = std::max(d, std::abs(a[c].get<double>() - b[c].get<double>()));
    m = std::max(m, std::abs(b[c].get<double>()));
  }
  return d / m;
}
// |applied load + Σ reactions| / |applied load| from a --json document: the balance itself, not
// the printed label.
double imbalance(const nlohmann::json& j) {
  double sum[3] = {0, 0, 0}, applied = 0.0;
  for (int c = 0; c < 3; ++c) {
    sum[c] = j["applied_load_mN"][c].get<double>();
    applied += sum[c] * sum[c];
  }
  for (const auto& g : j["reactions"]) {
    for (int c = 0; c < 3; ++c) sum[c] += g["force_mN"][c].get<double>();
  }
  return std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]) / std::sqrt(applied);
}
// A short structured tube: a second or two per run.
const std::string kTube = "--structured --length 0.004 --no-cache ";

}  // namespace

TEST(FemDistributedCli, TwoRanksMatchTheSerialDirectSolveAndPrintOnce) {
  TempDir dir;
  const std::string load = "--degree 2 --load contact --contact-radius 1e-3 --tolerance 1e-13 ";
  const auto serial =
      vv("fem " + kTube + load + "--solver direct --json " + (dir / "serial.json").string());
  ASSERT_EQ(serial.exit_code, 0) << serial.output;
  const auto mpi =
      mpi_vv(2, "fem " + kTube + load + "--distributed --json " + (dir / "mpi.json").string());
  ASSERT_EQ(mpi.exit_code, 0) << mpi.output;
  EXPECT_EQ(count(mpi.output, "element P2:"), 1u) << mpi.output;  // rank 0 alone prints
  EXPECT_TRUE(contains(mpi.output, "2 MPI rank(s)")) << mpi.output;
  const auto s = nlohmann::json::parse(vessel::test::read_text(dir / "serial.json"));
  const auto m = nlohmann::json::parse(vessel::test::read_text(dir / "mpi.json"));
  EXPECT_EQ(m["distributed"]["mpi_ranks"], 2);
  // Neither rank held the whole mesh: each only its own tets and their ghost layer.
  const auto& dist = m["distributed"];
  ASSERT_EQ(dist["local_tets_per_rank"].size(), 2u);
  const int tets = dist["tets_per_rank"][0].get<int>() + dist["tets_per_rank"][1].get<int>();
  for (int r = 0; r < 2; ++r) {
    EXPECT_LT(dist["local_tets_per_rank"][r].get<int>(), tets) << "rank " << r;
    EXPECT_GT(dist["peak_memory_mb_per_rank"][r].get<double>(), 0.0) << "rank " << r;
  }
  EXPECT_EQ(m["solver"], "cg-amg");
  EXPECT_EQ(m["dofs"], s["dofs"]);
  EXPECT_GT(m["cg_iterations"].get<int>(), 0);
  EXPECT_LT(rel(m["contact"]["displacement_mm"], s["contact"]["displacement_mm"]), 1e-8);
  EXPECT_LT(rel(m["applied_load_mN"], s["applied_load_mN"]), 1e-12);
  EXPECT_NEAR(m["strain_energy_mJ"].get<double>(), s["strain_energy_mJ"].get<double>(),
              1e-8 * s["strain_energy_mJ"].get<double>());
  EXPECT_NEAR(m["max_displacement_mm"].get<double>(), s["max_displacement_mm"].get<double>(),
              1e-8 * s["max_displacement_mm"].get<double>());
  ASSERT_EQ(m["reactions"].size(), 2u);
  for (int g = 0; g < 2; ++g) {
    // Against the total push (0.1 mN), to 1e-8.
    const auto& a = m["reactions"][g]["force_mN"];
    const auto& b = s["reactions"][g]["force_mN"];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c].get<double>(), b[c].get<double>(), 1e-9);
  }
}

TEST(FemDistributedCli, TaylorHoodOnTwoRanksMatchesTheSerialDirectSolve) {
  // ν = 0.5: the mixed system, UMFPACK serially, FGMRES with the block preconditioner on 2 ranks.
  TempDir dir;
  const std::string load = "--nu 0.5 --load contact --contact-radius 1e-3 --tolerance 1e-13 ";
  const auto serial =
      vv("fem " + kTube + load + "--solver direct --json " + (dir / "serial.json").string());
  ASSERT_EQ(serial.exit_code, 0) << serial.output;
  const auto mpi =
      mpi_vv(2, "fem " + kTube + load + "--distributed --json " + (dir / "mpi.json").string());
  ASSERT_EQ(mpi.exit_code, 0) << mpi.output;
  const auto s = nlohmann::json::parse(vessel::test::read_text(dir / "serial.json"));
  const auto m = nlohmann::json::parse(vessel::test::read_text(dir / "mpi.json"));
  EXPECT_EQ(m["distributed"]["mpi_ranks"], 2);
  EXPECT_EQ(m["solver"], "gmres-block");
  EXPECT_EQ(m["dofs"], s["dofs"]);
  EXPECT_LT(rel(m["contact"]["displacement_mm"], s["contact"]["displacement_mm"]), 1e-8);
  EXPECT_NEAR(m["strain_energy_mJ"].get<double>(), s["strain_energy_mJ"].get<double>(),
              1e-8 * s["strain_energy_mJ"].get<double>());
  EXPECT_LT(imbalance(s), 1e-9);
  EXPECT_LT(imbalance(m), 1e-9);
}

TEST(FemDistributedCli, RunsWithoutMpirunOnOneRankAndItsReactionsBalanceTheLoad) {
  TempDir dir;
  // A contact load (a non-zero net force, unlike pressure) held by the clamped ends.
  const auto r = vv("fem " + kTube + "--load contact --contact-radius 1e-3 --tolerance 1e-12 " +
                    "--distributed --json " + (dir / "one.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "one.json"));
  EXPECT_EQ(j["distributed"]["mpi_ranks"], 1);
  EXPECT_LT(imbalance(j), 1e-9) << r.output;
}

TEST(FemDistributedCli, RefusesWhatIsNotDistributedAndWritesNothing) {
  TempDir dir;
  const std::string json = " --json " + (dir / "x.json").string();
  // On one rank without mpirun (the same validation runs on every rank): exit code 1.
  auto r = vv("fem " + kTube + "--distributed --degree 2 --curved" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "curved")) << r.output;
  r = vv("fem " + kTube + "--distributed --solver direct" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "serial only")) << r.output;
  r = vv("fem " + kTube + "--distributed --modes 3" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--modes is serial only")) << r.output;
  r = vv("fem " + kTube + "--distributed --transient" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--transient is serial only")) << r.output;
  r = vv("fem " + kTube + "--distributed --load contact --contact-point 0 0 0.002" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "off the wall")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}
