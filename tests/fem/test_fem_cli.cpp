// `vesselverify fem` end to end: a pressure run against Lamé, a contact run writing JSON and VTU,
// and bad input giving a clear message, exit code 1 and no output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "../test_helpers.hpp"
#include "meshes/vtu_io.hpp"

using vessel::read_vtu;
using vessel::Vec3;
using vessel::VtuData;
using vessel::VtuField;
using vessel::test::CommandResult;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::vv;

namespace {

bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}
// A short structured tube keeps each run well under a second.
const std::string kTube = "--structured --length 0.002 --no-cache ";

}  // namespace

TEST(FemCli, HelpHasExamples) {
  const auto r = vv("fem --help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "Examples")) << r.output;
  EXPECT_TRUE(contains(r.output, "--solver")) << r.output;
}

TEST(FemCli, PressureRunComparesWithLameAndBalancesReactions) {
  TempDir dir;
  const auto r = vv("fem " + kTube + "--degree 2 --json " + (dir / "f.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "DoFs")) << r.output;
  EXPECT_TRUE(contains(r.output, "Lamé closed form")) << r.output;
  // One problem: its direct solver gets every core.
  const std::string threads = std::to_string(std::max(1U, std::thread::hardware_concurrency()));
  EXPECT_TRUE(contains(r.output, "solving on " + threads + " thread(s)")) << r.output;
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "f.json"));
  EXPECT_EQ(j["schema"], "vesselverify.fem");
  EXPECT_EQ(j["element"], "P2");
  EXPECT_LT(j["lame_relative_l2_error"].get<double>(), 0.02);  // level 0, P2: about 1 %
  EXPECT_GT(j["dofs"].get<int>(), 0);
}

TEST(FemCli, MatrixFreeSolverGivesTheDirectSolversAnswer) {
  // The same P2 problem by CHOLMOD and by CG on the matrix-free operator (p-multigrid): strain
  // energy and the contact point's displacement within the CG tolerance's reach.
  TempDir dir;
  const std::string run = "fem " + kTube +
                          "--degree 2 --load contact --force 1e-4 "
                          "--contact-point 0.003 0 0.001 --bc clamped --tolerance 1e-12 ";
  const auto d = vv(run + "--solver direct --json " + (dir / "d.json").string());
  const auto m = vv(run + "--solver matrix-free --json " + (dir / "m.json").string());
  ASSERT_EQ(d.exit_code, 0) << d.output;
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_TRUE(contains(m.output, "matrix-free")) << m.output;
  EXPECT_TRUE(contains(m.output, "CG iterations (p-multigrid P2->P1, ML-CG on P1)")) << m.output;
  const auto jd = nlohmann::json::parse(vessel::test::read_text(dir / "d.json"));
  const auto jm = nlohmann::json::parse(vessel::test::read_text(dir / "m.json"));
  EXPECT_EQ(jm["solver"], "matrix-free");
  EXPECT_GT(jm["cg_iterations"].get<int>(), 0);
  EXPECT_NEAR(jm["strain_energy_mJ"].get<double>() / jd["strain_energy_mJ"].get<double>(), 1.0,
              1e-9);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(jm["contact"]["displacement_mm"][c].get<double>(),
                jd["contact"]["displacement_mm"][c].get<double>(),
                1e-9 * std::abs(jd["contact"]["displacement_mm"][0].get<double>()));
  }
}

TEST(FemCli, ContactRunWritesVtuAndJson) {
  TempDir dir;
  const auto r =
      vv("fem " + kTube + "--load contact --force 1e-4 --contact-point 0.003 0 0.001 --vtu " +
         (dir / "c.vtu").string() + " --json " + (dir / "c.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "c.vtu"));
  const std::string vtu = vessel::test::read_text(dir / "c.vtu");
  EXPECT_TRUE(contains(vtu, "displacement") && contains(vtu, "stress")) << vtu.substr(0, 400);
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "c.json"));
  // The two clamped ends hold the whole 0.1 mN push in +x: their reactions sum to −0.1 mN.
  const auto& rx = j["reactions"];
  ASSERT_EQ(rx.size(), 2u);
  EXPECT_NEAR(rx[0]["force_mN"][0].get<double>() + rx[1]["force_mN"][0].get<double>(), -0.1, 1e-9);
  // The patch pushes the inner wall outward at +x.
  EXPECT_GT(j["contact"]["displacement_mm"][0].get<double>(), 0.0);
}

TEST(FemCli, BadInputExitsOneWithAClearMessageAndWritesNothing) {
  TempDir dir;
  const std::string json = " --json " + (dir / "x.json").string();
  auto r = vv("fem " + kTube + "--nu 0.6" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "Poisson")) << r.output;
  r = vv("fem " + kTube + "--nu 0.5 --formulation displacement" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "mixed formulation")) << r.output;
  r = vv("fem " + kTube + "--E -1" + json);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "Young's modulus")) << r.output;
  r = vv("fem " + kTube + "--load contact --contact-point 0 0 0.001" + json);  // in the lumen
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "off the wall")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}

TEST(FemCli, ModesArePrintedAndWritten) {
  TempDir dir;
  const auto modes = [&](const std::string& material, const std::string& name) {
    const auto json = dir / name;
    const auto r = vv("fem " + kTube + "--bc clamped-inlet --modes 4 " + material + " --json " +
                      json.string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "f (Hz):")) << r.output;
    return nlohmann::json::parse(vessel::test::read_text(json))["modal"]["frequencies_hz"];
  };
  const auto f = modes("", "m.json");
  ASSERT_EQ(f.size(), 4u);
  EXPECT_GT(f[0].get<double>(), 0.0);
  // K ∝ E and M ∝ ρ, so f ∝ √(E/ρ): 4 E doubles every frequency, 4 ρ halves it.
  const auto stiff = modes("--E 56.96e3", "stiff.json");
  const auto heavy = modes("--density 4240", "heavy.json");
  ASSERT_EQ(stiff.size(), 4u);
  ASSERT_EQ(heavy.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const double fi = f[i].get<double>();
    EXPECT_NEAR(stiff[i].get<double>(), 2.0 * fi, 1e-9 * fi) << i;  // measured 2e-15
    EXPECT_NEAR(heavy[i].get<double>(), 0.5 * fi, 1e-9 * fi) << i;
    if (i > 0) EXPECT_GE(fi, f[i - 1].get<double>());
  }
}

TEST(FemCli, TransientPrintsTheHistoryAndWritesTheCsv) {
  TempDir dir;
  const auto csv = dir / "h.csv";
  const std::string load = "--load contact --contact-point 0.003 0 0.001 ";
  // Mass damping 1e4 /s: the step response has settled after 300 steps (60 ms).
  const auto r =
      vv("fem " + kTube + load +
         "--transient --dt 2e-4 --steps 300 --mass-damping 1e4 --history-csv " + csv.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "Newmark")) << r.output;
  EXPECT_TRUE(contains(r.output, "ms/step")) << r.output;
  const std::string text = vessel::test::read_text(csv);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 302);  // header + steps + 1 rows
  EXPECT_EQ(text.rfind("t_s,ux_mm", 0), 0u) << text.substr(0, 80);
  // Heavily damped, the step response settles on the static solve of the same load (measured
  // agreement: the CSV's 12 digits).
  const auto s = vv("fem " + kTube + load + "--json " + (dir / "s.json").string());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "s.json"));
  const double ux_static = j["contact"]["displacement_mm"][0].get<double>();
  const std::string last = text.substr(text.rfind('\n', text.size() - 2) + 1);
  const double ux_end = std::stod(last.substr(last.find(',') + 1));
  std::cout << "  transient end ux " << ux_end << " mm, static " << ux_static << " mm\n";
  EXPECT_NEAR(ux_end, ux_static, 1e-8 * std::abs(ux_static));
}

TEST(FemCli, TransientRefusesABadTimeStepAndWritesNothing) {
  TempDir dir;
  const auto csv = dir / "h.csv";
  const auto r = vv("fem " + kTube + "--load contact --contact-point 0.003 0 0.001 --transient " +
                    "--dt -1 --history-csv " + csv.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "time step")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(csv));
}

TEST(FemCli, RichardsonSolvesOneLevelCoarserAndExtrapolates) {
  TempDir dir;
  const auto r = vv("fem " + kTube + "--level 1 --richardson --json " + (dir / "r.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "GCI")) << r.output;
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "r.json"))["richardson"];
  EXPECT_EQ(j["coarse_level"], 0);
  // u_ext = u1 + (u1 − u2)/(2^p − 1) with p = 2 (Richardson 1911), recomputed by hand.
  const double u1 = j["u_fine_mm"], u2 = j["u_coarse_mm"];
  EXPECT_NEAR(j["extrapolated_mm"].get<double>(), u1 + (u1 - u2) / 3.0, 1e-12 * std::abs(u1));
  EXPECT_NEAR(j["error_fine_mm"].get<double>(), std::abs(u1 - u2) / 3.0, 1e-12 * std::abs(u1));
}

TEST(FemCli, RichardsonNeedsALevelToCoarsen) {
  const auto r = vv("fem " + kTube + "--level 0 --richardson");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--level >= 1")) << r.output;
}

namespace {

/// The number printed right after `label` in `text` (NaN if absent).
double number_after(const std::string& text, const std::string& label) {
  const auto at = text.find(label);
  if (at == std::string::npos) return std::nan("");
  return std::stod(text.substr(at + label.size()));
}

}  // namespace

TEST(FemCli, FiniteStrainReferenceAgreesWithTheLinearOneAtASmallLoad) {
  // 0.1 mN on the short tube: strain well below 1 %, so the neo-Hookean answer along the patch
  // normal is within a few per cent of the linear reference's (O(load) relative difference).
  const auto r = vv("fem " + kTube +
                    "--load contact --force 1e-4 --contact-point 0.003 0 0.001 --reference "
                    "finite-strain");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "load factor reached 1")) << r.output;
  EXPECT_TRUE(contains(r.output, "Newton iterations")) << r.output;
  const double finite = number_after(r.output, "along the patch normal ");
  const double linear = number_after(r.output, "linear reference at the same load ");
  ASSERT_GT(linear, 0.0) << r.output;
  EXPECT_NEAR(finite, linear, 0.03 * linear) << r.output;
  EXPECT_NE(finite, linear) << r.output;
}

TEST(FemCli, FiniteStrainWritesItsDisplacementFieldAsVtu) {
  // At 0.1 mN the neo-Hookean field is within a few per cent of the linear reference's, which
  // the linear solver writes to its own VTU: the largest nodal difference against the largest
  // displacement.
  TempDir dir;
  const std::string load = "--load contact --force 1e-4 --contact-point 0.003 0 0.001 ";
  const auto f = vv("fem " + kTube + load + "--reference finite-strain --vtu " +
                    (dir / "finite.vtu").string());
  ASSERT_EQ(f.exit_code, 0) << f.output;
  const auto l = vv("fem " + kTube + load + "--vtu " + (dir / "linear.vtu").string());
  ASSERT_EQ(l.exit_code, 0) << l.output;
  const VtuData finite = read_vtu(dir / "finite.vtu"), linear = read_vtu(dir / "linear.vtu");
  const VtuField* uf = VtuData::find(finite.point_fields, "displacement");
  const VtuField* ul = VtuData::find(linear.point_fields, "displacement");
  ASSERT_TRUE(uf && ul);
  ASSERT_EQ(uf->values.size(), ul->values.size());
  double largest = 0.0, difference = 0.0;
  for (std::size_t i = 0; i < ul->values.size(); i += 3) {
    const Vec3 a{uf->values[i], uf->values[i + 1], uf->values[i + 2]};
    const Vec3 b{ul->values[i], ul->values[i + 1], ul->values[i + 2]};
    largest = std::max(largest, b.norm());
    difference = std::max(difference, (a - b).norm());
  }
  ASSERT_GT(largest, 0.0);
  EXPECT_LT(difference, 0.03 * largest);
  EXPECT_GT(difference, 0.0);  // a different solver, not the linear field copied
}

TEST(FemCli, FiniteStrainJsonGivesTheLoadReachedAndTheContactDisplacement) {
  TempDir dir;
  const auto r = vv("fem " + kTube +
                    "--load contact --force 1e-4 --contact-point 0.003 0 0.001 "
                    "--reference finite-strain --json " +
                    (dir / "f.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "f.json"));
  EXPECT_EQ(j["schema"], "vesselverify.fem_finite_strain");
  EXPECT_EQ(j["load_factor"], 1.0);
  EXPECT_TRUE(j["completed"].get<bool>());
  // The contact point's displacement along the patch normal, as the command printed it (mm).
  double along = 0.0;
  for (int c = 0; c < 3; ++c) {
    along += j["contact"]["displacement_mm"][c].get<double>() *
             j["contact"]["inward_normal"][c].get<double>();
  }
  EXPECT_NEAR(along, number_after(r.output, "along the patch normal "), 1e-5 * std::abs(along));
  // And, at 0.1 mN, within 3 % of the linear reference's (another solver; printed beside it).
  const double linear = number_after(r.output, "linear reference at the same load ");
  EXPECT_NEAR(along, linear, 0.03 * std::abs(linear));
  EXPECT_GE(j["max_displacement_mm"].get<double>(), std::abs(along));
}

TEST(FemCli, FiniteStrainUnderPressureGivesLamesDisplacementAtTheQoiPoint) {
  // 10 Pa on the short tube with roller ends: strains near 0.1 %, so the neo-Hookean radial
  // displacement at the QoI point (on the inner wall) is Lamé's plane-strain closed form within
  // P2's discretisation error, and the linear reference's within O(strain).
  TempDir dir;
  const auto r = vv("fem " + kTube + "--degree 2 --reference finite-strain --json " +
                    (dir / "f.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "u at QoI point")) << r.output;
  const auto j = nlohmann::json::parse(vessel::test::read_text(dir / "f.json"));
  ASSERT_TRUE(j.contains("qoi")) << j.dump();
  const auto& q = j["qoi"];
  const double E = j["material"]["E_Pa"], nu = j["material"]["nu"];
  const double a = 3e-3, b = 4e-3, p = 10.0;  // the command's default tube and pressure
  const double x = q["point_mm"][0].get<double>() * 1e-3, y = q["point_mm"][1].get<double>() * 1e-3;
  const double radius = std::hypot(x, y);
  EXPECT_NEAR(radius, a, 1e-6);
  const double lame_mm = 1e3 * p * a * a / (E * (b * b - a * a)) *
                         ((1 + nu) * (1 - 2 * nu) * radius + (1 + nu) * b * b / radius);
  const double along = q["along_mm"];
  EXPECT_NEAR(along, lame_mm, 0.02 * lame_mm);
  EXPECT_NEAR(along, q["linear_along_mm"].get<double>(), 0.005 * lame_mm);
  EXPECT_NEAR(along, number_after(r.output, "along the radial direction "), 1e-5 * lame_mm);
}

TEST(FemCli, FiniteStrainUnderGravityPrintsTheQoiPointBesideTheLinearReference) {
  const auto r = vv("fem " + kTube + "--load gravity --reference finite-strain");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double finite = number_after(r.output, "along the radial direction ");
  const double linear = number_after(r.output, "linear reference at the same load ");
  ASSERT_TRUE(std::isfinite(finite) && std::isfinite(linear)) << r.output;
  ASSERT_NE(linear, 0.0) << r.output;
  EXPECT_NEAR(finite, linear, 0.03 * std::abs(linear)) << r.output;  // 1 g: strains far below 1 %
}

TEST(FemCli, FiniteStrainRefusesOptionsOfTheLinearReferenceOnly) {
  const auto r = vv("fem " + kTube + "--reference finite-strain --modes 3");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--modes is available with the linear reference only"))
      << r.output;
  const auto d = vv("fem " + kTube + "--dead-pressure");
  EXPECT_EQ(d.exit_code, 1) << d.output;
  EXPECT_TRUE(contains(d.output, "--dead-pressure is for --reference finite-strain")) << d.output;
}
