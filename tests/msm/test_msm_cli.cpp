// `vesselverify msm` end to end: both models on the default vessel under a contact patch,
// statically and dynamically; bad input and divergence give a clear message, exit 1, no file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "../test_helpers.hpp"

using vessel::test::CommandResult;
using vessel::test::read_text;
using vessel::test::run_command;
using vessel::test::TempDir;

namespace {

class MsmCli : public ::testing::Test {
 protected:
  TempDir dir;
  CommandResult vv(const std::string& args) {
    return run_command(std::string(VESSELVERIFY_EXE) + " msm --cache-dir " +
                       (dir / "cache").string() + " " + args);
  }
};

bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}

}  // namespace

TEST_F(MsmCli, SurfaceAndVolumeModelsSolveStaticallyAndWriteJson) {
  const auto s = vv("--json " + (dir / "surface.json").string());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  EXPECT_TRUE(contains(s.output, "springs: structural")) << s.output;
  EXPECT_TRUE(contains(s.output, "contact-point displacement")) << s.output;
  const auto j = nlohmann::json::parse(read_text(dir / "surface.json"));
  EXPECT_EQ(j["model"], "surface");
  EXPECT_GT(j["springs"]["structural"].get<int>(), 1000);
  EXPECT_GT(j["springs"]["bend"].get<int>(), 1000);
  EXPECT_GT(j["contact_displacement_along_load_mm"].get<double>(), 0.0);

  const auto v = vv("--model volume --stiffness seed001 --mass seed001 --json " +
                    (dir / "volume.json").string());
  ASSERT_EQ(v.exit_code, 0) << v.output;
  // The hybrid volume model: its springs and its volume term, named in the topology.
  const auto h = vv("--model volume --volume-term --poisson-ratio 0.45");
  ASSERT_EQ(h.exit_code, 0) << h.output;
  EXPECT_TRUE(contains(h.output, "volume term")) << h.output;
  // The homogenised rule for its (E_s, κ), named in the topology.
  const auto hh =
      vv("--model volume --volume-term --volume-moduli homogenised --poisson-ratio 0.3");
  ASSERT_EQ(hh.exit_code, 0) << hh.output;
  EXPECT_TRUE(contains(hh.output, "homogenised on this mesh")) << hh.output;
  // The discrete-shells surface model: hinges named in the topology, no bend springs left.
  const auto b =
      vv("--bending discrete-shells --poisson-ratio 0.45 --json " + (dir / "shell.json").string());
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_TRUE(contains(b.output, "discrete-shell hinges")) << b.output;
  const auto jb = nlohmann::json::parse(read_text(dir / "shell.json"));
  EXPECT_EQ(jb["springs"].value("bend", 0), 0);
  EXPECT_GT(jb["contact_displacement_along_load_mm"].get<double>(), 0.0);
  const auto jv = nlohmann::json::parse(read_text(dir / "volume.json"));
  EXPECT_GT(jv["springs"]["volume"].get<int>(), 5000);
  EXPECT_GT(jv["contact_displacement_along_load_mm"].get<double>(), 0.0);
}

TEST_F(MsmCli, StructuredGridHasSeed000FamiliesAndEveryDynamicSolverRuns) {
  // Level 0 structured: 24 × 22 cells (structural 24·23 + 24·22, shear 2·24·22, bend 24·23 +
  // 24·21); the coarse grid needs a patch wider than its 0.8 mm × 1.8 mm cells.
  const auto g = vv("--structured --surface mid --solver linear --patch-radius 1.5e-3");
  ASSERT_EQ(g.exit_code, 0) << g.output;
  EXPECT_TRUE(contains(g.output, "structural 1080 shear 1056 bend 1056")) << g.output;
  // The integrators' first steps from rest under the step load, closed forms with a0 = M⁻¹F
  // (the springs exert nothing at rest): explicit Euler x1 = x0, x2 = x0 + h²a0; symplectic
  // Euler x1 = x0 + h²a0; Verlet x1 = x0 + h²a0/2. The contact point's displacement is linear
  // in x − x0, so it follows the same ratios.
  const auto displacement = [&](const std::string& args, const std::string& name) {
    const auto json = dir / (name + ".json");
    const auto r = vv(args + " --dt 1e-6 --json " + json.string());
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "per step")) << r.output;
    if (r.exit_code != 0) return std::nan("");
    return nlohmann::json::parse(read_text(json))["contact_displacement_along_load_mm"].get<double>();
  };
  const std::string grid = "--structured --patch-radius 1.5e-3 --solver ";
  const double ee1 = displacement(grid + "explicit-euler --steps 1", "ee1");
  const double ee2 = displacement(grid + "explicit-euler --steps 2", "ee2");
  const double se1 = displacement(grid + "symplectic-euler --steps 1", "se1");
  const double vv1 = displacement(grid + "verlet --steps 1", "vv1");
  EXPECT_GT(se1, 0.0);
  EXPECT_EQ(ee1, 0.0);
  EXPECT_NEAR(ee2, se1, 1e-9 * se1);  // measured: equal to the last digit
  EXPECT_NEAR(vv1, 0.5 * se1, 1e-9 * se1);
  const auto pbd = vv(grid + "pbd --steps 20");
  EXPECT_EQ(pbd.exit_code, 0) << pbd.output;
  EXPECT_TRUE(contains(pbd.output, "per step")) << pbd.output;
  // The volume model: Verlet's first step half symplectic Euler's again; implicit Euler by its
  // direct solve and by conjugate gradients (to relative residual 1e-8) take the same steps, on
  // the current and on the rest matrix.
  const double vol_se = displacement("--model volume --solver symplectic-euler --steps 1", "vse");
  const double vol_vv = displacement("--model volume --solver verlet --steps 1", "vvv");
  EXPECT_GT(vol_se, 0.0);
  EXPECT_NEAR(vol_vv, 0.5 * vol_se, 1e-9 * vol_se);
  const auto rest = vv("--model volume --solver implicit-euler-rest --steps 5 --dt 1e-6");
  EXPECT_EQ(rest.exit_code, 0) << rest.output;
  EXPECT_TRUE(contains(rest.output, "set-up (assembly and factorisation at rest)")) << rest.output;
  const std::string cg = " --steps 5 --cg-tolerance 1e-8 --cg-preconditioner jacobi";
  std::map<std::string, double> direct_of;
  for (const std::string solver : {"implicit-euler", "implicit-euler-rest"}) {
    const double direct = displacement("--model volume --steps 5 --solver " + solver, solver);
    direct_of[solver] = direct;
    const auto pcg = dir / (solver + "-pcg.json");
    const auto r = vv("--model volume --dt 1e-6 --solver " + solver + "-pcg" + cg + " --json " +
                      pcg.string());
    EXPECT_EQ(r.exit_code, 0) << solver << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "conjugate gradients to relative residual 1e-08")) << r.output;
    const double iterative =
        nlohmann::json::parse(read_text(pcg))["contact_displacement_along_load_mm"].get<double>();
    EXPECT_GT(direct, 0.0) << solver;
    EXPECT_NEAR(iterative, direct, 1e-8 * direct) << solver;  // measured 2.7e-10
  }
  // Five steps of 1 µs from rest move the wall by ~3e-8 mm: the current matrix is the rest one
  // to ~1e-9 (measured 1.9e-9 apart).
  EXPECT_NEAR(direct_of["implicit-euler-rest"], direct_of["implicit-euler"],
              1e-7 * direct_of["implicit-euler"]);
}

TEST_F(MsmCli, BadInputNamesTheParameterAndExitsOne) {
  const std::pair<std::string, std::string> cases[] = {
      {"--solver verlet --dt -1", "dt"},
      {"--youngs-modulus -5", "youngs_modulus"},
      {"--poisson-ratio 0.7", "poisson_ratio"},
      {"--stiffness magic", "stiffness rule"},
      {"--mass heavy", "mass rule"},
      {"--model volume --solver pbd", "surface model"},
      {"--model volume --volume-term --poisson-ratio 0.5", "κ = λ − μ is infinite"},
      {"--model volume --volume-term --stiffness lloyd --poisson-ratio 0.45", "van-gelder"},
      {"--model volume --volume-term --volume-moduli homogenised --poisson-ratio 0.5",
       "κ is infinite"},
      {"--model volume --volume-moduli homogenised", "volume_term = true"},
      {"--model volume --volume-term --volume-moduli voigt", "'golec' or 'homogenised'"},
      {"--model surface --volume-term", "volume model"},
      {"--model volume --bending discrete-shells", "surface model"},
      {"--structured --topology grid --bending discrete-shells", "grid"},
      {"--bending discrete-shells --solver pbd", "PBD"},
      {"--bending discrete-shells --solver local-global", "local-global"},
  };
  for (const auto& [args, what] : cases) {
    const auto r = vv(args + " --json " + (dir / "bad.json").string());
    EXPECT_EQ(r.exit_code, 1) << args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, what)) << args << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.json"));
  }
}

TEST_F(MsmCli, DivergenceStopsWithStepNodeEnergyAndWritesNothing) {
  const auto r = vv("--model volume --solver explicit-euler --dt 1e-3 --steps 500 --json " +
                    (dir / "diverged.json").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "diverged at step")) << r.output;
  EXPECT_TRUE(contains(r.output, "node")) << r.output;
  EXPECT_TRUE(contains(r.output, "energy")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "diverged.json"));
}

TEST_F(MsmCli, PressureAndGravityFromTheSharedLoadDefinitionsSuperpose) {
  // The linearised model is linear in its load: at the contact point, what pressure and gravity
  // add to the contact force together is the sum of what each adds alone, and twice the pressure
  // adds twice as much. A load dropped, doubled or applied with the wrong sign when the loads are
  // combined fails this.
  const auto along = [&](const std::string& load, const std::string& name) {
    const auto json = dir / (name + ".json");
    const auto r = vv("--model volume --force 1e-4 --solver linear " + load + " --json " +
                      json.string());
    EXPECT_EQ(r.exit_code, 0) << load << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "linearised model")) << r.output;
    if (r.exit_code != 0) return std::nan("");
    return nlohmann::json::parse(read_text(json))["contact_displacement_along_load_mm"]
        .get<double>();
  };
  const double contact = along("", "c");
  const double pressure = along("--pressure 5", "p") - contact;
  const double gravity = along("--gravity", "g") - contact;
  const double both = along("--pressure 5 --gravity", "pg") - contact;
  const double doubled = along("--pressure 10", "p2") - contact;
  const double scale = std::abs(contact);
  EXPECT_GT(std::abs(pressure), 1e-3 * scale);
  EXPECT_GT(std::abs(gravity), 1e-3 * scale);
  EXPECT_NEAR(both, pressure + gravity, 1e-9 * scale);
  EXPECT_NEAR(doubled, 2.0 * pressure, 1e-9 * scale);
  const auto bad = vv("--pressure nan");
  EXPECT_NE(bad.exit_code, 0) << bad.output;
}

TEST_F(MsmCli, StaticNewtonMeetsTheLinearisedModelAtASmallLoad) {
  // Two solvers of the same model: at 0.1 µN the wall moves ~1e-4 of its thickness, so Newton's
  // equilibrium equals the linearised model's up to the geometric nonlinearity, which is O(F)
  // (measured on the surface model: 3.5 %, 0.38 % and 0.039 % at 10, 1 and 0.1 µN). So small a
  // load puts Newton's last steps below the energy's round-off, where the line search must judge
  // them by the residual (on this mesh the volume model stalled at 6e-13 N when it did not).
  for (const std::string model : {"surface", "volume"}) {
    const auto solve = [&](const std::string& solver) {
      const auto json = dir / (model + "-" + solver + ".json");
      const auto r = vv("--model " + model + " --force 1e-7 --solver " + solver +
                        " --json " + json.string());
      EXPECT_EQ(r.exit_code, 0) << model << " " << solver << "\n" << r.output;
      if (r.exit_code != 0) return std::nan("");
      return nlohmann::json::parse(read_text(json))["contact_displacement_along_load_mm"]
          .get<double>();
    };
    const double newton = solve("static");
    const double linear = solve("linear");
    EXPECT_GT(linear, 0.0) << model;
    EXPECT_NEAR(newton, linear, 1e-3 * linear) << model;
  }
}

TEST_F(MsmCli, InputMshAndStlGiveTheSameModelAsTheGeneratedMesh) {
  // The generated level-0 vessel written once as .msh and its inner wall as STL: the surface
  // model read back from either (fixed ends: the groups, or the STL's open boundary) has the
  // generated model's springs and equilibrium. STL stores float32, hence the 1e-5 tolerance.
  const auto m = run_command(std::string(VESSELVERIFY_EXE) + " mesh --cache-dir " +
                             (dir / "cache").string() + " -o " + (dir / "v.msh").string() +
                             " --stl " + (dir / "inner.stl").string() + " --stl-group inner_wall");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  auto solve = [&](const std::string& args, const std::string& name) {
    const auto r = vv(args + " --json " + (dir / name).string());
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
    return nlohmann::json::parse(read_text(dir / name));
  };
  const std::string stl_in = "--input " + (dir / "inner.stl").string();
  const std::string stl_fix = stl_in + " --contact-point 0.003 0 0.02 --fix-boundary";
  // Static Newton on the STL surface and on the generated wall.
  const auto gen = solve("", "gen.json");
  const auto stl = solve(stl_fix, "stl.json");
  EXPECT_EQ(stl["springs"], gen["springs"]);
  EXPECT_NEAR(stl["contact_displacement_mm"].get<double>(),
              gen["contact_displacement_mm"].get<double>(),
              1e-5 * gen["contact_displacement_mm"].get<double>());
  EXPECT_EQ(stl["input"], (dir / "inner.stl").string());
  // The .msh file (both models, linearised: cheap and deterministic) equals the generated mesh.
  for (const std::string model : {"surface", "volume"}) {
    const std::string args = "--solver linear --model " + model;
    const auto a = solve(args, "a.json");
    const auto b = solve(args + " --input " + (dir / "v.msh").string(), "b.json");
    EXPECT_EQ(b["springs"], a["springs"]) << model;
    EXPECT_DOUBLE_EQ(b["contact_displacement_mm"].get<double>(),
                     a["contact_displacement_mm"].get<double>())
        << model;
  }
  // z-planes fix the same ends as the STL's boundary: the tube spans z = 0 … 40 mm.
  const auto boundary = solve(stl_fix + " --solver linear", "boundary.json");
  const auto planes = solve(stl_in +
                                " --solver linear --contact-point 0.003 0 0.02 --fix-below-z 1e-9 "
                                "--fix-above-z 0.039999999",
                            "planes.json");
  EXPECT_DOUBLE_EQ(planes["contact_displacement_mm"].get<double>(),
                   boundary["contact_displacement_mm"].get<double>());

  const std::pair<std::string, std::string> bad[] = {
      {stl_in + " --model volume --contact-point 0.003 0 0.02 --fix-boundary", "needs tetrahedra"},
      {stl_in + " --fix-boundary", "--contact-point"},
      {stl_in + " --contact-point 0.003 0 0.02", "--fix-below-z"},
      {stl_in + " --contact-point 0.003 0 0.02 --fixed inlet", "physical groups"},
      {stl_in + " --contact-point 0.003 0 0.02 --fix-below-z -1", "fixes no node"},
      {stl_in + " --contact-point 0.003 0 0.02 --fix-below-z 5", "every node"},
      {stl_in + " --contact-point 0.003 0 0.02 --fix-boundary --surface mid", "--surface mid"},
      {"--input " + (dir / "v.obj").string(), ".obj"},
      {"--input " + (dir / "missing.msh").string(), "missing.msh"},
      {"--input " + (dir / "v.msh").string() + " --structured", "grid topology"},
  };
  for (const auto& [args, what] : bad) {
    const auto r = vv(args + " --json " + (dir / "bad.json").string());
    EXPECT_EQ(r.exit_code, 1) << args << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, what)) << args << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.json"));
  }
}

TEST_F(MsmCli, LocalGlobalSolversRunAndRefuseBilinearSprings) {
  const auto r = vv("--model volume --solver local-global-euler --dt 1e-3 --steps 5 "
                    "--lg-iterations 3 --json " + (dir / "lg.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "3 local-global iterations per step")) << r.output;
  const auto j = nlohmann::json::parse(read_text(dir / "lg.json"));
  EXPECT_EQ(j["solver"]["numeric_factorisations"], 1) << j.dump();
  const auto bilinear =
      vv("--model volume --solver local-global --bilinear-threshold 0.01 --json " +
         (dir / "bad.json").string());
  EXPECT_EQ(bilinear.exit_code, 1) << bilinear.output;
  EXPECT_TRUE(contains(bilinear.output, "solver local-global")) << bilinear.output;
  EXPECT_TRUE(contains(bilinear.output, "bilinear")) << bilinear.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.json"));
}

TEST_F(MsmCli, LocalGlobalStaticsReachNewtonsEquilibrium) {
  // Liu et al.'s local-global iterations and Newton minimise the same Hooke-spring energy: their
  // equilibria agree to the local-global gradient tolerance (1e-8 of the load).
  const auto solve = [&](const std::string& solver) {
    const auto json = dir / (solver + ".json");
    const auto r = vv("--model volume --solver " + solver + " --json " + json.string());
    EXPECT_EQ(r.exit_code, 0) << solver << "\n" << r.output;
    if (r.exit_code != 0) return std::nan("");
    return nlohmann::json::parse(read_text(json))["contact_displacement_along_load_mm"]
        .get<double>();
  };
  const double newton = solve("static");
  const double local_global = solve("local-global");
  EXPECT_GT(newton, 0.0);
  EXPECT_NEAR(local_global, newton, 1e-6 * newton);
}
