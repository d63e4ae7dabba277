// A user's own wire model through the exchange (verification/guidewire/wire_exchange.hpp): the
// case's manifest against $defs.wire_case of verification/exchange.schema.json, bad answers refused
// naming the file, and the example program (examples/external/wire_model.py) run end to end by a
// scene whose guidewire load has model = "external", against the continuum wire (Kirchhoff
// shooting: F·z²/EI = 0.470968 at L/z = 1.012498) and against the suite's own DER.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "../schema_check.hpp"
#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/guidewire/wire_exchange.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

const std::filesystem::path kExamples = VESSEL_EXAMPLES_DIR;

std::string wire_scene(const std::string& model_keys) {
  return "name = \"w\"\n[vessel]\nkind = \"straight\"\nmesh = \"structured\"\nlevel = 0\n"
         "[load]\ntype = \"guidewire\"\nE = 5.073e8\ndiameter = 0.356e-3\ninsertion = 20.25e-3\n"
         "tilt = 0.3\n" + model_keys + "\n[[models]]\nkind = \"fem\"\ndegree = 1\n";
}

std::string python_wire() {
  return "model = \"external\"\ncommand = [\"/usr/bin/python3\", \"" +
         (kExamples / "external" / "wire_model.py").string() + "\"]";
}

/// The scene parsed, then its wire solved (as the run path does).
Scene solved_scene(const std::string& text) {
  Scene s = parse_scene(text, "wire.toml");
  solve_guidewire_load(s);
  return s;
}

GuidewireSpec straight_spec() {
  GuidewireSpec w;
  w.young = 5.073e8;
  w.shear = w.young / 2.66;
  w.diameter = 0.356e-3;
  w.insertion = 20.25e-3;
  w.segments = 4;
  w.clamp_direction = Vec3(std::sin(0.3), 0.0, std::cos(0.3));
  return w;
}

}  // namespace

TEST(WireExchange, ManifestMeetsItsSchemaAndCarriesTheRodProblem) {
  test::TempDir dir;
  write_wire_case(dir.path(), "w", straight_spec(), 20.25e-3, {false, 0.0, 2.822e-3});
  const auto m = nlohmann::json::parse(test::read_text(dir / "manifest.json"));
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_EXCHANGE_SCHEMA));
  const auto problems = test::schema_problems(m, schema["$defs"]["wire_case"]);
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  const auto& rest = m["wire"]["rest_centreline_m"];
  ASSERT_EQ(rest.size(), 5u);
  EXPECT_EQ(rest[0], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_NEAR(rest[4][0].get<double>(), 20.25e-3 * std::sin(0.3), 1e-15);
  EXPECT_NEAR(rest[4][2].get<double>(), 20.25e-3 * std::cos(0.3), 1e-15);
  // EI = E π d⁴/64 = 5.073e8 · π · (0.356e-3)⁴ / 64 = 4.000e-7 N·m².
  EXPECT_NEAR(m["wire"]["bending_stiffness_Nm2"].get<double>(), 4.0e-7, 1e-10);
  EXPECT_EQ(m["wire"]["lumen"]["centreline_offset_m"], 2.822e-3);
}

TEST(WireExchange, BadAnswersAreRefusedNamingTheFile) {
  test::TempDir dir;
  const auto error = [&] {
    try {
      (void)read_wire_answer(dir.path(), 3);
    } catch (const WireModelError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error().find("centreline.csv: no answer"), std::string::npos);
  test::write_text(dir / "centreline.csv", "n,x,y,z\n");
  EXPECT_NE(error().find("centreline.csv:1: expected the header"), std::string::npos);
  test::write_text(dir / "centreline.csv", "node,x,y,z\n0,0,0,0\n2,0,0,2\n");
  EXPECT_NE(error().find("node 1 missing"), std::string::npos) << error();
  test::write_text(dir / "centreline.csv", "node,x,y,z\n0,0,0,0\n1,0,0,1\n2,0,nan,2\n");
  EXPECT_NE(error().find("centreline.csv:4"), std::string::npos) << error();
  test::write_text(dir / "centreline.csv", "node,x,y,z\n0,0,0,0\n1,0,0,1\n2,0,0,2\n");
  EXPECT_NE(error().find("contact.json: no answer"), std::string::npos) << error();
  test::write_text(dir / "contact.json", "{\"force_N\": -1, \"node\": 2}");
  EXPECT_NE(error().find("≥ 0"), std::string::npos) << error();
  test::write_text(dir / "contact.json", "{\"force_N\": 1e-3, \"node\": 3}");
  EXPECT_NE(error().find("node 3 out of range"), std::string::npos) << error();
  test::write_text(dir / "contact.json", "{\"force_N\": 1e-3, \"node\": 2}");
  const WireAnswer a = read_wire_answer(dir.path(), 3);
  EXPECT_EQ(a.node, 2);
  EXPECT_EQ(a.centreline[2], Vec3(0, 0, 2));
}

TEST(WireExchange, TheExampleProgramIsTheScenesWireAndMeetsTheContinuumWire) {
  // The scene's load runs the user's program: its force and contact become the patch.
  const Scene s = solved_scene(wire_scene(python_wire()));
  const GuidewireSolution& w = s.load.wire.value();
  const double EI = 5.073e8 * std::numbers::pi * std::pow(0.356e-3, 4) / 64.0;  // E π d⁴/64
  const double z = 20.25e-3 / 1.012498;
  std::printf("WIRE-EXTERNAL example: F %.9e N (continuum %.9e N), contact (%.6e, %.6e, %.6e)\n",
              w.force, 0.470968 * EI / (z * z), w.contact_point.x(), w.contact_point.y(),
              w.contact_point.z());
  EXPECT_NEAR(s.load.magnitudes.at(0) / (0.470968 * EI / (z * z)), 1.0, 2e-5);
  EXPECT_NEAR(w.contact_point.z(), z, 1e-7);
  EXPECT_NEAR(std::hypot(w.contact_point.x(), w.contact_point.y()), 3e-3 - 0.178e-3, 1e-9);
  EXPECT_NEAR(std::hypot(w.wall_point.x(), w.wall_point.y()), 3e-3, 1e-9);
  ASSERT_EQ(w.centreline.size(), 33u);
  EXPECT_EQ(w.centreline.front(), Vec3::Zero());
  // The suite's own DER on the same wire: within its discretisation error (4e-4 at N = 32).
  const Scene der = solved_scene(wire_scene(""));
  EXPECT_NEAR(w.force / der.load.wire.value().force, 1.0, 1e-3);
  // A failing program is the scene's error, naming the file and the program's output.
  try {
    (void)solved_scene(wire_scene("model = \"external\"\ncommand = [\"/bin/false\"]"));
    ADD_FAILURE() << "a failing wire program was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("wire.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exited with code 1"), std::string::npos) << e.what();
  }
  // command without model = "external" is refused.
  try {
    (void)parse_scene(wire_scene("command = [\"/bin/true\"]"), "wire.toml");
    ADD_FAILURE() << "command without model = external was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("load.command"), std::string::npos) << e.what();
  }
}

// Parsing a scene checks it and runs nothing: a wire program that would leave a marker file
// leaves none after parse_scene (what `vesselverify scene` calls), and does when the wire is
// solved on the run path (solve_guidewire_load).
TEST(WireExchange, ParsingASceneRunsNoProgram) {
  test::TempDir dir;
  const std::filesystem::path marker = dir / "ran";
  const std::string program =
      "model = \"external\"\ncommand = [\"/bin/sh\", \"-c\", \"touch " + marker.string() +
      "; exit 1\", \"sh\"]";
  Scene s = parse_scene(wire_scene(program), "wire.toml");
  EXPECT_FALSE(s.load.wire.has_value());
  EXPECT_TRUE(s.load.magnitudes.empty());
  EXPECT_FALSE(std::filesystem::exists(marker)) << "parsing the scene ran its wire program";
  EXPECT_THROW(solve_guidewire_load(s), InputError);  // the program exits 1
  EXPECT_TRUE(std::filesystem::exists(marker)) << "the run path did not run the wire program";
}
