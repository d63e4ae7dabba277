// Scene files: every shipped scene parses and validates; bad scenes are refused naming file, line
// and key.
#include <gtest/gtest.h>

#include <filesystem>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

const char* kMinimal = R"(name = "t"
[vessel]
kind = "straight"
level = 0
[load]
type = "contact"
magnitudes = [0.01, 0.02]
point = [3e-3, 0, 20e-3]
[[models]]
kind = "fem"
degree = 1
)";

std::string error_of(const std::string& text) {
  try {
    (void)parse_scene(text, "scene.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// `kMinimal` with the first `from` replaced by `to`.
std::string replaced(const std::string& from, const std::string& to) {
  std::string text = kMinimal;
  return text.replace(text.find(from), from.size(), to);
}

/// `kMinimal` with `line` inserted after the first line that starts with `after`.
std::string with(const std::string& after, const std::string& line) {
  std::string text = kMinimal;
  const auto at = text.find('\n', text.find(after)) + 1;
  return text.insert(at, line + "\n");
}

}  // namespace

TEST(Scene, EveryShippedSceneParsesAndValidates) {
  const std::filesystem::path dir = VESSEL_SCENES_DIR;
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    Scene s = read_scene(entry.path());
    EXPECT_EQ(s.name, entry.path().stem().string());
    EXPECT_FALSE(s.models.empty());
    if (s.load.guidewire) {  // its one magnitude is the wire's force, solved on the run path
      EXPECT_FALSE(s.load.wire.has_value());
      solve_guidewire_load(s);
      ASSERT_EQ(s.load.magnitudes.size(), 1u);
      EXPECT_GT(s.load.magnitudes[0], 0.0);
    }
    EXPECT_FALSE(s.load.magnitudes.empty());
    ++count;
  }
  EXPECT_GE(count, 5);
}

TEST(Scene, ReferenceChoiceIsReadAndChecked) {
  EXPECT_EQ(parse_scene(kMinimal, "scene.toml").reference, ReferenceChoice::linear);
  EXPECT_EQ(parse_scene(with("name", "reference = \"finite-strain\""), "s").reference,
            ReferenceChoice::finite_strain);
  EXPECT_EQ(parse_scene(with("name", "reference = \"auto\""), "s").reference,
            ReferenceChoice::automatic);
  const std::string e = error_of(with("name", "reference = \"nonlinear\""));
  EXPECT_NE(e.find("reference"), std::string::npos) << e;
  EXPECT_NE(e.find("finite-strain"), std::string::npos) << e;
}

TEST(Scene, DefaultsAndValuesAreRead) {
  const Scene s = parse_scene(kMinimal, "scene.toml");
  EXPECT_EQ(s.vessel.kind, VesselKind::straight);
  EXPECT_EQ(s.vessel.style, MeshStyle::structured);
  EXPECT_DOUBLE_EQ(s.youngs_modulus, 14.24e3);  // seed 000's E
  EXPECT_EQ(s.load.magnitudes, (std::vector<double>{0.01, 0.02}));
  EXPECT_DOUBLE_EQ(s.load.contact.radius, 0.5e-3);
  EXPECT_EQ(s.models.at(0).degree, 1);
  EXPECT_EQ(s.models.at(0).name, "fem_1");
  EXPECT_EQ(s.boundary.at("inlet"), EndCondition::clamped);
}

TEST(Scene, UnknownKeyIsRefusedWithLineAndKnownKeys) {
  const auto msg = error_of(with("[vessel]", "lenght = 0.04"));
  EXPECT_NE(msg.find("scene.toml:3: key 'vessel.lenght': unknown key"), std::string::npos) << msg;
  EXPECT_NE(msg.find("length"), std::string::npos) << msg;
  EXPECT_NE(error_of(with("name", "colour = \"red\"")).find("key 'colour'"), std::string::npos);
}

TEST(Scene, WrongTypesAndRangesAreRefusedNamingTheKey) {
  auto msg = error_of(with("[vessel]", "inner_radius = \"3mm\""));
  EXPECT_NE(msg.find("key 'vessel.inner_radius': found \"3mm\", expected a number"),
            std::string::npos) << msg;
  msg = error_of(with("[vessel]", "inner_radius = -3e-3"));
  EXPECT_NE(msg.find("vessel.inner_radius"), std::string::npos) << msg;
  msg = error_of(replaced("level = 0", "level = 7"));
  EXPECT_NE(msg.find("key 'vessel.level': found 7, expected an integer in [0, 4]"),
            std::string::npos) << msg;
  msg = error_of(with("name", "[material]\nnu = 0.6"));
  EXPECT_NE(msg.find("key 'material.nu': found 0.6, expected a number in [0, 0.5]"),
            std::string::npos) << msg;
  msg = error_of(with("name", "[material]\nE = 0"));
  EXPECT_NE(msg.find("material.E"), std::string::npos) << msg;
}

TEST(Scene, IntegratorsNeedAPositiveTimeStep) {
  const std::string model = "[[models]]\nkind = \"volume_msm\"\nsolver = \"verlet\"\nsteps = 10\n";
  auto msg = error_of(std::string(kMinimal) + model + "dt = 0.0\n");
  EXPECT_NE(msg.find("dt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("> 0"), std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) + model + "dt = -1e-4\n");
  EXPECT_NE(msg.find("models[1].dt"), std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) + model);
  EXPECT_NE(msg.find("missing; solver \"verlet\" needs a time step"), std::string::npos) << msg;
}

TEST(Scene, UnknownRuleNamesAndDuplicateModelsAreRefused) {
  auto msg = error_of(std::string(kMinimal) + "[[models]]\nkind = \"volume_msm\"\nstiffness = \"magic\"\n");
  EXPECT_NE(msg.find("key 'models[1].stiffness'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected one of seed000"), std::string::npos) << msg;
  EXPECT_NE(msg.find("magic"), std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) + "[[models]]\nkind = \"fem\"\nname = \"fem_1\"\n");
  EXPECT_NE(msg.find("used twice"), std::string::npos) << msg;
}

TEST(Scene, MissingSectionsSyntaxErrorsAndMissingFilesAreClear) {
  EXPECT_NE(error_of("name = \"x\"\n").find("[vessel]"), std::string::npos);
  const auto msg = error_of("name = \"x\"\n[vessel\n");
  EXPECT_NE(msg.find("scene.toml:2: TOML syntax error"), std::string::npos) << msg;
  try {
    (void)read_scene("/nonexistent/scene.toml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

TEST(Scene, ArchTooTightForItsWallIsRefused) {
  const auto msg =
      error_of(replaced("kind = \"straight\"", "kind = \"arch\"\nbend_radius = 3.5e-3"));
  EXPECT_NE(msg.find("too thick"), std::string::npos) << msg;
}

TEST(Scene, LevelMayBeAListForAConvergenceSweep) {
  const Scene s = parse_scene(replaced("level = 0", "level = [2, 0, 1]"), "scene.toml");
  EXPECT_EQ(s.model_levels, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(s.vessel.level, 0);
  EXPECT_EQ(s.reference_level, 2);  // default: the finest model level
  const auto msg = error_of(replaced("level = 0", "level = [0, 9]"));
  EXPECT_NE(msg.find("key 'vessel.level': found 9"), std::string::npos) << msg;
}

TEST(Scene, ArraysInAModelTableExpandIntoOneModelPerCombination) {
  const std::string model =
      "[[models]]\nname = \"vol\"\nkind = \"volume_msm\"\nstiffness = [\"seed001\", \"lloyd\"]\n"
      "solver = [\"static\", \"verlet\"]\ndt = [1e-5, 2e-5]\nsteps = 10\n";
  const Scene s = parse_scene(std::string(kMinimal) + model, "scene.toml");
  // 2 rules × (static + verlet at 2 steps) = 6 mass-spring models after the FEM one.
  ASSERT_EQ(s.models.size(), 7u);
  std::vector<std::string> names;
  for (std::size_t i = 1; i < s.models.size(); ++i) names.push_back(s.models[i].name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "vol[stiffness=seed001;solver=static]",
                       "vol[stiffness=seed001;solver=verlet;dt=1e-05]",
                       "vol[stiffness=seed001;solver=verlet;dt=2e-05]",
                       "vol[stiffness=lloyd;solver=static]",
                       "vol[stiffness=lloyd;solver=verlet;dt=1e-05]",
                       "vol[stiffness=lloyd;solver=verlet;dt=2e-05]"}));
  EXPECT_EQ(s.models[3].stiffness, msm::StiffnessRule::seed001);
  EXPECT_EQ(s.models[3].solver.kind, msm::SolverKind::integrator);
  EXPECT_EQ(s.models[3].solver.integrator, msm::Integrator::verlet);
  EXPECT_DOUBLE_EQ(s.models[3].solver.dt, 2e-5);
  EXPECT_EQ(s.models[3].solver.steps, 10);
  EXPECT_EQ(s.models[4].solver.kind, msm::SolverKind::static_newton);
  EXPECT_EQ(s.models[4].solver.steps, 0);  // static: no steps
  const auto msg = error_of(std::string(kMinimal) +
                            "[[models]]\nkind = \"volume_msm\"\nstiffness = [\"seed001\", 3]\n");
  EXPECT_NE(msg.find("key 'models[1].stiffness': found 3, expected a string"), std::string::npos)
      << msg;
}

TEST(Scene, PositionBasedDynamicsIsASolverOfSurfaceModels) {
  const std::string pbd =
      "[[models]]\nname = \"pbd\"\nkind = \"surface_msm\"\nsolver = \"pbd\"\ndt = 1e-3\n"
      "steps = 20\n";
  const Scene s = parse_scene(std::string(kMinimal) + pbd, "scene.toml");
  const ModelSpec& m = s.models.back();
  EXPECT_EQ(m.solver.kind, msm::SolverKind::pbd);
  EXPECT_TRUE(m.solver.is_dynamic());
  EXPECT_DOUBLE_EQ(m.solver.dt, 1e-3);
  EXPECT_EQ(m.solver.steps, 20);
  // Like an integrator it needs a time step; on a volume model it is refused with the key's line.
  const auto no_dt = error_of(std::string(kMinimal) +
                              "[[models]]\nkind = \"surface_msm\"\nsolver = \"pbd\"\nsteps = 5\n");
  EXPECT_NE(no_dt.find("models[1].dt"), std::string::npos) << no_dt;
  const auto volume = error_of(std::string(kMinimal) +
                               "[[models]]\nkind = \"volume_msm\"\nsolver = \"pbd\"\n");
  EXPECT_NE(volume.find("models[1].solver"), std::string::npos) << volume;
  EXPECT_NE(volume.find("surface_msm"), std::string::npos) << volume;
}

TEST(Scene, LocalGlobalEulerTakesItsIterationsPerStep) {
  const std::string lg =
      "[[models]]\nname = \"lg\"\nkind = \"volume_msm\"\nsolver = \"local-global-euler\"\n"
      "dt = 1e-3\nsteps = 20\n";
  Scene s = parse_scene(std::string(kMinimal) + lg, "scene.toml");
  EXPECT_EQ(s.models.back().solver.kind, msm::SolverKind::local_global_euler);
  EXPECT_TRUE(s.models.back().solver.is_dynamic());
  EXPECT_EQ(s.models.back().solver.local_global.iterations, 10);  // the default
  s = parse_scene(std::string(kMinimal) + lg + "iterations = 3\n", "scene.toml");
  EXPECT_EQ(s.models.back().solver.local_global.iterations, 3);
  auto msg = error_of(std::string(kMinimal) + lg + "iterations = 0\n");
  EXPECT_NE(msg.find("models[1].iterations"), std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) +
                 "[[models]]\nkind = \"volume_msm\"\nsolver = \"static\"\niterations = 3\n");
  EXPECT_NE(msg.find("local-global-euler"), std::string::npos) << msg;
  EXPECT_EQ(parse_scene(std::string(kMinimal) +
                            "[[models]]\nname = \"lgs\"\nkind = \"volume_msm\"\nsolver = \"local-global\"\n",
                        "scene.toml")
                .models.back()
                .solver.kind,
            msm::SolverKind::local_global);
}

TEST(Scene, VolumeTermSelectsTheHybridVolumeModel) {
  const Scene s = parse_scene(std::string(kMinimal) +
                                  "[[models]]\nname = \"hybrid\"\nkind = \"volume_msm\"\n"
                                  "volume_term = true\n",
                              "scene.toml");
  const ModelSpec& m = s.models.back();
  EXPECT_TRUE(m.volume_term);
  EXPECT_EQ(m.stiffness, msm::StiffnessRule::van_gelder);  // its default
  // Another rule, a non-boolean, or the key on a surface model: refused, naming the key.
  const auto rule = error_of(std::string(kMinimal) +
                             "[[models]]\nkind = \"volume_msm\"\nvolume_term = true\n"
                             "stiffness = \"lloyd\"\n");
  EXPECT_NE(rule.find("models[1].stiffness"), std::string::npos) << rule;
  EXPECT_NE(rule.find("van-gelder"), std::string::npos) << rule;
  const auto type = error_of(std::string(kMinimal) +
                             "[[models]]\nkind = \"volume_msm\"\nvolume_term = 1\n");
  EXPECT_NE(type.find("models[1].volume_term"), std::string::npos) << type;
  const auto surface = error_of(std::string(kMinimal) +
                                "[[models]]\nkind = \"surface_msm\"\nvolume_term = true\n");
  EXPECT_NE(surface.find("volume_term"), std::string::npos) << surface;
}

TEST(Scene, VolumeModuliSelectsTheHomogenisedRule) {
  EXPECT_EQ(parse_scene(std::string(kMinimal) +
                            "[[models]]\nname = \"h\"\nkind = \"volume_msm\"\nvolume_term = true\n",
                        "scene.toml")
                .models.back()
                .volume_moduli,
            msm::VolumeModuli::golec);  // the default
  const Scene s = parse_scene(std::string(kMinimal) +
                                  "[[models]]\nname = \"h\"\nkind = \"volume_msm\"\n"
                                  "volume_term = true\nvolume_moduli = \"homogenised\"\n",
                              "scene.toml");
  EXPECT_EQ(s.models.back().volume_moduli, msm::VolumeModuli::homogenised);
  // An unknown rule, or the key without the volume term: refused, naming the key.
  const auto unknown = error_of(std::string(kMinimal) +
                                "[[models]]\nkind = \"volume_msm\"\nvolume_term = true\n"
                                "volume_moduli = \"voigt\"\n");
  EXPECT_NE(unknown.find("models[1].volume_moduli"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("homogenised"), std::string::npos) << unknown;
  const auto alone = error_of(std::string(kMinimal) +
                              "[[models]]\nkind = \"volume_msm\"\n"
                              "volume_moduli = \"homogenised\"\n");
  EXPECT_NE(alone.find("models[1].volume_moduli"), std::string::npos) << alone;
  EXPECT_NE(alone.find("volume_term = true"), std::string::npos) << alone;
}

TEST(Scene, EdgePairsSelectsTheEdgePairModel) {
  const Scene s = parse_scene(std::string(kMinimal) +
                                  "[[models]]\nname = \"pairs\"\nkind = \"volume_msm\"\n"
                                  "edge_pairs = true\n",
                              "scene.toml");
  EXPECT_TRUE(s.models.back().edge_pairs);
  EXPECT_FALSE(s.models.back().volume_term);
  // With a stiffness rule, the volume term or a calibration: refused, naming the key; on a
  // surface model the key is unknown.
  const auto rule = error_of(std::string(kMinimal) +
                             "[[models]]\nkind = \"volume_msm\"\nedge_pairs = true\n"
                             "stiffness = \"lloyd\"\n");
  EXPECT_NE(rule.find("models[1].stiffness"), std::string::npos) << rule;
  EXPECT_NE(rule.find("edge_pairs"), std::string::npos) << rule;
  const auto both = error_of(std::string(kMinimal) +
                             "[[models]]\nkind = \"volume_msm\"\nedge_pairs = true\n"
                             "volume_term = true\n");
  EXPECT_NE(both.find("models[1].edge_pairs"), std::string::npos) << both;
  const auto calibrated = error_of(std::string(kMinimal) +
                                   "[[models]]\nkind = \"volume_msm\"\nedge_pairs = true\n"
                                   "calibration = \"c.json\"\n");
  EXPECT_NE(calibrated.find("models[1].calibration"), std::string::npos) << calibrated;
  const auto surface = error_of(std::string(kMinimal) +
                                "[[models]]\nkind = \"surface_msm\"\nedge_pairs = true\n");
  EXPECT_NE(surface.find("edge_pairs"), std::string::npos) << surface;
}

TEST(Scene, ModesTableIsReadAndCheckedNamingTheKey) {
  EXPECT_EQ(parse_scene(kMinimal, "scene.toml").modes.count, 0);  // off unless asked for
  const Scene s = parse_scene(std::string(kMinimal) + "[modes]\ncount = 6\nreference_level = 0\n",
                              "scene.toml");
  EXPECT_EQ(s.modes.count, 6);
  EXPECT_EQ(s.modes.reference_level, 0);
  EXPECT_EQ(parse_scene(std::string(kMinimal) + "[modes]\ncount = 3\n", "scene.toml")
                .modes.reference_level,
            -1);  // the scene's reference level
  auto msg = error_of(std::string(kMinimal) + "[modes]\ncount = -1\n");
  EXPECT_NE(msg.find("key 'modes.count': found -1, expected an integer in [0, 100]"),
            std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) + "[modes]\ncount = 6\nreference_level = 9\n");
  EXPECT_NE(msg.find("key 'modes.reference_level'"), std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) + "[modes]\nnumber = 6\n");
  EXPECT_NE(msg.find("key 'modes.number': unknown key"), std::string::npos) << msg;
}

TEST(Scene, TransientTableIsReadAndCheckedNamingTheKey) {
  EXPECT_EQ(parse_scene(kMinimal, "scene.toml").transient.reference_level, -1);  // the scene's
  EXPECT_EQ(parse_scene(std::string(kMinimal) + "[transient]\nreference_level = 0\n", "scene.toml")
                .transient.reference_level,
            0);
  auto msg = error_of(std::string(kMinimal) + "[transient]\nreference_level = -2\n");
  EXPECT_NE(msg.find("key 'transient.reference_level'"), std::string::npos) << msg;
  msg = error_of(std::string(kMinimal) + "[transient]\nlevel = 0\n");
  EXPECT_NE(msg.find("key 'transient.level': unknown key"), std::string::npos) << msg;
}

TEST(Scene, BendingSelectsTheDiscreteShellsSurfaceModel) {
  const Scene s = parse_scene(std::string(kMinimal) +
                                  "[[models]]\nname = \"shell\"\nkind = \"surface_msm\"\n"
                                  "bending = \"discrete-shells\"\n",
                              "scene.toml");
  const ModelSpec& m = s.models.back();
  EXPECT_EQ(m.bending, msm::Bending::discrete_shells);
  EXPECT_EQ(m.stiffness, msm::StiffnessRule::van_gelder);  // its default membrane
  EXPECT_EQ(network_options(s, m, 0.45).bending, msm::Bending::discrete_shells);
  // An unknown name, the grid topology, PBD, or the key on a volume model: refused, naming the key.
  const auto name = error_of(std::string(kMinimal) +
                             "[[models]]\nkind = \"surface_msm\"\nbending = \"kirchhoff\"\n");
  EXPECT_NE(name.find("models[1].bending"), std::string::npos) << name;
  EXPECT_NE(name.find("discrete-shells"), std::string::npos) << name;
  const auto grid = error_of(std::string(kMinimal) +
                             "[[models]]\nkind = \"surface_msm\"\nbending = \"discrete-shells\"\n"
                             "topology = \"grid\"\n");
  EXPECT_NE(grid.find("models[1].topology"), std::string::npos) << grid;
  const auto pbd = error_of(std::string(kMinimal) +
                            "[[models]]\nkind = \"surface_msm\"\nbending = \"discrete-shells\"\n"
                            "solver = \"pbd\"\ndt = 1e-3\nsteps = 10\n");
  EXPECT_NE(pbd.find("models[1].solver"), std::string::npos) << pbd;
  const auto volume = error_of(
      std::string(kMinimal) + "[[models]]\nkind = \"volume_msm\"\nbending = \"discrete-shells\"\n");
  EXPECT_NE(volume.find("bending"), std::string::npos) << volume;
}
