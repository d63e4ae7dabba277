// Every study's JSON document against its JSON Schema, and the Markdown the report renders from
// that document: the recommendation and the calibration study built by hand here, checked
// against hand-written expectations (the numbers below are the inputs, formatted by hand).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "../../schema_check.hpp"
#include "../../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/studies/calibrate/calibrate.hpp"
#include "verification/studies/recommend/recommend.hpp"

using namespace vessel;

namespace {

nlohmann::json schema(const std::string& path) { return nlohmann::json::parse(test::read_text(path)); }

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(SchemaCheck, NamesAMissingKeyAWrongTypeAConstAnEnumAndABadItem) {
  const auto s = nlohmann::json::parse(R"({
    "type": "object", "required": ["schema", "n", "kind"],
    "properties": {"schema": {"const": "x"}, "n": {"type": "integer", "minimum": 1},
                   "kind": {"enum": ["a", "b"]},
                   "list": {"type": "array", "items": {"$ref": "#/$defs/item"}}},
    "$defs": {"item": {"type": "object", "required": ["v"], "properties": {"v": {"type": ["number", "null"]}}}}})");
  EXPECT_TRUE(test::schema_problems(nlohmann::json::parse(
                  R"({"schema": "x", "n": 2, "kind": "a", "list": [{"v": 1}, {"v": null}]})"), s)
                  .empty());
  const auto problems = test::schema_problems(
      nlohmann::json::parse(R"({"schema": "y", "n": 0.5, "list": [{"v": "s"}, {}]})"), s);
  const std::string all = test::joined(problems);
  EXPECT_EQ(problems.size(), 6u) << all;
  EXPECT_TRUE(has(all, "$: missing required 'kind'")) << all;
  EXPECT_TRUE(has(all, "$.schema: is \"y\", expected \"x\"")) << all;
  EXPECT_TRUE(has(all, "$.n: is number, expected \"integer\"")) << all;
  EXPECT_TRUE(has(all, "$.n: 0.5 < minimum 1")) << all;
  EXPECT_TRUE(has(all, "$.list[0].v: is string")) << all;
  EXPECT_TRUE(has(all, "$.list[1]: missing required 'v'")) << all;
  EXPECT_FALSE(test::schema_problems(nlohmann::json::parse(R"({"schema": "x", "n": 1, "kind": "c"})"), s)
                   .empty());
}

namespace {

Candidate candidate(const std::string& name, double error, double update, double setup,
                    double roi_radius = 0.0) {
  Candidate c;
  c.name = name;
  c.model = name;
  c.detail = "detail of " + name;
  c.unknowns = 300;
  c.ok = true;
  c.error = error;
  c.update_seconds = update;
  c.setup_seconds = setup;
  c.roi_radius = roi_radius;
  return c;
}

/// A contact scene at 30 Hz with a 0.1 mm tolerance: the whole-vessel candidate (0.05 mm, 20 ms)
/// wins over a slower one, a region of interest is too inaccurate, and one failed with a '|'
/// in its message.
Recommendation hand_recommendation() {
  Recommendation rec;
  rec.scene.name = "hand_scene";
  rec.scene.source = "hand_scene.toml";
  rec.scene.model_levels = {0, 1};
  rec.scene.reference_level = 2;
  rec.scene.load.kind = LoadKind::contact;
  rec.scene.budget.stated = true;
  rec.scene.budget.tolerance = 0.1;
  rec.scene.budget.rate_hz = 30.0;
  ReferenceInfo ref;
  ref.poisson_ratio = 0.45;
  ref.element = "P2";
  ref.level = 2;
  ref.budget_magnitude = 0.05;  // N: 50 mN
  rec.result.references = {ref};
  rec.candidates = {candidate("whole @ L0", 0.05, 0.020, 0.002),
                    candidate("slow @ L1", 0.04, 0.030, 0.004),
                    candidate("roi @ L0", 0.5, 0.001, 0.001, 0.004)};
  Candidate failed = candidate("broken @ L0", 0.0, 0.0, 0.0);
  failed.ok = false;
  failed.failure = "diverged | step 3";
  rec.candidates.push_back(failed);
  rec.selection = select_model(rec.candidates, 0.1, rec.scene.budget.seconds_per_update());
  return rec;
}

}  // namespace

TEST(RecommendDocument, ConformsToItsSchemaAndTheReportRendersRecommendMdFromIt) {
  const Recommendation rec = hand_recommendation();
  ASSERT_EQ(rec.selection.recommended, std::optional<std::size_t>(0));
  const std::string text = recommendation_json(rec, "vesselverify recommend hand_scene.toml", ".");
  const auto j = nlohmann::json::parse(text);
  const auto problems = test::schema_problems(j, schema(VESSEL_RECOMMEND_SCHEMA));
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  EXPECT_EQ(j["load_unit"], "N");
  EXPECT_EQ(j["loads"][0]["reference_element"], "P2");
  EXPECT_FALSE(j["candidates"][0].contains("roi_radius_mm"));
  EXPECT_DOUBLE_EQ(j["candidates"][2]["roi_radius_mm"].get<double>(), 4.0);

  const std::string md =
      reports::recommendation_markdown(reports::parse_recommend(text, "recommend.json"));
  EXPECT_EQ(md.rfind("## Model recommendation: hand_scene at 30 Hz\n", 0), 0u) << md;
  EXPECT_TRUE(has(md, "at ν = 0.45 the load is 50 mN (reference P2, level 2)")) << md;
  EXPECT_TRUE(has(md, "    vesselverify recommend hand_scene.toml\n")) << md;
  EXPECT_TRUE(has(md, "**Recommended: `whole @ L0`** (detail of whole @ L0): error 0.05 mm, "
                      "20 ms per update, 300 unknowns. Set-up 2 ms, once. The whole vessel (no "
                      "region of interest)."))
      << md;
  // The recommended one is whole-vessel: no separate whole-vessel line.
  EXPECT_FALSE(has(md, "Whole vessel (no region of interest)")) << md;
  // Rows: the winner first, the failure last with dashes and its '|' escaped.
  EXPECT_LT(md.find("| `whole @ L0` |"), md.find("| `slow @ L1` |"));
  EXPECT_TRUE(has(md, "| `broken @ L0` | 300 | – | – | – |  | failed | failed: diverged \\| step 3 |")) << md;
  EXPECT_LT(md.find("| `roi @ L0` |"), md.find("| `broken @ L0` |"));
}

TEST(RecommendDocument, SaysWhenNoWholeVesselCandidateMeetsTheBudget) {
  Recommendation rec = hand_recommendation();
  rec.candidates.erase(rec.candidates.begin(), rec.candidates.begin() + 2);  // roi, broken
  rec.scene.budget.tolerance = 1.0;
  rec.selection = select_model(rec.candidates, 1.0, rec.scene.budget.seconds_per_update());
  ASSERT_EQ(rec.selection.recommended, std::optional<std::size_t>(0));
  const std::string text = recommendation_json(rec, "cmd", ".");
  const std::string md =
      reports::recommendation_markdown(reports::parse_recommend(text, "recommend.json"));
  EXPECT_TRUE(has(md, "**Recommended: `roi @ L0`** (detail of roi @ L0): error 0.5 mm, 1 ms per "
                      "update, 300 unknowns. Set-up 1 ms, once.\n")) << md;
  EXPECT_TRUE(has(md, "No whole-vessel candidate (without a region of interest) meets the budget."))
      << md;
}

namespace {

CalibrationCaseResult calibration_case(const std::string& name, bool training, double p1,
                                       double base, double calibrated) {
  CalibrationCaseResult c;
  c.scene = "tube";
  c.name = name;
  c.training = training;
  c.holds_out = training ? "training" : "other contact point";
  c.kind = LoadKind::contact;
  c.magnitude = 0.05;
  c.point = Vec3(0.01, 0.0, 0.02);
  c.p1.relative_l2 = p1;
  c.base.relative_l2 = base;
  c.calibrated.relative_l2 = calibrated;
  c.p1_solve_seconds = 0.25;
  c.base_update_seconds = 0.0125;
  c.calibrated_update_seconds = 0.0135;
  c.max_strain_reference = 0.0123;
  return c;
}

CalibrationStudy hand_calibration(const std::string& granularity) {
  CalibrationStudy st;
  Calibration& c = st.calibration;
  c.granularity = granularity;
  c.scene = "tube";
  c.model = "volume_hybrid";
  c.poisson_ratio = 0.45;
  c.vessel = "straight tube";
  c.mesh_hash = "0123456789abcdef";
  c.nodes = 100;
  c.springs = 400;
  c.names = {"axial", "kappa", "radial"};
  c.factors = {3.0, 1.0, 2.0};
  c.method = "linearised at rest, L-BFGS";
  c.iterations = 12;
  c.stop_reason = "gradient small";
  c.objective_before = 2.5;
  c.objective_after = 0.5;
  st.fit_seconds = 1.5;
  st.model_detail = "van-gelder + volume term (golec), newton";
  st.cases.push_back(calibration_case("contact θ", true, 0.1, 0.2, 0.05));
  CalibrationCaseResult refused = calibration_case("contact θ+180°", false, 0.1, 0.3, 0.0);
  refused.ok = false;
  refused.failure = "transfer refused";
  st.cases.push_back(refused);
  CalibrationCaseResult again = refused;
  again.name = "contact θ+45°";
  st.cases.push_back(again);
  CalibrationCaseResult no_base = calibration_case("pressure 10 Pa", false, 0.2, 0.0, 0.1);
  no_base.kind = LoadKind::pressure;
  no_base.magnitude = 10.0;
  no_base.base_ok = false;
  no_base.base_failure = "Newton did not converge";
  st.cases.push_back(no_base);
  return st;
}

}  // namespace

TEST(CalibrateDocument, ConformsToItsSchemaAndTheReportRendersTheTablesFromIt) {
  const std::string text = calibration_study_json(hand_calibration("groups"), "vesselverify calibrate x", "cal.json");
  const auto j = nlohmann::json::parse(text);
  const auto problems = test::schema_problems(j, schema(VESSEL_CALIBRATE_SCHEMA));
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  ASSERT_EQ(j["fit"]["parameters"].size(), 3u);
  EXPECT_DOUBLE_EQ(j["fit"]["factors"]["median"].get<double>(), 2.0);
  EXPECT_FALSE(j["cases"][1].contains("calibrated_relative_l2"));
  EXPECT_EQ(j["cases"][3]["load_unit"], "Pa");

  const std::string md = reports::calibration_markdown(reports::parse_calibrate(text, "cal.study.json"));
  EXPECT_EQ(md.rfind("# Calibration of volume_hybrid (tube, groups)\n", 0), 0u) << md;
  EXPECT_TRUE(has(md, "3 parameters, 12 iterations (gradient small), 1.500 s; objective 2.5 → 0.5"))
      << md;
  EXPECT_TRUE(has(md, "| axial | 3.000 |")) << md;
  // Training: P1 0.1, base 0.2, calibrated 0.05, calibrated / P1 = 0.5; strain 1.23 % → "1.2 %".
  EXPECT_TRUE(has(md, "| tube | 0 | contact θ | training | 0.05 N | 0.100 | 0.200 | 0.050 | 0.500 | "
                      "0.0125 | 0.0135 | 0.25 | 1.2 % |")) << md;
  EXPECT_LT(md.find("## Training loads"), md.find("| contact θ |"));
  EXPECT_LT(md.find("## Held-out loads"), md.find("contact θ+180°"));
  EXPECT_TRUE(has(md, "| tube | 0 | contact θ+180° | other contact point | 0.05 N | 0.100 | 0.300 | — | — | 0.0125 | — |"))
      << md;
  EXPECT_TRUE(has(md, "| 10 Pa | 0.200 | — | 0.100 | 0.500 | — | 0.0135 |")) << md;
  // One refusal shared by two cases is said once; the base model's failure on its own case.
  const std::string refusal = "calibrated model not evaluated: transfer refused";
  ASSERT_TRUE(has(md, refusal)) << md;
  EXPECT_EQ(md.find(refusal), md.rfind(refusal)) << md;
  EXPECT_TRUE(has(md, "tube pressure 10 Pa (10 Pa): uncalibrated model not evaluated: Newton did "
                      "not converge")) << md;
}

TEST(CalibrateDocument, PerSpringFitsGiveTheFactorsRangeNotEachFactor) {
  const std::string text = calibration_study_json(hand_calibration("per_spring"), "cmd", "cal.json");
  const auto j = nlohmann::json::parse(text);
  EXPECT_TRUE(test::schema_problems(j, schema(VESSEL_CALIBRATE_SCHEMA)).empty());
  EXPECT_FALSE(j["fit"].contains("parameters"));
  const std::string md = reports::calibration_markdown(reports::parse_calibrate(text, "s.json"));
  EXPECT_TRUE(has(md, "Per-spring factors (kappa included): min 1.000, median 2.000, max 3.000."))
      << md;
  EXPECT_FALSE(has(md, "| axial |")) << md;
}

TEST(CalibrateDocument, AStudyFileWithAMissingFieldIsRefusedNamingIt) {
  auto j = nlohmann::json::parse(calibration_study_json(hand_calibration("groups"), "cmd", "c.json"));
  j["fit"].erase("iterations");
  try {
    (void)reports::parse_calibrate(j.dump(), "bad.study.json");
    FAIL() << "accepted a study without fit.iterations";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "bad.study.json: fit: missing field 'iterations'")) << e.what();
  }
}
