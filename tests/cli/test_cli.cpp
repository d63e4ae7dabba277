// The vesselverify program end to end: help, a successful mesh run, and bad input giving a clear
// message and a non-zero exit with nothing half-written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>

#include "../test_helpers.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/msh_io.hpp"

using vessel::test::CommandResult;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::write_text;
using vessel::test::vv;

namespace {

bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}

}  // namespace

TEST(Cli, HelpListsTheSubcommandsAndExitsZero) {
  const auto r = vv("--help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "mesh")) << r.output;
  const auto m = vv("mesh --help");
  EXPECT_EQ(m.exit_code, 0) << m.output;
  EXPECT_TRUE(contains(m.output, "--level")) << m.output;
  EXPECT_TRUE(contains(m.output, "Examples")) << m.output;
}

TEST(Cli, NoOrUnknownSubcommandIsAUsageError) {
  EXPECT_NE(vv("").exit_code, 0);
  const auto r = vv("frobnicate");
  EXPECT_NE(r.exit_code, 0);
}

TEST(Cli, MeshWritesMshVtuStlAndJsonThatReadBack) {
  TempDir dir;
  const auto r = vv("mesh --no-cache -o " + (dir / "t.msh").string() + " --vtu " +
                    (dir / "t.vtu").string() + " --stl " + (dir / "inner.stl").string() +
                    " --stats-json " + (dir / "s.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "closed and consistently oriented")) << r.output;
  EXPECT_TRUE(contains(r.output, "inverted tets    0")) << r.output;
  const vessel::TetMesh mesh = vessel::read_msh(dir / "t.msh");
  EXPECT_NO_THROW(vessel::require_vessel_groups(mesh, "t.msh"));
  EXPECT_TRUE(std::filesystem::exists(dir / "t.vtu"));
  EXPECT_TRUE(std::filesystem::exists(dir / "inner.stl"));
  EXPECT_TRUE(contains(vessel::test::read_text(dir / "s.json"), "\"schema\": \"vesselverify.mesh_stats\""));
  // The written file reads back through --input and reports the same node count.
  const auto again = vv("mesh --input " + (dir / "t.msh").string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_TRUE(contains(again.output, std::to_string(mesh.nodes.size()) + " nodes")) << again.output;
}

TEST(Cli, CacheIsWrittenOnceAndHitAfterwards) {
  TempDir dir;
  const std::string args = "mesh --cache-dir " + (dir / "cache").string();
  const auto first = vv(args);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  EXPECT_TRUE(contains(first.output, "generated in")) << first.output;
  const auto second = vv(args);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_TRUE(contains(second.output, "read from cache")) << second.output;
}

TEST(Cli, GenerationIsDeterministicAcrossRunsSoTheCacheIsSound) {
  TempDir dir;
  for (const char* name : {"a.msh", "b.msh"}) {
    const auto r = vv("mesh --no-cache --vessel arch -o " + (dir / name).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  EXPECT_EQ(vessel::test::read_text(dir / "a.msh"), vessel::test::read_text(dir / "b.msh"));
}

TEST(Cli, NegativeRadiusIsAClearErrorAndNonZeroExit) {
  TempDir dir;
  const auto r = vv("mesh --no-cache --inner-radius -0.003 -o " + (dir / "x.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "inner_radius")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.msh"));
}

TEST(Cli, WallTooThickForTheArchIsAClearError) {
  const auto r = vv("mesh --no-cache --vessel arch --wall-thickness 0.013");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "too thick")) << r.output;
}

TEST(Cli, MissingTruncatedAndGrouplessFilesAreClearErrors) {
  TempDir dir;
  auto r = vv("mesh --input " + (dir / "missing.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "not found")) << r.output;

  vessel::write_msh(dir / "full.msh", vessel::generate_vessel_mesh(vessel::VesselParams{}));
  const std::string text = vessel::test::read_text(dir / "full.msh");
  write_text(dir / "cut.msh", text.substr(0, text.size() / 2));
  r = vv("mesh --input " + (dir / "cut.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "truncated")) << r.output;

  std::string renamed = text;
  renamed.replace(renamed.find("\"outer_wall\""), 12, "\"outside\"");
  write_text(dir / "groups.msh", renamed);
  r = vv("mesh --input " + (dir / "groups.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "missing physical group 'outer_wall'")) << r.output;
}

namespace {

/// The generated level-0 tube as msh 2.2 text with the first tet's element line edited by `edit`
/// (its tokens: tag type ntags tags... n1 n2 n3 n4); `line_no` gets that 1-based line number.
std::string tube_with_first_tet_edited(
    const vessel::test::TempDir& dir,
    const std::function<void(std::vector<std::string>&)>& edit, int& line_no) {
  vessel::write_msh(dir / "full22.msh", vessel::generate_vessel_mesh(vessel::VesselParams{}),
                    vessel::MshVersion::v22);
  std::istringstream in(vessel::test::read_text(dir / "full22.msh"));
  std::string out, line, nodes_text;
  bool in_elements = false, done = false;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line == "$Elements") in_elements = true;
    std::istringstream ls(line);
    std::vector<std::string> tok{std::istream_iterator<std::string>(ls), {}};
    if (in_elements && !done && tok.size() > 2 && tok[1] == "4") {
      edit(tok);
      line.clear();
      for (const auto& t : tok) line += (line.empty() ? "" : " ") + t;
      line_no = n;
      done = true;
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace

TEST(Cli, InvertedOrZeroVolumeTetsInAUserMeshAreRefusedWithExitOneAndNoOutput) {
  TempDir dir;
  int line_no = 0;
  std::string element_tag, repeated;
  // Swapping two nodes of one tet inverts it.
  write_text(dir / "inverted.msh",
             tube_with_first_tet_edited(
                 dir,
                 [&](std::vector<std::string>& t) {
                   element_tag = t[0];
                   std::swap(t[t.size() - 1], t[t.size() - 2]);
                 },
                 line_no));
  const std::string where =
      (dir / "inverted.msh").string() + ":" + std::to_string(line_no) + ": element " + element_tag;
  for (const std::string cmd : {"mesh --input " + (dir / "inverted.msh").string() + " -o " +
                                    (dir / "out.msh").string() + " --stats-json " +
                                    (dir / "out.json").string(),
                                "msm --model volume --input " + (dir / "inverted.msh").string() +
                                    " --json " + (dir / "out.json").string()}) {
    const auto r = vv(cmd);
    EXPECT_EQ(r.exit_code, 1) << cmd << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, where)) << where << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "is inverted: signed volume -")) << r.output;
    EXPECT_TRUE(contains(r.output, "expected a positive volume")) << r.output;
    EXPECT_TRUE(contains(r.output, "1 of ")) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.msh"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out.json"));
  }
  // Listing a node twice in a tet (coincident nodes) gives it zero volume.
  write_text(dir / "coincident.msh",
             tube_with_first_tet_edited(
                 dir,
                 [&](std::vector<std::string>& t) {
                   element_tag = t[0];
                   repeated = t[t.size() - 2];
                   t[t.size() - 1] = repeated;
                 },
                 line_no));
  const auto r = vv("mesh --input " + (dir / "coincident.msh").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, (dir / "coincident.msh").string() + ":" +
                                     std::to_string(line_no) + ": element " + element_tag))
      << r.output;
  EXPECT_TRUE(contains(r.output, "has zero volume: signed volume 0 m³")) << r.output;
  EXPECT_TRUE(contains(r.output, "it lists its node " + repeated + " twice")) << r.output;
}

TEST(Cli, UnwritableOutputIsAClearError) {
  const auto r = vv("mesh --no-cache -o /proc/vesselverify/x.msh");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "/proc/vesselverify")) << r.output;
}

TEST(Cli, SceneValidatesShippedScenesAndRefusesBadOnes) {
  const std::string scenes = std::string(VESSEL_SCENES_DIR);
  const auto ok = vv("scene " + scenes + "/contact_straight.toml " + scenes + "/pressure_lame.toml");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_TRUE(contains(ok.output, "scene 'pressure_lame' is valid")) << ok.output;
  TempDir dir;
  write_text(dir / "bad.toml", "name = \"b\"\n[vessel]\nkind = \"straight\"\nradius = 1\n");
  const auto bad = vv("scene " + (dir / "bad.toml").string());
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_TRUE(contains(bad.output, "bad.toml:4: key 'vessel.radius': unknown key")) << bad.output;
}

TEST(Cli, SceneSaysWhatAContactCouplingWouldSolveAndRefusesAnUnknownCoupling) {
  // The shipped straight guidewire scene is coupled by contact: `scene` names the contact solve a
  // run would add, and solves nothing (it returns at once). A coupling it does not know is refused
  // with the key and the values it takes.
  const auto ok = vv("scene " + std::string(VESSEL_SCENES_DIR) + "/guidewire_straight.toml");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_TRUE(contains(ok.output,
                       "coupling contact: `vesselverify run` would then press each "
                       "model's wall"))
      << ok.output;
  EXPECT_TRUE(contains(ok.output, "not solved now")) << ok.output;
  std::ifstream in(std::string(VESSEL_SCENES_DIR) + "/guidewire_straight.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find("coupling = \"contact\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::string("coupling = \"contact\"").size(), "coupling = \"mortar\"");
  TempDir dir;
  write_text(dir / "wire.toml", text);
  const auto bad = vv("scene " + (dir / "wire.toml").string());
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_TRUE(contains(bad.output, "coupling")) << bad.output;
  EXPECT_TRUE(contains(bad.output, "contact")) << bad.output;
  EXPECT_TRUE(contains(bad.output, "mortar")) << bad.output;
  // The contact mesh's size belongs to the contact coupling alone.
  text.replace(text.find("coupling = \"mortar\""), std::string("coupling = \"mortar\"").size(),
               "coupling = \"compliant\"\ncontact_fine_size = 0.1e-3");
  write_text(dir / "sized.toml", text);
  const auto sized = vv("scene " + (dir / "sized.toml").string());
  EXPECT_EQ(sized.exit_code, 1) << sized.output;
  EXPECT_TRUE(contains(sized.output, "contact_fine_size")) << sized.output;
  EXPECT_TRUE(contains(sized.output, "expected coupling = \"contact\"")) << sized.output;
  // So does its wall; with the contact coupling, a wall it does not know is refused with the
  // values it takes, and a neo-Hookean one is what `scene` says a run would solve.
  text.replace(text.find("contact_fine_size = 0.1e-3"),
               std::string("contact_fine_size = 0.1e-3").size(), "contact_wall = \"neo-hookean\"");
  write_text(dir / "walled.toml", text);
  const auto walled = vv("scene " + (dir / "walled.toml").string());
  EXPECT_EQ(walled.exit_code, 1) << walled.output;
  EXPECT_TRUE(contains(walled.output, "contact_wall")) << walled.output;
  text.replace(text.find("coupling = \"compliant\""),
               std::string("coupling = \"compliant\"").size(), "coupling = \"contact\"");
  write_text(dir / "neo.toml", text);
  const auto neo = vv("scene " + (dir / "neo.toml").string());
  EXPECT_EQ(neo.exit_code, 0) << neo.output;
  EXPECT_TRUE(contains(neo.output, "at finite strain: the neo-Hookean reference")) << neo.output;
  EXPECT_FALSE(contains(neo.output, "from P1's equilibrium")) << neo.output;
  // The finite-strain reference's P1 start: said by `scene`, refused beside a linear wall.
  const std::string neo_text = text;
  text.replace(text.find("contact_wall = \"neo-hookean\""),
               std::string("contact_wall = \"neo-hookean\"").size(),
               "contact_wall = \"neo-hookean\"\ncontact_p1_start = true");
  write_text(dir / "started.toml", text);
  const auto started = vv("scene " + (dir / "started.toml").string());
  EXPECT_EQ(started.exit_code, 0) << started.output;
  EXPECT_TRUE(contains(started.output, "the neo-Hookean reference from P1's equilibrium"))
      << started.output;
  text.replace(text.find("\"neo-hookean\""), std::string("\"neo-hookean\"").size(), "\"linear\"");
  write_text(dir / "linear_started.toml", text);
  const auto linear_started = vv("scene " + (dir / "linear_started.toml").string());
  EXPECT_EQ(linear_started.exit_code, 1) << linear_started.output;
  EXPECT_TRUE(contains(linear_started.output, "contact_p1_start")) << linear_started.output;
  EXPECT_TRUE(contains(linear_started.output, "expected contact_wall = \"neo-hookean\""))
      << linear_started.output;
  text = neo_text;
  text.replace(text.find("\"neo-hookean\""), std::string("\"neo-hookean\"").size(),
               "\"hyperelastic\"");
  write_text(dir / "unknown.toml", text);
  const auto unknown = vv("scene " + (dir / "unknown.toml").string());
  EXPECT_EQ(unknown.exit_code, 1) << unknown.output;
  EXPECT_TRUE(contains(unknown.output, "contact_wall")) << unknown.output;
  EXPECT_TRUE(contains(unknown.output, "neo-hookean")) << unknown.output;
}

TEST(Cli, RunPrintsTheGuidewiresSolvedForceAndWallPoint) {
  // The shipped straight guidewire scene with one model and one wire: its log names the force the
  // solved wire puts on the wall, which must be the continuum wire's against the rigid lumen,
  // F = 0.470968·EI/z² at z = 20 mm (Kirchhoff shooting; within DER's error at N = 32, ~5e-4).
  std::ifstream in(std::string(VESSEL_SCENES_DIR) + "/guidewire_straight.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = text.substr(0, text.find("[[models]]"));
  const auto sweep = text.find("stiffness_sweep");
  text.erase(sweep, text.find('\n', sweep) - sweep);
  const auto coupling = text.find("coupling = \"contact\"");  // the log line, not the contact solve
  text.replace(coupling, std::string("coupling = \"contact\"").size(), "coupling = \"compliant\"");
  text += "[[models]]\nname = \"fem_p1\"\nkind = \"fem\"\ndegree = 1\n";
  TempDir dir;
  write_text(dir / "wire.toml", text);
  const auto r = vv("run --quick --cache-dir " + (dir / "cache").string() + " --output-dir " +
                    (dir / "out").string() + " " + (dir / "wire.toml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string marker = "guidewire_straight: the guidewire pushes the wall with ";
  const auto at = r.output.find(marker);
  ASSERT_NE(at, std::string::npos) << r.output;
  double force_mN = 0.0, x = 0.0, y = 0.0, z = 0.0;
  ASSERT_EQ(std::sscanf(r.output.c_str() + at + marker.size(), "%lf mN at (%lf, %lf, %lf) mm",
                        &force_mN, &x, &y, &z),
            4)
      << r.output.substr(at, 120);
  const double closed_form_mN = 0.470968 * 4e-7 / (20e-3 * 20e-3) * 1e3;
  EXPECT_NEAR(force_mN / closed_form_mN - 1.0, 0.0, 1e-3);
  EXPECT_NEAR(std::hypot(x, y), 3.0, 1e-3);  // on the inner wall (radius 3 mm)
  EXPECT_NEAR(z, 20.0, 0.05);
}

// `contact --p1-start` starts a P2 finite-strain wall from P1's equilibrium: with a linear or a
// P1 wall there is nothing to start, and the flag is refused rather than ignored.
TEST(Cli, ContactRefusesAP1StartWithoutAP2FiniteStrainWall) {
  const std::string scene = std::string(VESSEL_SCENES_DIR) + "/guidewire_straight.toml";
  for (const std::string wall : {"--wall linear --degree 2", "--wall neo-hookean --degree 1"}) {
    const auto r = vv("contact " + scene + " --p1-start " + wall);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "--p1-start: expected --wall neo-hookean and --degree 2"))
        << r.output;
  }
}
