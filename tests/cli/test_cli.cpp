// The vesselverify program end to end: help, a successful mesh run, and bad input giving a clear
// message and a non-zero exit with nothing half-written.
#include <gtest/gtest.h>

#include <filesystem>

#include "../test_helpers.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/msh_io.hpp"

using vessel::test::CommandResult;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::write_text;

namespace {

CommandResult vv(const std::string& args) {
  return run_command(std::string(VESSELVERIFY_EXE) + " " + args);
}

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
