// Calibration files (verification/calibration_file): a round trip, the factors applied to a
// network as the fit defines them, and clear errors for another mesh, a per-spring transfer,
// and bad files; the scene keys that refer to a file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/model/build_network.hpp"
#include "tests/fixtures/kuhn_block.hpp"
#include "verification/calibration_file.hpp"
#include "verification/scene.hpp"

using namespace vessel;

namespace {

TetMesh block_mesh(int n, double h) {
  return vessel::test::kuhn_block(n, n, n, h, Vec3(3e-3, 0.0, 0.0));
}

constexpr double kE = 14.24e3;

ModelSpec hybrid_spec() {
  ModelSpec m;
  m.name = "volume_hybrid";
  m.kind = ModelKind::volume_msm;
  m.stiffness = msm::StiffnessRule::van_gelder;
  m.volume_term = true;
  return m;
}

msm::BuiltNetwork hybrid(const TetMesh& mesh) {
  msm::NetworkOptions o;
  o.model = msm::ModelType::volume;
  o.stiffness = msm::StiffnessRule::van_gelder;
  o.stiffness_params.youngs_modulus = kE;
  o.stiffness_params.poisson_ratio = 0.45;
  o.volume_term = true;
  return msm::build_network(mesh, VesselParams{}, o);
}

/// A calibration of `built` on `mesh` with factors 1 + 0.1·(index + 1).
Calibration make_calibration(const TetMesh& mesh, const msm::BuiltNetwork& built, bool per_spring) {
  const msm::StiffnessParameters p =
      per_spring ? msm::per_spring_parameters(built.network, true)
                 : msm::group_parameters(built.network, VesselParams{}, true);
  Calibration c;
  c.granularity = per_spring ? "per_spring" : "groups";
  c.scene = "block";
  c.model = "volume_hybrid";
  c.model_kind = "volume_msm";
  c.stiffness = "van-gelder";
  c.volume_term = true;
  c.poisson_ratio = 0.45;
  c.youngs_modulus = kE;
  c.mesh_hash = mesh_hash(mesh);
  c.vessel = "block";
  c.nodes = mesh.nodes.size();
  c.springs = built.network.springs.size();
  c.tets = mesh.tets.size();
  c.names = p.names;
  for (int i = 0; i < p.size(); ++i) c.factors.push_back(1.0 + 0.1 * (i % 7 + 1));
  c.training_loads.push_back({"contact θ+0°", LoadKind::contact, 5e-4, Vec3(3e-3, 0, 0.02)});
  c.fit_cases.push_back({"contact θ+0°", 0.5, 0.1});
  c.method = "test";
  return c;
}

/// A file in this test program's own temporary folder (removed when the program exits).
std::filesystem::path temp_file(const std::string& name) {
  static const test::TempDir dir;
  return dir.path() / name;
}

void expect_input_error(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "expected an InputError mentioning " << needle;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(CalibrationFile, RoundTripAndAppliedFactorsScaleEachSpringAndKappa) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  for (const bool per_spring : {false, true}) {
    const msm::BuiltNetwork base = hybrid(mesh);
    const Calibration c = make_calibration(mesh, base, per_spring);
    const auto path = temp_file(per_spring ? "per_spring.json" : "groups.json");
    write_calibration(path, c);
    const Calibration r = read_calibration(path);
    EXPECT_EQ(r.granularity, c.granularity);
    EXPECT_EQ(r.mesh_hash, c.mesh_hash);
    ASSERT_EQ(r.names.size(), c.names.size());
    for (std::size_t i = 0; i < c.names.size(); ++i) {
      const auto it = std::find(r.names.begin(), r.names.end(), c.names[i]);
      ASSERT_NE(it, r.names.end()) << c.names[i];
      EXPECT_DOUBLE_EQ(r.factors[static_cast<std::size_t>(it - r.names.begin())], c.factors[i]);
    }
    ASSERT_EQ(r.training_loads.size(), 1u);
    EXPECT_EQ(r.training_loads[0].kind, LoadKind::contact);
    EXPECT_DOUBLE_EQ(r.training_loads[0].point.z(), 0.02);

    msm::BuiltNetwork applied = base;
    apply_calibration(r, "test", applied, mesh, VesselParams{}, hybrid_spec(), kE, 0.45, false);
    // Each spring's k is its base k times the factor its class (or index) was given.
    const msm::StiffnessParameters p =
        per_spring ? msm::per_spring_parameters(base.network, true)
                   : msm::group_parameters(base.network, VesselParams{}, true);
    for (std::size_t s = 0; s < base.network.springs.size(); ++s) {
      const double factor = c.factors[static_cast<std::size_t>(p.of_spring[s])];
      EXPECT_NEAR(applied.network.springs[s].law.k1, factor * base.network.springs[s].law.k1,
                  1e-12 * base.network.springs[s].law.k1);
    }
    EXPECT_NEAR(*applied.terms.volume_kappa, c.factors.back() * *base.terms.volume_kappa,
                1e-12 * *base.terms.volume_kappa);
  }
}

// A wall-layer calibration: its spring factors per (direction, layer) class and κ per half of
// the wall go through the file and land on each spring and on each tet's κ factor; it transfers
// to another mesh as a group calibration does.
TEST(CalibrationFile, WallLayerCalibrationRoundTripsAndScalesSpringsAndEachTetsKappa) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  VesselParams wall;  // the block spans ρ = 3–5.4 mm
  wall.inner_radius = 3.5e-3;
  wall.wall_thickness = 1.0e-3;
  const msm::BuiltNetwork base = hybrid(mesh);
  const msm::StiffnessParameters p = msm::wall_layer_parameters(base.network, wall, true);
  Calibration c = make_calibration(mesh, base, false);
  c.granularity = "wall_layers";
  c.names = p.names;
  c.factors.clear();
  for (int i = 0; i < p.size(); ++i) c.factors.push_back(1.0 + 0.1 * (i + 1));
  const auto path = temp_file("wall_layers.json");
  write_calibration(path, c);
  const Calibration r = read_calibration(path);
  EXPECT_EQ(r.granularity, "wall_layers");
  msm::BuiltNetwork applied = base;
  apply_calibration(r, "test", applied, mesh, wall, hybrid_spec(), kE, 0.45, false);
  for (std::size_t s = 0; s < base.network.springs.size(); ++s) {
    const double factor = c.factors[static_cast<std::size_t>(p.of_spring[s])];
    EXPECT_NEAR(applied.network.springs[s].law.k1, factor * base.network.springs[s].law.k1,
                1e-12 * base.network.springs[s].law.k1);
  }
  EXPECT_DOUBLE_EQ(*applied.terms.volume_kappa, *base.terms.volume_kappa);  // κ scaled per tet instead
  ASSERT_EQ(applied.network.tet_kappa_factors.size(), base.network.tets.size());
  int inner = 0, outer = 0;
  for (std::size_t e = 0; e < base.network.tets.size(); ++e) {
    const double base_factor =
        base.network.tet_kappa_factors.empty() ? 1.0 : base.network.tet_kappa_factors[e];
    const std::string& name = p.names[static_cast<std::size_t>(p.of_tet[e])];
    (name == "kappa/inner" ? inner : outer) += 1;
    EXPECT_NEAR(applied.network.tet_kappa_factors[e],
                c.factors[static_cast<std::size_t>(p.of_tet[e])] * base_factor, 1e-12);
  }
  EXPECT_GT(inner, 0);
  EXPECT_GT(outer, 0);
  TetMesh moved = mesh;
  moved.nodes[5].x() += 1e-6;
  msm::BuiltNetwork on_moved = hybrid(moved);
  EXPECT_NO_THROW(apply_calibration(r, "cal.json", on_moved, moved, wall, hybrid_spec(), kE, 0.45,
                                    true));
}

// A per-spring calibration with κ per half of the wall (a fit on top of an edge-types one)
// keeps its two κ factors through the file, and they land on each tet's κ factor.
TEST(CalibrationFile, PerSpringCalibrationKeepsItsKappaHalves) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  VesselParams wall;  // the block spans ρ = 3–5.4 mm
  wall.inner_radius = 3.5e-3;
  wall.wall_thickness = 1.0e-3;
  const msm::BuiltNetwork base = hybrid(mesh);
  const msm::StiffnessParameters p = msm::per_spring_parameters(base.network, true, &wall);
  ASSERT_EQ(p.of_tet.size(), base.network.tets.size());
  Calibration c = make_calibration(mesh, base, true);
  c.names = p.names;
  c.factors.clear();
  for (int i = 0; i < p.size(); ++i) c.factors.push_back(1.0 + 0.05 * (i % 11));
  const auto path = temp_file("per_spring_halves.json");
  write_calibration(path, c);
  const Calibration r = read_calibration(path);
  ASSERT_EQ(r.names.size(), c.names.size());
  msm::BuiltNetwork applied = base;
  apply_calibration(r, "test", applied, mesh, wall, hybrid_spec(), kE, 0.45, false);
  for (std::size_t s = 0; s < base.network.springs.size(); ++s) {
    EXPECT_NEAR(applied.network.springs[s].law.k1, c.factors[s] * base.network.springs[s].law.k1,
                1e-12 * base.network.springs[s].law.k1);
  }
  EXPECT_DOUBLE_EQ(*applied.terms.volume_kappa, *base.terms.volume_kappa);
  ASSERT_EQ(applied.network.tet_kappa_factors.size(), base.network.tets.size());
  for (std::size_t e = 0; e < base.network.tets.size(); ++e) {
    const double base_factor =
        base.network.tet_kappa_factors.empty() ? 1.0 : base.network.tet_kappa_factors[e];
    EXPECT_NEAR(applied.network.tet_kappa_factors[e],
                c.factors[static_cast<std::size_t>(p.of_tet[e])] * base_factor, 1e-12);
  }
}

// A per-section-spring calibration goes through the file onto each spring by its section class,
// and, indexed by one mesh's cross-section, is refused on another mesh even with transfer.
TEST(CalibrationFile, PerSectionSpringCalibrationAppliesOnItsMeshOnly) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  VesselParams tube;
  tube.inner_radius = 3.5e-3;
  tube.wall_thickness = 1.0e-3;
  const msm::BuiltNetwork base = hybrid(mesh);
  const msm::StiffnessParameters p =
      msm::per_section_spring_parameters(base.network, tube, true, false);
  ASSERT_LT(p.size(), static_cast<int>(base.network.springs.size()));
  Calibration c = make_calibration(mesh, base, false);
  c.granularity = "per_section_spring";
  Eigen::VectorXd theta(p.size());
  for (int i = 0; i < p.size(); ++i) theta[i] = 0.1 * std::sin(1.0 + i);
  set_calibration_parameters(c, p, theta);
  const auto path = temp_file("per_section_spring.json");
  write_calibration(path, c);
  const Calibration r = read_calibration(path);
  EXPECT_EQ(r.granularity, "per_section_spring");
  msm::BuiltNetwork applied = base;
  apply_calibration(r, "test", applied, mesh, tube, hybrid_spec(), kE, 0.45, false);
  for (std::size_t s = 0; s < base.network.springs.size(); ++s) {
    const double factor = std::exp(theta[p.of_spring[s]]);
    EXPECT_NEAR(applied.network.springs[s].law.k1, factor * base.network.springs[s].law.k1,
                1e-12 * factor * base.network.springs[s].law.k1);
  }
  EXPECT_NEAR(*applied.terms.volume_kappa, std::exp(theta[p.kappa]) * *base.terms.volume_kappa,
              1e-12 * *base.terms.volume_kappa);
  TetMesh moved = mesh;
  moved.nodes[5].x() += 1e-6;
  msm::BuiltNetwork on_moved = hybrid(moved);
  expect_input_error(
      [&] { apply_calibration(r, "cal.json", on_moved, moved, tube, hybrid_spec(), kE, 0.45, true); },
      "mesh.hash");
}

// A wall-layer class the fitted mesh did not have gets the geometric mean of its direction's
// factors in the other layers (hand-computed here); a direction missing altogether is refused.
TEST(CalibrationFile, AMissingWallLayerTakesTheGeometricMeanOfItsDirectionsLayers) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  VesselParams wall;
  wall.inner_radius = 3.5e-3;
  wall.wall_thickness = 1.0e-3;
  const msm::BuiltNetwork base = hybrid(mesh);
  const msm::StiffnessParameters p = msm::wall_layer_parameters(base.network, wall, true);
  const auto has = [&](const std::string& n) {
    return std::find(p.names.begin(), p.names.end(), n) != p.names.end();
  };
  ASSERT_TRUE(has("volume/axial/inner") && has("volume/axial/middle") && has("volume/axial/outer"));
  Calibration c = make_calibration(mesh, base, false);
  c.granularity = "wall_layers";
  c.names.clear();
  c.factors.clear();
  for (const std::string& n : p.names) {
    if (n == "volume/axial/middle") continue;  // as if the fitted mesh had none
    c.names.push_back(n);
    c.factors.push_back(n == "volume/axial/inner" ? 4.0 : n == "volume/axial/outer" ? 0.25 * 9.0 : 1.5);
  }
  const auto [params, theta] = calibration_parameters(c, "cal.json", base, wall);
  const auto at = std::find(params.names.begin(), params.names.end(), "volume/axial/middle");
  ASSERT_NE(at, params.names.end());
  EXPECT_NEAR(std::exp(theta[at - params.names.begin()]), 3.0, 1e-12);  // sqrt(4 × 2.25)
  Calibration none = c;
  for (std::size_t i = none.names.size(); i-- > 0;) {
    if (none.names[i].rfind("volume/axial/", 0) == 0) {
      none.names.erase(none.names.begin() + static_cast<std::ptrdiff_t>(i));
      none.factors.erase(none.factors.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }
  expect_input_error([&] { calibration_parameters(none, "cal.json", base, wall); },
                     "volume/axial/");
}

TEST(CalibrationFile, AnotherMeshIsRefusedUnlessAGroupCalibrationTransfers) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  TetMesh moved = mesh;
  moved.nodes[5].x() += 1e-6;  // one node 1 µm away: another mesh
  EXPECT_NE(mesh_hash(mesh), mesh_hash(moved));
  EXPECT_EQ(mesh_hash(mesh), mesh_hash(block_mesh(2, 1e-3)));
  const msm::BuiltNetwork base = hybrid(mesh);
  for (const bool per_spring : {false, true}) {
    const Calibration c = make_calibration(mesh, base, per_spring);
    msm::BuiltNetwork on_moved = hybrid(moved);
    expect_input_error(
        [&] {
          apply_calibration(c, "cal.json", on_moved, moved, VesselParams{}, hybrid_spec(), kE,
                            0.45, false);
        },
        "mesh.hash");
    if (per_spring) {
      expect_input_error(
          [&] {
            apply_calibration(c, "cal.json", on_moved, moved, VesselParams{}, hybrid_spec(), kE,
                              0.45, true);
          },
          "cannot transfer");
    } else {
      EXPECT_NO_THROW(apply_calibration(c, "cal.json", on_moved, moved, VesselParams{},
                                        hybrid_spec(), kE, 0.45, true));
    }
  }
  // Another ν or another model is refused too.
  const Calibration c = make_calibration(mesh, base, false);
  msm::BuiltNetwork b = base;
  expect_input_error(
      [&] { apply_calibration(c, "cal.json", b, mesh, VesselParams{}, hybrid_spec(), kE, 0.49, false); },
      "nu = 0.45");
  ModelSpec other = hybrid_spec();
  other.volume_term = false;
  expect_input_error(
      [&] { apply_calibration(c, "cal.json", b, mesh, VesselParams{}, other, kE, 0.45, false); },
      "cal.json: model");
  // A calibration of Golec's rule applied to the homogenised rule's model (another κ and E_s).
  ModelSpec homogenised = hybrid_spec();
  homogenised.volume_moduli = msm::VolumeModuli::homogenised;
  expect_input_error(
      [&] {
        apply_calibration(c, "cal.json", b, mesh, VesselParams{}, homogenised, kE, 0.45, false);
      },
      "cal.json: model.volume_moduli");
  // The rule round-trips through the file; a file without the key is Golec's.
  Calibration h = c;
  h.volume_moduli = "homogenised";
  const auto path = temp_file("homogenised.json");
  write_calibration(path, h);
  EXPECT_EQ(read_calibration(path).volume_moduli, "homogenised");
  write_calibration(path, c);
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  std::string json = text.str();
  const auto at = json.find("\"volume_moduli\"");
  ASSERT_NE(at, std::string::npos);
  json.erase(at, json.find('\n', at) - at);  // `"volume_moduli": "golec",` (not the last member)
  std::ofstream(path) << json;
  EXPECT_EQ(read_calibration(path).volume_moduli, "golec");
}

TEST(CalibrationFile, BadFilesGiveErrorsNamingFileAndKey) {
  const auto path = temp_file("bad.json");
  const auto write = [&](const std::string& text) {
    std::ofstream(path) << text;
  };
  expect_input_error([&] { read_calibration(temp_file("missing.json")); }, "cannot open");
  write("{ not json");
  expect_input_error([&] { read_calibration(path); }, "not valid JSON");
  write(R"({"schema": "other", "version": 1})");
  expect_input_error([&] { read_calibration(path); }, "\"schema\"");
  const TetMesh mesh = block_mesh(1, 1e-3);
  const msm::BuiltNetwork base = hybrid(mesh);
  write_calibration(path, make_calibration(mesh, base, false));
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    return t;
  };
  write(replace("\"hash\"", "\"hush\""));
  expect_input_error([&] { read_calibration(path); }, "\"hash\" missing");
  write(replace("\"kappa\": 1.", "\"kappa\": -1."));
  expect_input_error([&] { read_calibration(path); }, "expected a finite factor > 0");
  write(replace("\"granularity\": \"groups\"", "\"granularity\": \"both\""));
  expect_input_error([&] { read_calibration(path); }, "\"granularity\"");
}

TEST(CalibrationFile, SceneModelsReferToAFileBesideTheScene) {
  const std::string base = R"(
name = "t"
[vessel]
kind = "straight"
[load]
type = "pressure"
magnitudes = [10.0]
[[models]]
name = "cal"
kind = "volume_msm"
volume_term = true
)";
  const Scene s = parse_scene(base + "calibration = \"cal.json\"\ncalibration_transfer = true\n",
                              "/some/dir/scene.toml");
  EXPECT_EQ(s.models[0].calibration, std::filesystem::path("/some/dir/cal.json"));
  EXPECT_TRUE(s.models[0].calibration_transfer);
  expect_input_error([&] { parse_scene(base + "calibration_transfer = true\n", "scene.toml"); },
                     "calibration_transfer");
}
