// The stability study's pieces: the refinement-exponent fit on exact power laws, the JSON against
// its schema, and the Markdown section the report renders from that JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "../../schema_check.hpp"
#include "../../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/studies/stability/stability.hpp"

using namespace vessel;

TEST(Stability, LogLogSlopeRecoversTheExponentOfAPowerLaw) {
  const std::vector<double> h{1e-3, 5e-4, 2.5e-4};
  for (double p : {1.0, 0.5, 2.0}) {
    std::vector<double> y;
    for (double x : h) y.push_back(3e-4 * std::pow(x, p));
    EXPECT_NEAR(loglog_slope(h, y), p, 1e-12);
  }
  EXPECT_THROW((void)loglog_slope({1e-3}, {1.0}), InputError);
  EXPECT_THROW((void)loglog_slope({1e-3, 1e-3}, {1.0, 2.0}), InputError);
}

namespace {
StabilityReport sample_report() {
  StabilityReport r;
  r.command_line = "vesselverify stability --quick";
  r.trial_steps = 500;
  CriticalStepRow row;
  row.model = "volume / seed001";
  row.integrator = "verlet";
  row.predicted_dt = 2e-4;
  row.found_dt = 1.99e-4;
  r.rows = {row, row};
  r.rows[1].level = 1;
  r.fits.push_back({"volume / seed001", "verlet", 0.0, {0, 1}, 1.0, 1.0});
  HardCase hc{"x", "A case", "setup", {}, 1.0};
  hc.outcomes.push_back(
      {"FEM | P1", true, true, std::nullopt, "fine | ok", {{"u_contact_mm", 0.1}}});
  hc.outcomes.push_back({"msm", false, std::nullopt, false, "stopped", {{"nan", NAN}}});
  r.hard_cases.push_back(hc);
  TetStepRow explicit_row;
  explicit_row.model = "corotational-p1";
  explicit_row.integrator = "symplectic-euler";
  explicit_row.predicted_dt = 2e-5;
  explicit_row.power_dt = 2.01e-5;
  explicit_row.found_dt = 1.99e-5;
  explicit_row.unstable_dt = 2.0e-5;
  TetStepRow ladder = explicit_row;
  ladder.integrator = "implicit-euler";
  ladder.load = 0.07;
  ladder.predicted_dt = ladder.power_dt = ladder.found_dt = ladder.unstable_dt = NAN;
  ladder.steps_tried = {1e-4, 1e-3};
  ladder.bounded = {true, false};
  ladder.failure = "dt 0.001 s: diverged";
  r.tet_rows = {explicit_row, ladder};
  return r;
}
}  // namespace

namespace {
/// stability.md as the study writes it: the report's section drawn from the study's JSON.
std::string stability_markdown(const StabilityReport& r) {
  return reports::stability_markdown(reports::parse_stability(stability_json(r), "stability.json"));
}
}  // namespace

TEST(Stability, JsonHasEveryFieldItsSchemaRequires) {
  const auto j = nlohmann::json::parse(stability_json(sample_report()));
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_STABILITY_SCHEMA));
  const auto problems = test::schema_problems(j, schema);
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  EXPECT_EQ(j["schema"], schema["properties"]["schema"]["const"]);
  for (const auto& key : schema["required"]) EXPECT_TRUE(j.contains(key)) << key;
  const auto& props = schema["properties"];
  for (const auto& key : props["critical_steps"]["items"]["required"])
    EXPECT_TRUE(j["critical_steps"][0].contains(key)) << key;
  for (const auto& key : props["refinement"]["items"]["required"])
    EXPECT_TRUE(j["refinement"][0].contains(key)) << key;
  const auto& hc = props["hard_cases"]["items"];
  for (const auto& key : hc["required"]) EXPECT_TRUE(j["hard_cases"][0].contains(key)) << key;
  for (const auto& key : hc["properties"]["outcomes"]["items"]["required"])
    EXPECT_TRUE(j["hard_cases"][0]["outcomes"][1].contains(key)) << key;
  EXPECT_TRUE(j["hard_cases"][0]["outcomes"][1]["converged"].is_null());
  EXPECT_TRUE(j["hard_cases"][0]["outcomes"][1]["values"]["nan"].is_null());  // NaN → null
  EXPECT_NEAR(j["critical_steps"][0]["found_over_predicted"].get<double>(), 0.995, 1e-12);
  for (const auto& key : props["tet_critical_steps"]["items"]["required"]) {
    EXPECT_TRUE(j["tet_critical_steps"][1].contains(key)) << key;
  }
  EXPECT_TRUE(j["tet_critical_steps"][1]["found_dt"].is_null());  // NaN → null
  EXPECT_NEAR(j["tet_critical_steps"][0]["found_over_predicted"].get<double>(), 0.995, 1e-12);
}

TEST(Stability, MarkdownIsOneSelfContainedSectionWithTheCommandAndEscapedCells) {
  const std::string md = stability_markdown(sample_report());
  EXPECT_EQ(md.rfind("## Numerical stability\n", 0), 0u);
  EXPECT_EQ(md.find("\n## "), std::string::npos);  // no second top-level section
  EXPECT_NE(md.find("`vesselverify stability --quick`"), std::string::npos);
  EXPECT_NE(md.find("fine \\| ok"), std::string::npos);
  EXPECT_NE(md.find("| volume / seed001 | verlet | 0 | 0,1 | 1 | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| corotational-p1 | symplectic-euler | 0 | 0 | 0 | 0.02 | 0.0201 | 0.0199 | "
                    "0.995 |"),
            std::string::npos)
      << md;
  EXPECT_NE(
      md.find("| corotational-p1 | implicit-euler | 0 | 0 | 70 | – | – | unbounded at 1 ms |"),
      std::string::npos)
      << md;
}

TEST(Stability, WritesBothFilesAtomicallyAndRefusesAnUnwritableDirectory) {
  test::TempDir dir;
  write_stability(dir.path(), sample_report());
  EXPECT_TRUE(std::filesystem::exists(dir / "stability.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "stability.md"));
  test::write_text(dir / "file", "x");
  EXPECT_THROW(write_stability(dir / "file" / "sub", sample_report()), InputError);
}

TEST(Stability, TheStepTableIsTheSameComputedOneRowAtATimeOrInParallel) {
  // Level 0 only, short trials. The search is deterministic, so the table computed on two
  // threads equals the one computed on one, row for row.
  test::TempDir cache;
  StabilityOptions o;
  o.cache_dir = cache.path();
  o.hard_cases = false;
  o.rod_steps = false;  // the vessel table only (test_rod_steps.cpp has the rod's)
  o.tet_steps = false;  // and the springs' (test_tet_steps.cpp has the P1 models')
  o.max_level = 0;
  o.trial_steps = 50;
  o.jobs = 1;
  const StabilityReport one = run_stability(o);
  o.jobs = 2;
  const StabilityReport two = run_stability(o);
  ASSERT_EQ(one.rows.size(), 12u);  // 3 models × 4 integrator configurations
  ASSERT_EQ(two.rows.size(), one.rows.size());
  for (std::size_t i = 0; i < one.rows.size(); ++i) {
    EXPECT_EQ(one.rows[i].model, two.rows[i].model);
    EXPECT_EQ(one.rows[i].integrator, two.rows[i].integrator);
    EXPECT_EQ(one.rows[i].zeta, two.rows[i].zeta);
    EXPECT_EQ(one.rows[i].predicted_dt, two.rows[i].predicted_dt) << i;
    EXPECT_EQ(one.rows[i].found_dt, two.rows[i].found_dt) << i;
    EXPECT_EQ(one.rows[i].trials, two.rows[i].trials) << i;
  }
}

TEST(Stability, HardCasesSideBySideGiveWhatTheyGiveOneAtATime) {
  // Cheap cases, two of them meshing (gmsh is one session at a time across threads), on the
  // meshes of one cache; the long run is timed and runs alone after the others. Every outcome
  // but the measured seconds is deterministic, so two threads must reproduce one, in order.
  test::TempDir cache;
  StabilityOptions o;
  o.cache_dir = cache.path();
  o.max_level = 0;
  o.trial_steps = 50;
  o.long_run_steps = 500;
  o.only_cases = {"zero_length", "long_run", "inverting_load", "tight_bend"};
  o.rod_steps = false;
  o.tet_steps = false;
  o.jobs = 1;
  const StabilityReport one = run_stability(o);
  o.jobs = 2;
  const StabilityReport two = run_stability(o);
  EXPECT_EQ(one.hard_cases_at_a_time, 1);
  EXPECT_EQ(two.hard_cases_at_a_time, 2);
  ASSERT_EQ(one.hard_cases.size(), 4u);
  ASSERT_EQ(two.hard_cases.size(), 4u);
  const std::vector<std::string> order{"inverting_load", "long_run", "tight_bend", "zero_length"};
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(one.hard_cases[c].id, order[c]);
    EXPECT_EQ(two.hard_cases[c].id, order[c]);
    ASSERT_EQ(one.hard_cases[c].outcomes.size(), two.hard_cases[c].outcomes.size()) << order[c];
    for (std::size_t i = 0; i < one.hard_cases[c].outcomes.size(); ++i) {
      const HardCaseOutcome& a = one.hard_cases[c].outcomes[i];
      const HardCaseOutcome& b = two.hard_cases[c].outcomes[i];
      EXPECT_EQ(a.model, b.model);
      EXPECT_EQ(a.finished, b.finished) << a.model;
      EXPECT_EQ(a.converged, b.converged) << a.model;
      EXPECT_EQ(a.bounded, b.bounded) << a.model;
      for (const auto& [key, value] : a.values) {
        if (key == "seconds") continue;
        // Round-off apart: a direct solve's threads (shared among the running cases) change the
        // order of its sums.
        EXPECT_NEAR(value, b.values.at(key), 1e-10 * std::abs(value))
            << order[c] << " " << a.model << " " << key;
      }
    }
  }
  EXPECT_NE(stability_markdown(two).find("ran 2 at a time"), std::string::npos);
  EXPECT_EQ(stability_markdown(one).find("at a time"), std::string::npos);
}

TEST(Stability, ASecondRunReadsTheRowsFromTheOutcomeCacheWithTheirTimings) {
  test::TempDir cache;
  std::ostringstream log;
  OutcomeCache outcomes(cache.path() / "outcomes", false, &log);
  StabilityOptions o;
  o.cache_dir = cache.path();
  o.hard_cases = false;
  o.rod_steps = false;  // the vessel table only (test_rod_steps.cpp has the rod's)
  o.tet_steps = false;
  o.max_level = 0;
  o.trial_steps = 50;
  o.outcome_cache = &outcomes;
  const StabilityReport first = run_stability(o);
  EXPECT_EQ(first.timed_items, 3u);  // one item per model at level 0
  EXPECT_TRUE(first.cached_at.empty());
  const StabilityReport second = run_stability(o);
  EXPECT_EQ(outcomes.statistics().hits, 3);
  ASSERT_EQ(second.cached_at.size(), 3u);
  ASSERT_EQ(second.rows.size(), first.rows.size());
  for (std::size_t i = 0; i < first.rows.size(); ++i) {
    EXPECT_EQ(second.rows[i].model, first.rows[i].model);
    EXPECT_EQ(second.rows[i].found_dt, first.rows[i].found_dt) << i;
    EXPECT_EQ(second.rows[i].guaranteed_dt, first.rows[i].guaranteed_dt) << i;
    EXPECT_EQ(second.rows[i].seconds, first.rows[i].seconds) << i;  // the cached timing
  }
  EXPECT_NE(stability_markdown(second).find("3 of 3 timings from the cache"), std::string::npos);
  EXPECT_EQ(log.str(), "");
}
