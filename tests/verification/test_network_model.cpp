// A spring network from a file (kind = "network") against the built-in model it was exported
// from: the same problem (loads, masses, held dofs), the same solution to the bit, and the same
// error against the reference in one harness run. Independent truth here is the built-in model's
// own problem and solution, built by the other path (its rules on the mesh, not the file).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/formats/network_file.hpp"
#include "msm/solvers/solve.hpp"
#include "verification/harness/harness.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

/// Level-0 straight tube, contact at mid-length, clamped ends; the built-in volume model and the
/// network file exported from it (the path is filled in by the test).
std::string scene_text(const std::string& file, const std::string& extra = "") {
  return R"(name = "network_round_trip"
[vessel]
kind = "straight"
mesh = "structured"
level = 0
reference_level = 0
[material]
E = 14.24e3
nu = 0.3
[boundary]
inlet = "clamped"
outlet = "clamped"
[load]
type = "contact"
magnitudes = [1.0e-4, 5.0e-4]
point = [3.0e-3, 0.0, 20.0e-3]
patch_radius = 1.0e-3
[[models]]
name = "volume"
kind = "volume_msm"
stiffness = "seed001"
mass = "seed001"
solver = "static"
[[models]]
name = "volume_from_file"
kind = "network"
file = ")" + file + "\"\n" + extra;
}

/// The built-in model of `scene`'s first model exported to `path` (following inlet and outlet).
msm::BuiltNetwork export_builtin(const Scene& scene, const TetMesh& mesh,
                                 const std::filesystem::path& path) {
  msm::BuiltNetwork built = scene_network(scene, scene.models[0], mesh, scene.vessel, 0.3);
  msm::NetworkSupports supports;
  supports.follow_groups = {"inlet", "outlet"};
  msm::write_network_file(path, msm::network_file_of(built, supports, "test export"));
  return built;
}

struct Solved {
  msm::Problem problem;
  Eigen::VectorXd x;
};

Solved solve_static(const Scene& scene, const msm::BuiltNetwork& built, const TetMesh& mesh,
                    double force, const msm::SolverSpec& solver) {
  static std::vector<std::unique_ptr<msm::MassSpringModel>> models;  // outlive the problems
  models.push_back(msm::make_model(built, 0.0));
  Solved s{msm_problem(scene, *models.back(), built, mesh, force), {}};
  s.x = msm::solve(s.problem, solver, &built.network).x;
  return s;
}

}  // namespace

TEST(NetworkModel, AnExportedModelReadBackHasTheSameProblemAndSolutionToTheBit) {
  test::TempDir dir;
  for (const char* name : {"volume.json", "volume.vtu"}) {
    SCOPED_TRACE(name);
    const Scene scene = parse_scene(scene_text((dir / name).string()), "net_test.toml");
    const TetMesh mesh = scene_mesh(scene, 0, {});
    const msm::BuiltNetwork builtin = export_builtin(scene, mesh, dir / name);
    const msm::BuiltNetwork from_file = scene_network(scene, scene.models[1], mesh, scene.vessel, 0.3);
    ASSERT_TRUE(from_file.file_supports.has_value());
    // Every node of a volume network is a mesh node: the file's nodes find them again.
    EXPECT_EQ(from_file.network.source_node, builtin.network.source_node);
    const msm::SolverSpec solver = msm::parse_solver("static");
    const Solved a = solve_static(scene, builtin, mesh, 5e-4, solver);
    const Solved b = solve_static(scene, from_file, mesh, 5e-4, solver);
    EXPECT_EQ(a.problem.fixed, b.problem.fixed);
    EXPECT_GT(std::count(a.problem.fixed.begin(), a.problem.fixed.end(), 1), 0);
    EXPECT_EQ(a.problem.mass, b.problem.mass);
    EXPECT_EQ(a.problem.external_force, b.problem.external_force);
    ASSERT_EQ(a.x.size(), b.x.size());
    EXPECT_GT((a.x - a.problem.rest).norm(), 1e-6);  // it moved
    EXPECT_LE((a.x - b.x).lpNorm<Eigen::Infinity>(), 1e-12 * a.x.lpNorm<Eigen::Infinity>());
  }
}

TEST(NetworkModel, ABilinearDampedSurfaceModelRoundTripsThroughADynamicSolve) {
  // The mid-surface (its nodes are not the inner-wall nodes its loads come from), seed 001's bilinear law
  // with its threshold crossed, axial damping, implicit Euler: both paths give the same history.
  test::TempDir dir;
  const Scene scene = parse_scene(scene_text((dir / "mid.json").string()), "net_test.toml");
  const TetMesh mesh = scene_mesh(scene, 0, {});
  msm::NetworkOptions o = network_options(scene, scene.models[0], 0.3);
  o.model = msm::ModelType::surface;
  o.surface = msm::WallSurface::mid;
  o.stiffness = msm::StiffnessRule::seed000;
  o.mass = msm::MassRule::consistent;
  o.stiffness_params.bilinear_ratio = 3.0;
  o.stiffness_params.bilinear_threshold_strain = 1e-3;
  o.axial_damping = 2e-3;
  const msm::BuiltNetwork builtin = msm::build_network(mesh, scene.vessel, o);
  msm::NetworkSupports supports;
  supports.follow_groups = {"inlet", "outlet"};
  msm::write_network_file(dir / "mid.json", msm::network_file_of(builtin, supports, ""));
  const msm::BuiltNetwork from_file = scene_network(scene, scene.models[1], mesh, scene.vessel, 0.3);
  // The built-in mid-surface network's source nodes are the inner wall's; the file's nodes find
  // the mesh's mid-wall nodes (level 0 has two layers through the wall). The inner wall's loads
  // then reach the same network nodes by the nearest-node rule.
  EXPECT_NE(from_file.network.source_node, builtin.network.source_node);
  msm::SolverSpec solver = msm::parse_solver("implicit-euler");
  solver.dt = 1e-3;
  solver.steps = 20;
  const Solved a = solve_static(scene, builtin, mesh, 5e-3, solver);
  const Solved b = solve_static(scene, from_file, mesh, 5e-3, solver);
  EXPECT_EQ(a.problem.fixed, b.problem.fixed);
  EXPECT_EQ(a.problem.external_force, b.problem.external_force);
  const double strain = msm::make_model(builtin, 0.0)->max_strain(a.x);
  EXPECT_GT(strain, 1e-3) << "the bilinear threshold is crossed";
  EXPECT_LE((a.x - b.x).lpNorm<Eigen::Infinity>(), 1e-12 * a.x.lpNorm<Eigen::Infinity>());
}

TEST(NetworkModel, TheSceneRunsTheFileAndGivesTheBuiltInModelsErrorInTheSameRun) {
  test::TempDir dir;
  const Scene scene = parse_scene(scene_text((dir / "volume.json").string()), "net_test.toml");
  const TetMesh mesh = scene_mesh(scene, 0, {});
  (void)export_builtin(scene, mesh, dir / "volume.json");
  const SceneResult r = run_scene(scene, HarnessOptions{});
  ASSERT_EQ(r.outcomes.size(), 4u);  // two models × two loads, model by model
  for (std::size_t k = 0; k < 2; ++k) {
    const ModelOutcome& builtin = r.outcomes[k];
    const ModelOutcome& file = r.outcomes[2 + k];
    ASSERT_EQ(builtin.model, "volume");
    ASSERT_EQ(file.model, "volume_from_file");
    ASSERT_TRUE(builtin.ok) << builtin.failure;
    ASSERT_TRUE(file.ok) << file.failure;
    EXPECT_EQ(file.kind, "network");
    EXPECT_EQ(file.magnitude, builtin.magnitude);
    EXPECT_EQ(file.nodes, builtin.nodes);
    EXPECT_EQ(file.unknowns, builtin.unknowns);
    EXPECT_GT(builtin.error.max_mm, 0.0);
    EXPECT_NEAR(file.error.max_mm, builtin.error.max_mm, 1e-12 * builtin.error.max_mm);
    EXPECT_NEAR(file.error.rms_mm, builtin.error.rms_mm, 1e-12 * builtin.error.rms_mm);
    EXPECT_NEAR(file.quantities.contact_point_mm, builtin.quantities.contact_point_mm,
                1e-12 * builtin.quantities.contact_point_mm);
    EXPECT_NE(file.detail.find("spring network from volume.json"), std::string::npos) << file.detail;
  }
}

TEST(NetworkModel, NodesOutsideTheVesselStopTheRunNamingThem) {
  test::TempDir dir;
  const Scene scene = parse_scene(scene_text((dir / "mm.json").string()), "net_test.toml");
  const TetMesh mesh = scene_mesh(scene, 0, {});
  // The exported network with its coordinates in millimetres (a likely user mistake).
  msm::BuiltNetwork built = scene_network(scene, scene.models[0], mesh, scene.vessel, 0.3);
  for (Vec3& x : built.network.nodes) x *= 1e3;
  for (auto& s : built.network.springs) s.rest_length *= 1e3;
  msm::write_network_file(dir / "mm.json", msm::network_file_of(built, {{0}, {}}, ""));
  try {
    (void)run_scene(scene, HarnessOptions{});
    FAIL() << "ran a network outside its vessel";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("model volume_from_file"), std::string::npos) << m;
    EXPECT_NE(m.find("mm.json"), std::string::npos) << m;
    EXPECT_NE(m.find("nodes lie outside the vessel mesh (nodes 0, 1, 2, 3, 4, ...)"), std::string::npos) << m;
    EXPECT_NE(m.find("coordinates in metres"), std::string::npos) << m;
  }
}

TEST(NetworkModel, ANetworkThatNothingHoldsIsRefused) {
  test::TempDir dir;
  const Scene scene = parse_scene(scene_text((dir / "free.json").string()), "net_test.toml");
  const TetMesh mesh = scene_mesh(scene, 0, {});
  const msm::BuiltNetwork built = scene_network(scene, scene.models[0], mesh, scene.vessel, 0.3);
  // It follows only the outlet, but the scene leaves the outlet free: nothing holds it.
  msm::write_network_file(dir / "free.json", msm::network_file_of(built, {{}, {"outlet"}}, ""));
  Scene free_outlet = scene;
  free_outlet.boundary["outlet"] = EndCondition::free;
  const msm::BuiltNetwork from_file = scene_network(free_outlet, scene.models[1], mesh, scene.vessel, 0.3);
  const auto model = msm::make_model(from_file, 0.0);
  try {
    (void)msm_problem(free_outlet, *model, from_file, mesh, 1e-4);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("free.json: no node of the network is held"),
              std::string::npos) << e.what();
  }
  // Following the clamped inlet instead holds exactly the nodes on the inlet face.
  msm::write_network_file(dir / "free.json", msm::network_file_of(built, {{}, {"inlet"}}, ""));
  const msm::BuiltNetwork inlet = scene_network(free_outlet, scene.models[1], mesh, scene.vessel, 0.3);
  const auto inlet_model = msm::make_model(inlet, 0.0);
  const msm::Problem p = msm_problem(free_outlet, *inlet_model, inlet, mesh, 1e-4);
  for (std::size_t i = 0; i < inlet.network.nodes.size(); ++i) {
    EXPECT_EQ(p.fixed[3 * i] == 1, std::abs(inlet.network.nodes[i].z()) < 1e-12) << "node " << i;
  }
}

TEST(NetworkModel, SceneKeysOfANetworkModelAreChecked) {
  auto error = [](const std::string& extra, const std::string& file = "x.json") {
    try {
      (void)parse_scene(scene_text(file, extra), "net_test.toml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("stiffness = \"seed001\"\n").find("key 'models[1].stiffness': unknown key"),
            std::string::npos);
  EXPECT_NE(error("solver = \"pbd\"\ndt = 1e-4\nsteps = 10\n").find("\"pbd\" on a network model"),
            std::string::npos);
  std::string text = scene_text("x.json");
  text.replace(text.find("file = \"x.json\""), std::string("file = \"x.json\"").size(), "");
  try {
    (void)parse_scene(text, "net_test.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'models[1].file': missing"), std::string::npos)
        << e.what();
  }
  // A relative file is found beside the scene.
  const Scene s = parse_scene(scene_text("nets/x.json"), "/some/dir/net_test.toml");
  EXPECT_EQ(s.models[1].network_file, std::filesystem::path("/some/dir/nets/x.json"));
  EXPECT_EQ(s.models[1].kind, ModelKind::network);
}
