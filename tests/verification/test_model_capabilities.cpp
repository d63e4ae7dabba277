/// What a model can run and what it needs (verification/model_capabilities.hpp): the refusals are
/// the models' own (the msm functions that would throw), the scene check finds a model's missing
/// file before any work, and a model whose file turns bad during a run fails alone.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/stiffness/hybrid_moduli.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "msm/terms/volume_term_homogenised.hpp"
#include "test_paths.hpp"
#include "tests/fixtures/lame_tube_scene.hpp"
#include "verification/harness/harness.hpp"
#include "verification/model_capabilities.hpp"
#include "verification/scene.hpp"

using namespace vessel;

namespace {

constexpr double kE = 14.24e3;

/// The message `f` throws as InputError, or "" if it does not throw.
template <class F>
std::string thrown(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(ModelCapabilities, TheHybridVolumeModelRefusesWhatItsModuliRuleThrowsFor) {
  ModelSpec hybrid;
  hybrid.kind = ModelKind::volume_msm;
  hybrid.volume_term = true;
  for (const double nu : {0.0, 0.2, 0.25, 0.3, 0.45, 0.49, 0.5}) {
    EXPECT_EQ(model_refusal(hybrid, kE, nu), thrown([&] { (void)msm::hybrid_moduli(kE, nu); }))
        << "ν = " << nu;
  }
  EXPECT_TRUE(model_refusal(hybrid, kE, 0.3).empty());
  EXPECT_NE(model_refusal(hybrid, kE, 0.2).find("[0.25, 0.5)"), std::string::npos);
  EXPECT_NE(model_refusal(hybrid, kE, 0.5).find("infinite"), std::string::npos);
}

TEST(ModelCapabilities, EdgePairsAndTheHomogenisedRuleRefuseOnlyNuOneHalf) {
  ModelSpec pairs;
  pairs.kind = ModelKind::volume_msm;
  pairs.edge_pairs = true;
  ModelSpec homogenised;
  homogenised.kind = ModelKind::volume_msm;
  homogenised.volume_term = true;
  homogenised.volume_moduli = msm::VolumeModuli::homogenised;
  for (const double nu : {0.0, 0.1, 0.3, 0.49}) {
    EXPECT_TRUE(model_refusal(pairs, kE, nu).empty()) << nu;
    EXPECT_TRUE(model_refusal(homogenised, kE, nu).empty()) << nu;  // a mesh's floor: when fitted
  }
  EXPECT_EQ(model_refusal(pairs, kE, 0.5), thrown([] { (void)msm::lame_parameters(kE, 0.5); }));
  EXPECT_NE(model_refusal(homogenised, kE, 0.5).find("homogenised"), std::string::npos);
  ModelSpec springs;
  springs.kind = ModelKind::volume_msm;
  EXPECT_TRUE(model_refusal(springs, kE, 0.5).empty());  // Cauchy's ν = 1/4 is an error, not a refusal
}

TEST(ModelCapabilities, RequiredFilesNameTheSceneKeys) {
  ModelSpec calibrated;
  calibrated.kind = ModelKind::volume_msm;
  calibrated.calibration = "c.json";
  ModelSpec network;
  network.kind = ModelKind::network;
  network.network_file = "n.vtu";
  ASSERT_EQ(required_files(calibrated).size(), 1u);
  EXPECT_EQ(required_files(calibrated)[0].key, "calibration");
  ASSERT_EQ(required_files(network).size(), 1u);
  EXPECT_EQ(required_files(network)[0].key, "file");
  EXPECT_EQ(required_files(network)[0].path, "n.vtu");
  EXPECT_TRUE(required_files(ModelSpec{}).empty());
}

TEST(ModelCapabilities, ASceneCopiedWithoutItsCalibrationFileFailsTheSceneCheck) {
  // contact_arch.toml copied to another folder, its calibrations/ left behind: read_scene (what
  // `vesselverify scene` and `run` call first) names the copy, the model, the key and the file.
  const test::TempDir scratch;
  const std::filesystem::path& dir = scratch.path();
  const auto copy = dir / "contact_arch.toml";
  std::filesystem::copy_file(std::filesystem::path(VESSEL_SCENES_DIR) / "contact_arch.toml", copy);
  const std::string why = thrown([&] { (void)read_scene(copy); });
  ASSERT_FALSE(why.empty());
  EXPECT_NE(why.find(copy.string()), std::string::npos) << why;
  EXPECT_NE(why.find("key 'calibration'"), std::string::npos) << why;
  EXPECT_NE(why.find("contact_straight_hybrid_groups.json"), std::string::npos) << why;
  // The scene as shipped passes.
  EXPECT_NO_THROW((void)read_scene(std::filesystem::path(VESSEL_SCENES_DIR) / "contact_arch.toml"));
}

TEST(ModelCapabilities, AModelWhoseCalibrationFileTurnsBadDuringARunFailsAlone) {
  const test::TempDir scratch;
  const std::filesystem::path& dir = scratch.path();
  std::ofstream(dir / "bad.json") << "{ not json";
  const std::string text = vessel::test::lame_tube_scene("bad_calibration") + R"(
[[models]]
name = "plain"
kind = "volume_msm"
stiffness = "van-gelder"
solver = "linear"
[[models]]
name = "calibrated"
kind = "volume_msm"
stiffness = "van-gelder"
solver = "linear"
calibration = "bad.json"
)";
  // parse_scene reads no files: as if bad.json had been spoilt after the scene was checked.
  const Scene scene = parse_scene(text, (dir / "scene.toml").string());
  const SceneResult r = run_scene(scene, HarnessOptions{});
  ASSERT_EQ(r.outcomes.size(), 2u);
  for (const ModelOutcome& o : r.outcomes) {
    if (o.model == "plain") {
      EXPECT_TRUE(o.ok) << o.failure;
    } else {
      EXPECT_FALSE(o.ok);
      EXPECT_NE(o.failure.find("bad.json"), std::string::npos) << o.failure;
    }
  }
}
