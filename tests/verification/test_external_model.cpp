// Models outside the suite (verification/harness/external_model.hpp): the exchange written for a case
// against independent truth (the loads' totals: the contact force, the wall's weight ρ·π(b²−a²)L;
// the clamped ends' nodes), the answers read back and every refusal, the process runner's
// exit codes and time-out (the whole process group killed), and in the harness: every failure
// recorded with its reason while the other models still run, and a model that answers zero
// scoring the closed-form relative L2 error of 1.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <thread>

#include "../test_helpers.hpp"

#include "meshes/foundation/errors.hpp"
#include "meshes/vtu_io.hpp"
#include "verification/harness/external_model.hpp"
#include "verification/harness/harness.hpp"
#include "verification/harness/results.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}

/// A 10 mm straight tube, level 0, ends clamped, with `load` and `models` appended.
std::string scene_text(const std::string& load, const std::string& models) {
  return R"(name = "external_test"
[vessel]
kind = "straight"
length = 0.01
mesh = "structured"
level = 0
reference_level = 0
[material]
E = 14.24e3
nu = 0.45
density = 1060.0
[boundary]
inlet = "clamped"
outlet = "clamped"
)" + load + models;
}

const char* kContact = R"([load]
type = "contact"
magnitudes = [1.0e-4, 5.0e-4]
point = [3.0e-3, 0.0, 5.0e-3]
)";

const char* kGravity = R"([load]
type = "gravity"
magnitudes = [1.0]
)";

std::string external_model(const std::string& name, const std::string& command,
                           const std::string& extra = "") {
  return "[[models]]\nname = \"" + name + "\"\nkind = \"external\"\ncommand = " + command + "\n" +
         extra;
}

std::string expect_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

}  // namespace

// ---------------------------------------------------------------------------- scene keys

TEST(ExternalScene, ReadsCommandTimeoutNodesAndDynamics) {
  const Scene s = parse_scene(
      scene_text(kContact, external_model("mine", R"(["python3", "m.py", "--fast"])",
                                          "timeout_s = 12\nnodes = \"surface\"\nsurface = "
                                          "\"outer\"\ndt = 1e-4\nsteps = 50\n") +
                               "[[models]]\nname = \"elsewhere\"\nkind = \"displacements\"\n"
                               "file = \"answers/mine\"\n"),
      "/some/folder/scene.toml");
  ASSERT_EQ(s.models.size(), 2u);
  const ExternalSpec& e = s.models[0].external;
  EXPECT_EQ(s.models[0].kind, ModelKind::external);
  EXPECT_EQ(e.command, (std::vector<std::string>{"python3", "m.py", "--fast"}));
  EXPECT_EQ(e.timeout_s, 12.0);
  EXPECT_EQ(e.nodes, ExchangeNodes::surface);
  EXPECT_EQ(e.surface, msm::WallSurface::outer);
  EXPECT_EQ(e.dt, 1e-4);
  EXPECT_EQ(e.steps, 50);
  EXPECT_EQ(e.working_dir, std::filesystem::path("/some/folder"));
  EXPECT_EQ(s.models[1].kind, ModelKind::displacements);
  EXPECT_EQ(s.models[1].external.directory, std::filesystem::path("/some/folder/answers/mine"));
  EXPECT_EQ(s.models[1].external.nodes, ExchangeNodes::volume);
}

TEST(ExternalScene, RefusesBadKeysNamingThem) {
  const auto refused = [](const std::string& models) {
    return expect_error([&] { (void)parse_scene(scene_text(kContact, models), "s.toml"); });
  };
  EXPECT_TRUE(contains(refused("[[models]]\nkind = \"external\"\n"), "'models[0].command': missing"));
  EXPECT_TRUE(contains(refused(external_model("a", "[]")), "expected a non-empty array"));
  EXPECT_TRUE(contains(refused(external_model("a", "\"python3 m.py\"")), "'models[0].command'"));
  EXPECT_TRUE(contains(refused(external_model("a", "[\"x\"]", "timeout_s = 0\n")), "timeout_s"));
  EXPECT_TRUE(contains(refused(external_model("a", "[\"x\"]", "nodes = \"edges\"\n")),
                       "expected one of volume, surface"));
  EXPECT_TRUE(contains(refused(external_model("a", "[\"x\"]", "surface = \"outer\"\n")),
                       "expected it only with nodes = \"surface\""));
  EXPECT_TRUE(contains(refused(external_model("a", "[\"x\"]", "dt = 1e-3\n")),
                       "found dt without steps"));
  EXPECT_TRUE(contains(refused(external_model("a", "[\"x\"]", "stiffness = \"lloyd\"\n")),
                       "'models[0].stiffness': unknown key"));
  EXPECT_TRUE(contains(refused("[[models]]\nkind = \"displacements\"\n"), "'models[0].file': missing"));
}

// ---------------------------------------------------------------------------- the exchange

class Exchange : public ::testing::Test {
 protected:
  static Scene scene(const char* load, const std::string& extra = "") {
    return parse_scene(scene_text(load, external_model("m", "[\"true\"]", extra)), "s.toml");
  }
  test::TempDir dir;
};

TEST_F(Exchange, ContactLoadsSumToTheForceAndClampedEndsAreHeld) {
  const Scene s = scene(kContact);
  const TetMesh mesh = scene_mesh(s, 0, {});
  const ExchangeNetwork net = exchange_network(s, s.models[0], mesh, 0, 0.45);
  const ExchangeProblem p = exchange_problem(net, s, s.models[0], mesh, 0, 0.45, 5e-4, qoi_point(s));
  EXPECT_EQ(p.nodes.size(), mesh.nodes.size());  // volume: every node of the tet mesh
  Vec3 total = Vec3::Zero();
  for (const auto& f : p.loads) total += f;
  EXPECT_NEAR(total.norm(), 5e-4, 1e-12);  // the patch's total force is the load's magnitude
  // It pushes the inner wall outward at (a, 0, L/2): along +x.
  EXPECT_GT(total.x(), 0.999 * 5e-4);
  // Clamped ends: every component of the nodes on z = 0 and z = L held, no other.
  for (std::size_t i = 0; i < p.nodes.size(); ++i) {
    const bool end = std::abs(p.nodes[i].z()) < 1e-9 || std::abs(p.nodes[i].z() - 0.01) < 1e-9;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(p.fixed[i][c] != 0, end) << i;
  }
  EXPECT_LT((p.nodes[p.qoi_node] - Vec3(3e-3, 0, 5e-3)).norm(), 1.5e-3);  // a cell away at most

  const auto folder = write_exchange_case(dir.path(), p);
  EXPECT_EQ(folder.filename(), "nu0.45_L0_load0.0005");
  const VtuData d = read_vtu(folder / "problem.vtu");
  ASSERT_EQ(d.points.size(), p.nodes.size());
  EXPECT_EQ(d.types.front(), 10);
  EXPECT_EQ(d.connectivity.size(), 4 * mesh.tets.size());
  const VtuField* load = VtuData::find(d.point_fields, "load_N");
  ASSERT_NE(load, nullptr);
  double sum_x = 0.0;
  for (std::size_t i = 0; i < d.points.size(); ++i) sum_x += load->values[3 * i];
  EXPECT_NEAR(sum_x, total.x(), 1e-15);
  ASSERT_NE(VtuData::find(d.point_fields, "fixed"), nullptr);
  ASSERT_NE(VtuData::find(d.point_fields, "mass_kg"), nullptr);

  const auto m = nlohmann::json::parse(test::read_text(folder / "manifest.json"));
  EXPECT_EQ(m["schema"], "vesselverify.exchange");
  EXPECT_EQ(m["problem"]["nodes"], p.nodes.size());
  EXPECT_EQ(m["material"]["youngs_modulus_pa"], 14.24e3);
  EXPECT_EQ(m["analysis"]["type"], "static");
  // Every key the committed schema requires is written.
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_EXCHANGE_SCHEMA));
  for (const auto& key : schema["required"]) EXPECT_TRUE(m.contains(key)) << key;
  for (const auto& [section, spec] : schema["properties"].items()) {
    if (!spec.contains("required") || !m.contains(section)) continue;
    for (const auto& key : spec["required"]) EXPECT_TRUE(m[section].contains(key)) << section << "." << key;
  }
}

TEST_F(Exchange, GravityLoadsAreTheWallsWeight) {
  const Scene s = scene(kGravity, "dt = 1e-4\nsteps = 20\n");
  const TetMesh mesh = scene_mesh(s, 0, {});
  const ExchangeNetwork net = exchange_network(s, s.models[0], mesh, 0, 0.45);
  const ExchangeProblem p = exchange_problem(net, s, s.models[0], mesh, 0, 0.45, 1.0, qoi_point(s));
  Vec3 total = Vec3::Zero();
  double mass = 0.0;
  for (std::size_t i = 0; i < p.nodes.size(); ++i) {
    total += p.loads[i];
    mass += p.masses[i];
  }
  // ρ·π(b² − a²)·L, the faceted wall's volume within 2 % (24 facets: 1 − sin(2π/24)/(2π/24)).
  const double exact = 1060.0 * std::numbers::pi * (4e-3 * 4e-3 - 3e-3 * 3e-3) * 0.01;
  EXPECT_NEAR(mass, exact, 0.02 * exact);
  EXPECT_NEAR(total.y(), -9.81 * mass, 1e-12);  // one g along −y on the same masses
  EXPECT_NEAR(std::hypot(total.x(), total.z()), 0.0, 1e-15);
  const auto folder = write_exchange_case(dir.path(), p);
  const auto m = nlohmann::json::parse(test::read_text(folder / "manifest.json"));
  EXPECT_EQ(m["analysis"]["type"], "dynamic");
  EXPECT_EQ(m["analysis"]["steps"], 20);
  EXPECT_NEAR(m["analysis"]["duration_s"].get<double>(), 2e-3, 1e-15);
}

TEST_F(Exchange, SurfaceNodesAreTheWallsTriangles) {
  const Scene s = scene(kContact, "nodes = \"surface\"\nsurface = \"inner\"\n");
  const TetMesh mesh = scene_mesh(s, 0, {});
  const ExchangeNetwork net = exchange_network(s, s.models[0], mesh, 0, 0.45);
  const ExchangeProblem p = exchange_problem(net, s, s.models[0], mesh, 0, 0.45, 1e-4, qoi_point(s));
  EXPECT_EQ(p.cells.vtk_type, 5);
  for (const auto& x : p.nodes) EXPECT_NEAR(std::hypot(x.x(), x.y()), 3e-3, 1e-9);
  Vec3 total = Vec3::Zero();
  for (const auto& f : p.loads) total += f;
  EXPECT_NEAR(total.norm(), 1e-4, 1e-12);  // the patch lies on the inner wall: all of it kept
}

TEST_F(Exchange, WritingACaseRemovesAStaleAnswer) {
  const Scene s = scene(kContact);
  const TetMesh mesh = scene_mesh(s, 0, {});
  const ExchangeNetwork net = exchange_network(s, s.models[0], mesh, 0, 0.45);
  const ExchangeProblem p = exchange_problem(net, s, s.models[0], mesh, 0, 0.45, 1e-4, qoi_point(s));
  const auto folder = dir.path() / p.id;
  std::filesystem::create_directories(folder);
  test::write_text(folder / "displacements.csv", "node,ux,uy,uz\n");
  test::write_text(folder / "timing.json", "{}");
  write_exchange_case(dir.path(), p);
  EXPECT_FALSE(std::filesystem::exists(folder / "displacements.csv"));
  EXPECT_FALSE(std::filesystem::exists(folder / "timing.json"));
}

// ---------------------------------------------------------------------------- answers

class Answers : public ::testing::Test {
 protected:
  std::string refused(const std::string& csv, std::size_t nodes = 2) {
    test::write_text(dir / "displacements.csv", csv);
    return expect_error([&] { (void)read_external_answer(dir.path(), nodes); });
  }
  test::TempDir dir;
};

TEST_F(Answers, ReadsCsvInAnyOrderAndTiming) {
  test::write_text(dir / "displacements.csv", "node,ux,uy,uz\n1, 4, 5, 6\n0,1e-3,2,3\n");
  test::write_text(dir / "timing.json", R"({"setup_seconds": 0.5, "solve_seconds": 0.25})");
  const ExternalAnswer a = read_external_answer(dir.path(), 2);
  EXPECT_EQ(a.u[0], Vec3(1e-3, 2, 3));
  EXPECT_EQ(a.u[1], Vec3(4, 5, 6));
  EXPECT_EQ(a.setup_seconds, 0.5);
  EXPECT_EQ(a.solve_seconds, 0.25);
}

TEST_F(Answers, ReadsVtuAnswer) {
  write_vtu(dir / "displacements.vtu", {Vec3(0, 0, 0), Vec3(1, 0, 0)}, VtuCells{3, 2, {0, 1}},
            {VtuField{"displacement", 3, {1, 2, 3, 4, 5, 6}}});
  const ExternalAnswer a = read_external_answer(dir.path(), 2);
  EXPECT_EQ(a.u[1], Vec3(4, 5, 6));
  EXPECT_FALSE(a.solve_seconds.has_value());
  EXPECT_TRUE(contains(expect_error([&] { (void)read_external_answer(dir.path(), 3); }),
                       "2 points, expected 3"));
}

TEST_F(Answers, RefusesEveryBadAnswerWithTheReason) {
  EXPECT_TRUE(contains(expect_error([&] { (void)read_external_answer(dir.path(), 2); }),
                       "no answer; expected displacements.csv or displacements.vtu"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n"), "1 nodes, expected 2"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n1,0,0,0\n2,0,0,0\n"), "3 nodes, expected 2"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n1,nan,0,0\n"), "node 1 ux is not finite (nan)"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n1,0,inf,0\n"), "is not finite"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n0,0,0,0\n"), "node 0 given twice"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n7,0,0,0\n"), "expected an index in [0, 1]"));
  EXPECT_TRUE(contains(refused("id,x,y,z\n0,0,0,0\n1,0,0,0\n"), ":1: found header \"id,x,y,z\""));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0\n"), ":2: found 3 fields, expected 4"));
  EXPECT_TRUE(contains(refused("node,ux,uy,uz\n0,0,0,0\n1,0,abc,0\n"), "found \"abc\", expected a number"));
  EXPECT_TRUE(contains(refused(""), "empty; expected the header"));
  test::write_text(dir / "displacements.csv", "node,ux,uy,uz\n0,0,0,0\n1,0,0,0\n");
  test::write_text(dir / "timing.json", R"({"solve_seconds": -1})");
  EXPECT_TRUE(contains(expect_error([&] { (void)read_external_answer(dir.path(), 2); }),
                       "solve_seconds: found -1, expected a time >= 0 s"));
  std::filesystem::remove(dir / "displacements.csv");
  std::filesystem::remove(dir / "timing.json");
  write_vtu(dir / "displacements.vtu", {Vec3(0, 0, 0), Vec3(1, 0, 0)}, VtuCells{3, 2, {0, 1}},
            {VtuField{"displacement", 3, {1, 2, 3, 4, NAN, 6}}});
  EXPECT_TRUE(contains(expect_error([&] { (void)read_external_answer(dir.path(), 2); }),
                       "point 1 displacement uy is not finite"));
}

TEST(VtuRead, ReadsWhatWriteVtuWritesAndRefusesBinary) {
  test::TempDir dir;
  const std::vector<Vec3> pts{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1.5)};
  write_vtu(dir / "t.vtu", pts, VtuCells{10, 4, {0, 1, 2, 3}}, {VtuField{"s", 1, {1, 2, 3, 4}}},
            {VtuField{"c", 2, {7, 8}}});
  const VtuData d = read_vtu(dir / "t.vtu");
  EXPECT_EQ(d.points, pts);
  EXPECT_EQ(d.connectivity, (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(d.offsets, (std::vector<std::size_t>{4}));
  EXPECT_EQ(VtuData::find(d.point_fields, "s")->values, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_EQ(VtuData::find(d.cell_fields, "c")->values, (std::vector<double>{7, 8}));
  std::string text = test::read_text(dir / "t.vtu");
  text.replace(text.find("format=\"ascii\""), 14, "format=\"binary\"");
  test::write_text(dir / "b.vtu", text);
  EXPECT_TRUE(contains(expect_error([&] { (void)read_vtu(dir / "b.vtu"); }), "expected format=\"ascii\""));
  EXPECT_TRUE(contains(expect_error([&] { (void)read_vtu(dir / "none.vtu"); }), "none.vtu: file not found"));
}

// ---------------------------------------------------------------------------- processes

TEST(RunProcess, ExitCodesLogAndEnvironment) {
  test::TempDir dir;
  const auto r = run_process({"sh", "-c", "echo \"out $MY_VAR\"; pwd; echo err >&2; exit 3"},
                             dir.path(), {{"MY_VAR", "here"}}, 10.0, dir / "log");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_FALSE(r.timed_out);
  const std::string log = test::read_text(dir / "log");
  EXPECT_TRUE(contains(log, "out here"));
  EXPECT_TRUE(contains(log, "err"));
  EXPECT_TRUE(contains(log, std::filesystem::canonical(dir.path()).string()));
  const auto missing = run_process({"no-such-program-vv"}, dir.path(), {}, 10.0, dir / "log2");
  EXPECT_EQ(missing.exit_code, 127);
  EXPECT_TRUE(contains(test::read_text(dir / "log2"), "cannot execute 'no-such-program-vv'"));
}

TEST(RunProcess, TimeOutKillsTheWholeProcessGroup) {
  test::TempDir dir;
  // The command starts a grandchild and waits: both must be gone after the time-out.
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_process({"sh", "-c", "sleep 30 & echo $! > grandchild.pid; wait"},
                             dir.path(), {}, 0.5, dir / "log");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.signal, SIGKILL);
  EXPECT_GE(seconds, 0.5);
  EXPECT_LT(seconds, 5.0);
  const int grandchild = std::stoi(test::read_text(dir / "grandchild.pid"));
  bool gone = false;
  for (int k = 0; k < 100 && !gone; ++k) {  // init reaps the orphan shortly after the kill
    gone = kill(grandchild, 0) != 0 ||
           contains(test::read_text("/proc/" + std::to_string(grandchild) + "/stat"), ") Z ");
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(gone) << "grandchild " << grandchild << " still running";
}

// ---------------------------------------------------------------------------- in the harness

TEST(ExternalHarness, FailuresAreRecordedWithReasonsAndTheRestRuns) {
  test::TempDir dir;
  // A model that answers zero everywhere (its error is the reference itself: relative L2 = 1),
  // one per failure, and a built-in model last: every one still runs.
  test::write_text(dir / "zero.py", R"(import json, os, sys
m = json.load(open(sys.argv[1]))
d = os.path.dirname(sys.argv[1])
with open(os.path.join(d, "displacements.csv"), "w") as f:
    f.write("node,ux,uy,uz\n")
    for i in range(m["problem"]["nodes"]):
        f.write("%d,0,0,0\n" % i)
)");
  test::write_text(dir / "nan.py", R"(import json, os, sys
m = json.load(open(sys.argv[1]))
with open(os.path.join(os.path.dirname(sys.argv[1]), "displacements.csv"), "w") as f:
    f.write("node,ux,uy,uz\n")
    for i in range(m["problem"]["nodes"]):
        f.write("%d,%s,0,0\n" % (i, "nan" if i == 5 else "0"))
)");
  test::write_text(dir / "short.py", R"(import os, sys
with open(os.path.join(os.path.dirname(sys.argv[1]), "displacements.csv"), "w") as f:
    f.write("node,ux,uy,uz\n0,0,0,0\n1,0,0,0\n")
)");
  const std::string models =
      external_model("zero", R"(["/usr/bin/python3", "zero.py"])") +
      external_model("exits_3", R"(["sh", "-c", "echo broken solver >&2; exit 3"])") +
      external_model("hangs", R"(["sh", "-c", "sleep 30"])", "timeout_s = 0.5\n") +
      external_model("writes_nothing", R"(["true"])") +
      external_model("writes_nan", R"(["/usr/bin/python3", "nan.py"])") +
      external_model("two_nodes", R"(["/usr/bin/python3", "short.py"])") +
      "[[models]]\nname = \"volume\"\nkind = \"volume_msm\"\nsolver = \"linear\"\n";
  test::write_text(dir / "scene.toml", scene_text(kContact, models));
  const Scene s = read_scene(dir / "scene.toml");
  HarnessOptions o;
  o.exchange_dir = dir / "exchange";
  const SceneResult r = run_scene(s, o);
  ASSERT_EQ(r.outcomes.size(), 14u);
  std::map<std::string, std::vector<const ModelOutcome*>> by_model;
  for (const auto& out : r.outcomes) by_model[out.model].push_back(&out);
  for (const ModelOutcome* z : by_model["zero"]) {
    ASSERT_TRUE(z->ok) << z->failure;
    EXPECT_NEAR(z->error.relative_l2, 1.0, 1e-12);  // ‖0 − u_ref‖/‖u_ref‖
    EXPECT_NEAR(z->error.max_mm, z->quantities.field_mm, 1e-12);
    EXPECT_NEAR(z->qoi_displacement_mm, 0.0, 0.0);
    EXPECT_GT(z->qoi_reference_mm, 0.0);
    EXPECT_EQ(z->timing_source, "process");
    EXPECT_GT(z->solve_seconds, 0.0);
    EXPECT_EQ(z->kind, "external");
  }
  const auto failed_with = [&](const std::string& model, const std::string& reason) {
    for (const ModelOutcome* out : by_model[model]) {
      EXPECT_FALSE(out->ok) << model;
      EXPECT_TRUE(contains(out->failure, reason)) << model << ": " << out->failure;
    }
  };
  failed_with("exits_3", "exited with code 3; its output ended: broken solver");
  failed_with("hangs", "timed out after 0.5 s (timeout_s)");
  failed_with("writes_nothing", "no answer; expected displacements.csv or displacements.vtu");
  failed_with("writes_nan", "node 5 ux is not finite (nan)");
  failed_with("two_nodes", "2 nodes, expected");
  for (const ModelOutcome* v : by_model["volume"]) EXPECT_TRUE(v->ok) << v->failure;
  // Written to results like any outcome: the failure's reason, the timing's source.
  write_results_json(dir / "results.json", {r}, "test");
  const auto j = nlohmann::json::parse(test::read_text(dir / "results.json"));
  int failures = 0;
  for (const auto& out : j["scenes"][0]["outcomes"]) {
    if (out["ok"] == false) {
      ++failures;
      EXPECT_TRUE(out.contains("failure"));
    }
    if (out["model"] == "zero") EXPECT_EQ(out["timing_source"], "process");
    if (out["model"] == "volume") EXPECT_FALSE(out.contains("timing_source"));
  }
  EXPECT_EQ(failures, 10);
}

TEST(ExternalHarness, DynamicModelsHistoryIsComparedWithTheFemTransient) {
  test::TempDir dir;
  // At rest for the whole run: its history's error is the FEM transient's own |u(t)| at the QoI,
  // and its final state's error the static reference's.
  test::write_text(dir / "still.py", R"(import json, os, sys
m = json.load(open(sys.argv[1]))
d = os.path.dirname(sys.argv[1])
assert m["analysis"]["type"] == "dynamic"
with open(os.path.join(d, "displacements.csv"), "w") as f:
    f.write("node,ux,uy,uz\n")
    for i in range(m["problem"]["nodes"]):
        f.write("%d,0,0,0\n" % i)
with open(os.path.join(d, "history.csv"), "w") as f:
    f.write("time_s,ux,uy,uz\n")
    for k in range(m["analysis"]["steps"] + 1):
        f.write("%r,0,0,0\n" % (k * m["analysis"]["dt_s"]))
)");
  const char* load = R"([load]
type = "contact"
magnitudes = [1.0e-4]
point = [3.0e-3, 0.0, 5.0e-3]
)";
  test::write_text(dir / "scene.toml",
                   scene_text(load, external_model("still", R"(["/usr/bin/python3", "still.py"])",
                                                   "dt = 1e-4\nsteps = 20\n")));
  HarnessOptions o;
  o.exchange_dir = dir / "exchange";
  const SceneResult r = run_scene(read_scene(dir / "scene.toml"), o);
  ASSERT_EQ(r.outcomes.size(), 1u);
  const ModelOutcome& out = r.outcomes[0];
  ASSERT_TRUE(out.ok) << out.failure;
  EXPECT_EQ(out.history.steps, 20);
  EXPECT_NEAR(out.history.simulated_s, 2e-3, 1e-15);
  ASSERT_EQ(out.history.time_s.size(), 21u);
  double peak = 0.0;
  for (const double v : out.history.reference_mm) peak = std::max(peak, v);
  EXPECT_GT(peak, 0.0);  // the step load moves the wall within 2 ms
  EXPECT_DOUBLE_EQ(out.history.max_error_mm, peak);
  EXPECT_NEAR(out.error.relative_l2, 1.0, 1e-12);
  EXPECT_GE(out.quantities.contact_point_mm, peak);  // the larger of history and final state
}
