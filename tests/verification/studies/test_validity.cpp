// The validity study (issue 17 item 3) on a small problem: the threshold interpolation by hand,
// the measured 1 % crossing against the one the O(load²) difference of the two references
// predicts from two small loads, the largest-load-reached path, and validity.json read back by
// the report with errors naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../../schema_check.hpp"
#include "../../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/vtu_io.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "test_paths.hpp"
#include "verification/studies/validity/validity.hpp"

using namespace vessel;

namespace {

/// A 20 mm tube, level 0, contact at mid-length, clamped ends; the seed 001 volume model.
const char* kScene = R"(name = "validity_test"
[vessel]
kind = "straight"
length = 20.0e-3
mesh = "structured"
level = 0
reference_level = 0
[material]
E = 14.24e3
nu = 0.45
[boundary]
inlet = "clamped"
outlet = "clamped"
[load]
type = "contact"
magnitudes = [1.0e-4]
point = [3.0e-3, 0.0, 10.0e-3]
patch_radius = 1.0e-3
surface = "inner_wall"
[[models]]
name = "volume_mollemans"
kind = "volume_msm"
stiffness = "seed001"
mass = "seed001"
solver = "static"
)";

ValidityOptions small_options() {
  ValidityOptions o;
  o.degree = 1;
  o.reference_level = 0;
  o.ladder = {1e-6, 2e-6, 3e-4, 1e-3, 2e-3, 4e-3};
  return o;
}

}  // namespace

TEST(ThresholdCrossing, InterpolatesLogLinearlyBetweenTheBracketingLoads) {
  // d = 0.005 F² on F = 1, 2, 4: 1 % at F = √2 and 5 % at √10 exactly (a power law is a line in
  // ln d against ln F); 10 % is not reached (d(4) = 8 %); at 0.4 % the first load already
  // exceeds it.
  const std::vector<double> F{1.0, 2.0, 4.0}, d{0.005, 0.02, 0.08};
  const ThresholdCrossing one = threshold_crossing(F, d, 0.01);
  EXPECT_EQ(one.status, "interpolated");
  EXPECT_NEAR(*one.load, std::sqrt(2.0), 1e-12);
  EXPECT_EQ(one.lower, 1.0);
  EXPECT_EQ(one.upper, 2.0);
  EXPECT_NEAR(*threshold_crossing(F, d, 0.05).load, std::sqrt(10.0), 1e-12);
  const ThresholdCrossing ten = threshold_crossing(F, d, 0.10);
  EXPECT_EQ(ten.status, "not_reached");
  EXPECT_FALSE(ten.load.has_value());
  EXPECT_EQ(ten.lower, 4.0);
  const ThresholdCrossing low = threshold_crossing(F, d, 0.004);
  EXPECT_EQ(low.status, "below_ladder");
  EXPECT_EQ(*low.load, 1.0);
  EXPECT_THROW((void)threshold_crossing({2.0, 1.0}, {0.1, 0.2}, 0.15), std::invalid_argument);
  EXPECT_THROW((void)threshold_crossing({1.0}, {}, 0.15), std::invalid_argument);
}

TEST(ValidityLadder, QuickDefaultAndFullLaddersSpanWhatTheyPromise) {
  Scene contact = parse_scene(kScene, "validity_test.toml");
  EXPECT_EQ(default_ladder(contact, false, true), (std::vector<double>{1e-4, 1e-3, 1e-2}));
  const auto standard = default_ladder(contact, false);
  EXPECT_EQ(standard.front(), 1e-4);
  EXPECT_EQ(standard.back(), 7e-2);  // the largest load reached is --full's to find
  EXPECT_EQ(default_ladder(contact, true).back(), 0.14);
  EXPECT_EQ(default_ladder(contact, true, true).back(), 0.14);  // --full wins
  Scene gravity = contact;
  gravity.load.kind = LoadKind::gravity;
  gravity.load.magnitudes = {0.5, 2.0};
  EXPECT_EQ(default_ladder(gravity, false, true), (std::vector<double>{2.0}));
  EXPECT_EQ(default_ladder(gravity, false), (std::vector<double>{1.0, 2.0}));
}

TEST(ValidityStudy, TheOnePercentCrossingIsWhatTheLoadSquaredDifferencePredicts) {
  const Scene s = parse_scene(kScene, "validity_test.toml");
  const ValidityScene v = run_validity_scene(s, small_options());
  ASSERT_TRUE(v.completed) << v.stop_reason;
  ASSERT_EQ(v.rows.size(), 6u);
  // At small loads the references differ by O(F²): the relative difference doubles with F.
  const double ratio = v.rows[1].qoi_difference / v.rows[0].qoi_difference;
  std::cout << "  QoI difference " << v.rows[0].qoi_difference << " at 1 µN, "
            << v.rows[1].qoi_difference << " at 2 µN (ratio " << ratio << ")\n";
  EXPECT_NEAR(ratio, 2.0, 0.02);
  // So d ≈ c F, and 1 % is reached at 0.01 / c: the ladder's interpolated crossing agrees.
  const double predicted = v.rows[0].magnitude * 0.01 / v.rows[0].qoi_difference;
  ASSERT_EQ(v.qoi_limits.size(), 3u);
  ASSERT_EQ(v.qoi_limits[0].status, "interpolated");
  std::cout << "  1 % crossing: predicted " << predicted << " N, measured "
            << *v.qoi_limits[0].load << " N (between " << v.qoi_limits[0].lower << " and "
            << v.qoi_limits[0].upper << ")\n";
  EXPECT_NEAR(*v.qoi_limits[0].load / predicted, 1.0, 0.1);
  // Every row has the model, judged against the finite-strain reference.
  for (const ValidityRow& r : v.rows) {
    ASSERT_EQ(r.models.size(), 1u);
    EXPECT_TRUE(r.models[0].ok) << r.models[0].failure;
    EXPECT_GT(r.models[0].relative_l2, 0.0);
  }
  // The lumen gap: at 1 µN the wall has moved by under 1 µm (the contact point by 0.5 µm), so it
  // is the rest value to 1 µm, at least the inner radius (the pairs' rest distance) and at most
  // the diameter; it narrows as the load grows.
  ASSERT_TRUE(v.rows.front().wall_gap_mm.has_value());
  EXPECT_GE(*v.rows.front().wall_gap_mm, 3.0 - 1e-3);
  EXPECT_LE(*v.rows.front().wall_gap_mm, 6.0);
  EXPECT_LT(*v.rows.back().wall_gap_mm, *v.rows.front().wall_gap_mm);
  // The continuation's cost is recorded and cumulative.
  EXPECT_GT(v.newton_iterations, 0);
  EXPECT_EQ(v.rows.back().newton_iterations, v.newton_iterations);
  EXPECT_GE(v.load_steps, 6);
}

TEST(ValidityStudy, TheModelsFieldsAtTheLargestLoadAreItsErrorsAgainstTheFiniteStrainOne) {
  const Scene s = parse_scene(kScene, "validity_test.toml");
  ValidityOptions o = small_options();
  o.ladder = {1e-4, 1e-3};
  const test::TempDir scratch;
  const std::filesystem::path& dir = scratch.path();
  o.fields_dir = dir / "validity_fields";
  ValidityStudy study;
  study.scenes = {run_validity_scene(s, o)};
  const ValidityScene& v = study.scenes[0];
  ASSERT_EQ(v.rows.size(), 2u);
  EXPECT_TRUE(v.rows[0].models[0].fields_file.empty());  // the largest load only
  const ValidityModelError& e = v.rows[1].models[0];
  ASSERT_TRUE(e.ok) << e.failure;
  EXPECT_EQ(e.fields_file, o.fields_dir / "validity_test" / "volume_mollemans_load0.001.vtu");
  const VtuData vtu = read_vtu(e.fields_file);
  const VtuField* um = VtuData::find(vtu.point_fields, "displacement_model_m");
  const VtuField* ur = VtuData::find(vtu.point_fields, "displacement_reference_m");
  const VtuField* err = VtuData::find(vtu.point_fields, "error_magnitude_mm");
  ASSERT_TRUE(um && ur && err);
  double largest = 0.0, nearest = 1e300;
  std::size_t q = 0;
  for (std::size_t i = 0; i < vtu.points.size(); ++i) {
    const Vec3 d(um->values[3 * i] - ur->values[3 * i], um->values[3 * i + 1] - ur->values[3 * i + 1],
                 um->values[3 * i + 2] - ur->values[3 * i + 2]);
    EXPECT_NEAR(err->values[i], d.norm() * 1e3, 1e-12);
    largest = std::max(largest, err->values[i]);
    const double to_qoi = (vtu.points[i] - Vec3(3e-3, 0.0, 10e-3)).norm();
    if (to_qoi < nearest) {
      nearest = to_qoi;
      q = i;
    }
  }
  // The file holds the model and the reference the row judged: its largest error, and at the
  // QoI node the model's displacement and the error there.
  EXPECT_NEAR(largest, e.max_error_mm, 1e-9 * e.max_error_mm);
  const Vec3 model_at_q(um->values[3 * q], um->values[3 * q + 1], um->values[3 * q + 2]);
  EXPECT_NEAR(model_at_q.norm() * 1e3, e.qoi_model_mm, 1e-9 * e.qoi_model_mm);
  EXPECT_NEAR(err->values[q], e.qoi_error_mm, 1e-9 * e.qoi_error_mm);
  // validity.json names the file relative to its own folder.
  write_validity_json(study, dir / "validity.json");
  const auto j = nlohmann::json::parse(std::ifstream(dir / "validity.json"));
  const auto& written = j["scenes"][0]["rows"][1]["models"][0];
  ASSERT_TRUE(written.contains("fields")) << written.dump();
  EXPECT_EQ(written["fields"], "validity_fields/validity_test/volume_mollemans_load0.001.vtu");
  EXPECT_FALSE(j["scenes"][0]["rows"][0]["models"][0].contains("fields"));
  std::filesystem::remove_all(dir);
}

TEST(ValidityStudy, ANewtonFailureEndsTheRowsAtTheLargestLoadReached) {
  // One Newton iteration per step never reaches the tolerance (after the linear predictor the
  // residual is O(F²), not round-off): no load is reached, there are no rows, and the reason is
  // kept with the largest load reached, 0.
  const Scene s = parse_scene(kScene, "validity_test.toml");
  ValidityOptions o = small_options();
  o.ladder = {1e-6, 1.0};
  o.finite.max_newton_iterations = 1;
  const ValidityScene v = run_validity_scene(s, o);
  EXPECT_FALSE(v.completed);
  EXPECT_EQ(v.largest_load, 0.0);
  EXPECT_TRUE(v.rows.empty());
  for (const auto& c : v.qoi_limits) EXPECT_FALSE(c.load.has_value());
  EXPECT_NE(v.stop_reason.find("no equilibrium found beyond load factor"), std::string::npos)
      << v.stop_reason;
}

TEST(ValidityStudy, TheCacheGivesTheSameRowsOnASecondRun) {
  const Scene s = parse_scene(kScene, "validity_test.toml");
  const test::TempDir scratch;
  const std::filesystem::path& dir = scratch.path();
  std::ostringstream log;
  fem::SolutionCache cache(dir, &log);
  ValidityOptions o = small_options();
  o.ladder = {1e-4, 1e-3};
  o.cache = &cache;
  const ValidityScene first = run_validity_scene(s, o);
  const ValidityScene second = run_validity_scene(s, o);
  EXPECT_FALSE(first.finite_from_cache);
  EXPECT_TRUE(second.finite_from_cache);
  ASSERT_EQ(first.rows.size(), second.rows.size());
  for (std::size_t k = 0; k < first.rows.size(); ++k) {
    EXPECT_EQ(first.rows[k].finite_qoi_mm, second.rows[k].finite_qoi_mm);
    EXPECT_EQ(first.rows[k].l2_difference, second.rows[k].l2_difference);
  }
  // Another ladder is another continuation: a miss.
  o.ladder = {1e-4, 2e-3};
  EXPECT_FALSE(run_validity_scene(s, o).finite_from_cache);
}

TEST(ValidityFile, WrittenThenReadBackByTheReportWithBadFieldsNamed) {
  ValidityStudy study;
  study.command = "vesselverify validity x.toml";
  ValidityScene v;
  v.scene = "x";
  v.load_kind = "contact";
  v.load_unit = "N";
  v.element = "P2";
  v.dofs = 10;
  v.ladder = {1e-3, 2e-3};
  v.models = {{"m", "detail", 0, 5}};
  v.completed = false;
  v.largest_load = 1.5e-3;
  v.stop_reason = "no equilibrium";
  v.self_contact = true;
  v.newton_iterations = 7;
  ValidityRow r;
  r.magnitude = 1e-3;
  r.qoi_difference = 0.02;
  r.wall_gap_mm = 3.5;
  r.models = {{"m", true, "", 0.5, 1.0, 0.1, 0.2, 0.3, 4}};
  v.rows = {r};
  v.qoi_limits = {threshold_crossing({1e-3}, {0.02}, 0.01),
                  threshold_crossing({1e-3}, {0.02}, 0.05)};
  v.l2_limits = v.qoi_limits;
  study.scenes = {v};
  const test::TempDir scratch;
  const std::filesystem::path& dir = scratch.path();
  write_validity_json(study, dir / "validity.json");
  const reports::ValidityFile f = reports::read_validity(dir / "validity.json");
  ASSERT_EQ(f.scenes.size(), 1u);
  const auto& e = f.scenes[0];
  EXPECT_EQ(e.largest_load, 1.5e-3);
  EXPECT_FALSE(e.completed);
  EXPECT_EQ(e.stop_reason, "no equilibrium");
  EXPECT_TRUE(e.self_contact);
  EXPECT_EQ(e.newton_iterations, 7);
  ASSERT_EQ(e.rows.size(), 1u);
  EXPECT_EQ(e.rows[0].qoi_difference, 0.02);
  EXPECT_EQ(e.rows[0].wall_gap_mm, 3.5);
  EXPECT_EQ(e.rows[0].models[0].relative_l2, 0.5);
  EXPECT_EQ(e.qoi_limits[0].status, "below_ladder");
  EXPECT_EQ(e.qoi_limits[1].status, "not_reached");
  EXPECT_EQ(e.models, std::vector<std::string>{"m"});

  // A missing field, a wrong status and another schema are refused naming what is wrong.
  std::ifstream in(dir / "validity.json");
  const nlohmann::json good = nlohmann::json::parse(in);
  std::ifstream schema_in(VESSEL_VALIDITY_SCHEMA);
  const auto problems = test::schema_problems(good, nlohmann::json::parse(schema_in));
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  auto refused = [&](nlohmann::json j) {
    try {
      (void)reports::parse_validity(j.dump(), "bad.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  nlohmann::json j = good;
  j["scenes"][0]["rows"][0].erase("qoi_difference");
  const std::string missing = refused(j);
  EXPECT_NE(missing.find("bad.json"), std::string::npos) << missing;
  EXPECT_NE(missing.find("scenes[0].rows[0]"), std::string::npos) << missing;
  EXPECT_NE(missing.find("'qoi_difference'"), std::string::npos) << missing;
  j = good;
  j["scenes"][0]["qoi_limits"][0]["status"] = "maybe";
  EXPECT_NE(refused(j).find("'status' is 'maybe'"), std::string::npos) << refused(j);
  j = good;
  j["scenes"][0]["continuation"].erase("largest_load");
  EXPECT_NE(refused(j).find("continuation: missing field 'largest_load'"), std::string::npos)
      << refused(j);
  j = good;  // a file from before the self-contact check: read, its stop not called self-contact
  j["scenes"][0]["continuation"].erase("self_contact");
  EXPECT_FALSE(reports::parse_validity(j.dump(), "old.json").scenes[0].self_contact);
  j = good;
  j["schema"] = "vesselverify.results";
  EXPECT_NE(refused(j).find("vesselverify.validity"), std::string::npos) << refused(j);
}

TEST(ValidityFile, TheReportSectionShowsTheLimitsAndTheLargestLoadReached) {
  reports::ValidityFile f;
  f.command = "vesselverify validity s.toml";
  reports::ValiditySceneEntry s;
  s.scene = "contact_straight";
  s.load_kind = "contact";
  s.load_unit = "N";
  s.element = "P2";
  s.models = {"surface_seed000"};
  s.completed = false;
  s.largest_load = 0.0625;
  s.stop_reason = "no equilibrium found beyond load factor 0.0625";
  s.newton_iterations = 51;
  s.qoi_limits = {{0.01, "interpolated", 4e-4, 3e-4, 1e-3}, {0.05, "not_reached", {}, 0.05, 0.05}};
  s.l2_limits = s.qoi_limits;
  reports::ValidityRowEntry r;
  r.magnitude = 0.05;
  r.models = {{"surface_seed000", true, "", 0.71, 2.0, 1.5, 0.3}};
  s.rows = {r};
  f.scenes = {s};
  reports::Document doc;
  reports::validity_section(doc, f);
  const std::string md = doc.markdown_text("figures");
  EXPECT_NE(md.find("## Limit of the linear reference"), std::string::npos) << md;
  EXPECT_NE(md.find("**stopped: the largest load reached is 62.5 mN**"), std::string::npos) << md;
  EXPECT_NE(md.find("| 1 % | 0.4 mN (between 0.3 mN and 1 mN) |"), std::string::npos) << md;
  EXPECT_NE(md.find("not reached up to 50 mN"), std::string::npos) << md;
  EXPECT_NE(md.find("surface_seed000: rel. L2 / QoI error (mm)"), std::string::npos) << md;
  EXPECT_NE(md.find("| 0.71 / 1.5 |"), std::string::npos) << md;

  // Stopped where the wall would pass through itself: said so, not as a Newton failure.
  f.scenes[0].self_contact = true;
  reports::Document contact;
  reports::validity_section(contact, f);
  const std::string cmd = contact.markdown_text("figures");
  EXPECT_NE(cmd.find("**stopped where the wall would touch itself: the largest load reached "
                     "without the wall passing through itself is 62.5 mN**"),
            std::string::npos)
      << cmd;
  EXPECT_EQ(cmd.find("**stopped: the largest load"), std::string::npos) << cmd;
}

// Corotational P1 on the reference's own mesh and element (P1, level 0), judged against the
// finite-strain reference: at 1 µN it is that reference to first order (its QoI error far below
// 0.1 %); at 4 mN, where the wall turns, its error is smaller than the linear reference's own
// difference from the finite-strain one (the rotations linear P1 lacks).
TEST(ValidityStudy, CorotationalP1IsJudgedAgainstTheFiniteStrainReference) {
  const Scene s = parse_scene(std::string(kScene) + R"(
[[models]]
name = "corotational"
kind = "corotational_fem"
)",
                              "validity_test.toml");
  ValidityOptions o = small_options();
  o.ladder = {1e-6, 1e-3, 4e-3};
  const ValidityScene v = run_validity_scene(s, o);
  ASSERT_TRUE(v.completed) << v.stop_reason;
  ASSERT_EQ(v.rows.size(), 3u);
  ASSERT_EQ(v.models.size(), 2u);  // the seed model and corotational P1
  for (const ValidityRow& r : v.rows) {
    ASSERT_EQ(r.models.size(), 2u);
    const ValidityModelError& e = r.models[1];
    EXPECT_EQ(e.model, "corotational");
    ASSERT_TRUE(e.ok) << e.failure;
    std::cout << "  " << r.magnitude << " N: corotational QoI error " << e.qoi_relative
              << ", linear reference's difference " << r.qoi_difference << "\n";
  }
  EXPECT_LT(v.rows.front().models[1].qoi_relative, 1e-3);
  EXPECT_LT(v.rows.back().models[1].qoi_relative, v.rows.back().qoi_difference);
}

// Linear P1, corotational P1 and XPBD FEM on the reference's own mesh and element (P1, level 0),
// judged against the finite-strain reference and timed. Linear P1's row is the linear
// reference's own difference from the finite-strain one (the same element on the same mesh,
// reached through the study's reference solve on one path and the model row on the other). XPBD
// FEM's steady state is its stable neo-Hookean energy's equilibrium, whose small-strain limit is
// the material's: at 1 µN it is the reference to first order, and at 4 mN, where the wall turns,
// it is nearer the finite-strain reference than linear P1. Its time per update is its per-step
// cost × the steps a period holds: ⌈1 ms / 0.1 ms⌉ = 10 at 1 kHz, ⌈33.3 ms / 0.1 ms⌉ = 334 at 30 Hz.
TEST(ValidityStudy, LinearCorotationalAndXpbdP1AreJudgedAndTimed) {
  const Scene s = parse_scene(std::string(kScene) + R"(
[[models]]
name = "p1"
kind = "fem"
degree = 1
[[models]]
name = "corotational"
kind = "corotational_fem"
[[models]]
name = "xpbd"
kind = "xpbd_fem"
)",
                              "validity_test.toml");
  ValidityOptions o = small_options();
  o.ladder = {1e-6, 1e-3, 4e-3};
  o.time_updates = true;
  const ValidityScene v = run_validity_scene(s, o);
  ASSERT_TRUE(v.completed) << v.stop_reason;
  ASSERT_EQ(v.rows.size(), 3u);
  ASSERT_EQ(v.models.size(), 4u);  // the seed model, linear, corotational and XPBD P1
  for (const ValidityRow& r : v.rows) {
    ASSERT_EQ(r.models.size(), 4u);
    for (const ValidityModelError& e : r.models) {
      ASSERT_TRUE(e.ok) << e.model << ": " << e.failure;
      ASSERT_TRUE(e.timing.has_value()) << e.model;
      EXPECT_GT(e.timing->update_seconds, 0.0) << e.model;
      std::cout << "  " << r.magnitude << " N: " << e.model << " rel. L2 " << e.relative_l2
                << ", QoI " << e.qoi_relative << ", update " << e.timing->update_seconds
                << " s (" << e.timing->steps << " steps)\n";
    }
    const ValidityModelError& p1 = r.models[1];
    EXPECT_EQ(p1.model, "p1");
    EXPECT_NEAR(p1.relative_l2, r.l2_difference, 1e-9 + 1e-6 * r.l2_difference);
    const ValidityModelError& spring = r.models[0];
    EXPECT_EQ(spring.timing->steps, 0);
    EXPECT_EQ(spring.timing->update_seconds_30hz, spring.timing->update_seconds);
    const ValidityTiming& xt = *r.models[3].timing;
    EXPECT_EQ(r.models[3].model, "xpbd");
    EXPECT_GT(xt.steps, 0);
    EXPECT_DOUBLE_EQ(xt.update_seconds_1khz, xt.update_seconds / xt.steps * 10.0);
    EXPECT_DOUBLE_EQ(xt.update_seconds_30hz, xt.update_seconds / xt.steps * 334.0);
  }
  EXPECT_LT(v.rows.front().models[3].qoi_relative, 1e-3);
  EXPECT_LT(v.rows.back().models[3].relative_l2, 0.5 * v.rows.back().models[1].relative_l2);

  // validity.json carries the timings (what scripts/measure_fem_models_vs_springs.py reads).
  ValidityStudy study;
  study.scenes = {v};
  const test::TempDir scratch;
  const std::filesystem::path& dir = scratch.path();
  write_validity_json(study, dir / "validity.json");
  std::ifstream in(dir / "validity.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json& xj = j["scenes"][0]["rows"][2]["models"][3];
  EXPECT_EQ(xj["model"], "xpbd");
  EXPECT_EQ(xj["timing"]["steps"].get<long>(), v.rows[2].models[3].timing->steps);
  EXPECT_EQ(xj["timing"]["update_seconds_1khz"].get<double>(),
            v.rows[2].models[3].timing->update_seconds_1khz);
}
