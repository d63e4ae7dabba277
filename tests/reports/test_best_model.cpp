// The report's best-model table (issue 14, item 6) on a small synthetic results set whose ratios
// are worked out by hand, and the natural-frequency section read back from a results file.
#include <gtest/gtest.h>

#include "reports/best_model.hpp"
#include "reports/report.hpp"

using namespace vessel::reports;

namespace {

OutcomeRow row(const std::string& model, const std::string& kind, const std::string& detail,
               double nu, int level, double magnitude, double relative_l2, double solve_s,
               bool ok = true) {
  OutcomeRow o;
  o.model = model;
  o.kind = kind;
  o.detail = detail;
  o.poisson_ratio = nu;
  o.level = level;
  o.magnitude = magnitude;
  o.ok = ok;
  o.relative_l2 = relative_l2;
  o.solve_seconds = solve_s;
  o.max_mm = relative_l2;
  return o;
}

/// Scene s1: budget load 5e-4 N (the representative load), ν 0.3 at levels 0 and 1, ν 0.5 at
/// level 0; scene s2: only P1.
ResultsFile synthetic() {
  ResultsFile r;
  r.path = "results.json";
  SceneRows s;
  s.name = "s1";
  s.load_unit = "N";
  s.model_levels = {0, 1};
  s.budget_magnitude = 5e-4;
  s.references.push_back({0.3, "P2", 1, 100, 1.0, 1.0});
  s.references.push_back({0.5, "Taylor-Hood", 1, 100, 1.0, 1.0});
  const double L = 5e-4;
  // ν = 0.3, level 0: B (0.25) beats A (0.50); C failed (its 0 error must not count); P2 is FEM.
  s.outcomes = {row("p1", "fem", "P1, direct (CHOLMOD)", 0.3, 0, L, 0.10, 0.40),
                row("p2", "fem", "P2, direct (CHOLMOD)", 0.3, 0, L, 0.01, 2.0),
                row("A", "volume_msm", "", 0.3, 0, L, 0.50, 0.02),
                row("B", "surface_msm", "", 0.3, 0, L, 0.25, 0.08),
                // the P1 tet models beat B but are FEM, not mass-spring models
                row("R", "corotational_fem", "corotational P1", 0.3, 0, L, 0.10, 0.05),
                row("X", "xpbd_fem", "XPBD stable neo-Hookean P1", 0.3, 0, L, 0.12, 0.05),
                row("C", "volume_msm", "", 0.3, 0, L, 0.0, 0.001, false),
                // the edge-pair model (P1 on the edges) beats B but is shown apart, not as best
                row("E", "volume_msm",
                    "tetrahedral edges (seed 001) coupled in tetrahedron-sharing edge pairs", 0.3,
                    0, L, 0.11, 0.04),
                // another load: ignored (A would win there)
                row("A", "volume_msm", "", 0.3, 0, 1e-3, 0.001, 0.02),
                row("p1", "fem", "P1, direct (CHOLMOD)", 0.3, 0, 1e-3, 0.10, 0.40),
                // ν = 0.3, level 1: A and B tie at 0.04; B is faster
                row("p1", "fem", "P1, direct (CHOLMOD)", 0.3, 1, L, 0.05, 1.6),
                row("A", "volume_msm", "", 0.3, 1, L, 0.04, 0.4),
                row("B", "surface_msm", "", 0.3, 1, L, 0.04, 0.2),
                // ν = 0.5, level 0: P1 failed (the element cannot represent it)
                row("p1", "fem", "", 0.5, 0, L, 0.0, 0.0, false),
                row("A", "volume_msm", "", 0.5, 0, L, 0.30, 0.01)};
  r.scenes.push_back(s);
  SceneRows s2;
  s2.name = "s2";
  s2.load_unit = "Pa";
  s2.model_levels = {0};
  s2.references.push_back({0.45, "P2", 1, 100, 1.0, 1.0});
  s2.outcomes = {row("p1", "fem", "P1, direct (CHOLMOD)", 0.45, 0, 10.0, 0.2, 0.5)};
  r.scenes.push_back(s2);
  return r;
}

}  // namespace

TEST(BestModel, RatiosToP1OnTheSameLevelByHand) {
  const std::vector<BestModelRow> rows = best_model_rows(synthetic());
  ASSERT_EQ(rows.size(), 4u);
  // s1, ν 0.3, level 0: B; 0.25 / 0.10 = 2.5, 0.08 / 0.40 = 0.2.
  EXPECT_EQ(rows[0].scene, "s1");
  EXPECT_EQ(rows[0].level, 0);
  EXPECT_DOUBLE_EQ(rows[0].magnitude, 5e-4);
  EXPECT_EQ(rows[0].best_model, "B");
  ASSERT_TRUE(rows[0].error_ratio && rows[0].time_ratio);
  EXPECT_DOUBLE_EQ(*rows[0].error_ratio, 2.5);
  EXPECT_DOUBLE_EQ(*rows[0].time_ratio, 0.2);
  EXPECT_EQ(rows[0].p1_model.value_or(""), "p1");
  // Its edge-pair model apart: 0.11 / 0.10 = 1.1, 0.04 / 0.40 = 0.1.
  EXPECT_EQ(rows[0].edge_pair_model, "E");
  ASSERT_TRUE(rows[0].edge_pair_error_ratio && rows[0].edge_pair_time_ratio);
  EXPECT_DOUBLE_EQ(*rows[0].edge_pair_error_ratio, 0.11 / 0.10);
  EXPECT_DOUBLE_EQ(*rows[0].edge_pair_time_ratio, 0.04 / 0.40);
  EXPECT_FALSE(rows[1].edge_pair_error_ratio.has_value());
  // level 1: the tie at 0.04 goes to the faster B; 0.04 / 0.05 = 0.8, 0.2 / 1.6 = 0.125.
  EXPECT_EQ(rows[1].level, 1);
  EXPECT_EQ(rows[1].best_model, "B");
  EXPECT_DOUBLE_EQ(*rows[1].error_ratio, 0.8);
  EXPECT_DOUBLE_EQ(*rows[1].time_ratio, 0.125);
  // ν 0.5: A is best, P1 failed: no ratios.
  EXPECT_DOUBLE_EQ(rows[2].poisson_ratio, 0.5);
  EXPECT_EQ(rows[2].best_model, "A");
  EXPECT_FALSE(rows[2].p1_model.has_value());
  EXPECT_FALSE(rows[2].error_ratio.has_value());
  // s2: P1 alone, no mass-spring model.
  EXPECT_EQ(rows[3].scene, "s2");
  EXPECT_TRUE(rows[3].best_model.empty());
  EXPECT_FALSE(rows[3].error_ratio.has_value());

  const Table t = best_model_table(rows);
  ASSERT_EQ(t.rows.size(), 4u);
  EXPECT_EQ(t.rows[0][4], "B");
  EXPECT_EQ(t.rows[0][7], "2.5");
  EXPECT_EQ(t.rows[0][10], "0.2");
  EXPECT_EQ(t.rows[0][11], "1.1");
  EXPECT_EQ(t.rows[0][12], "0.1");
  EXPECT_EQ(t.rows[1][11], "–");
  EXPECT_EQ(t.rows[0][3], "0.5 mN");
  EXPECT_EQ(t.rows[2][6], "no P1");
  EXPECT_EQ(t.rows[2][7], "–");
  EXPECT_EQ(t.rows[3][4], "none finished");
}

TEST(BestModel, TheReportCarriesTheTable) {
  const Document doc = build_report(synthetic(), std::nullopt, "test");
  const std::string md = doc.markdown_text("figures");
  EXPECT_NE(md.find("## Best mass-spring model against P1"), std::string::npos);
  EXPECT_NE(md.find("| s1 | 0.3 | 1 | 0.5 mN | B | 0.04 | 0.05 | 0.8 | 0.2 | 1.6 | 0.125 | – | – |"),
            std::string::npos)
      << md;
}

TEST(NaturalFrequencySection, ReadBackFromResultsAndDrawn) {
  // A results file with a modes block by hand: the reference 10 and 20 Hz, a model 8 and 30 Hz
  // (ratios 0.8 and 1.5 as the harness writes them), one that failed.
  const char* text = R"({"schema": "vesselverify.results", "schema_version": 2,
    "date": "2026-11-24T20:00:00Z", "command": "vesselverify run x.toml",
    "machine": {"host": "h", "hardware_threads": 2}, "build": {"compiler": "gcc"},
    "scenes": [{"name": "m", "vessel": "tube", "load": "contact", "load_unit": "N",
      "model_levels": [0], "reference_level": 1, "seconds": 1.0, "references": [],
      "outcomes": [],
      "modes": {"count": 2,
        "reference": [{"model": "reference", "kind": "fem", "detail": "P2, displacement formulation, consistent mass",
                       "poisson_ratio": 0.45, "level": 1, "ok": true, "dofs": 300, "seconds": 2.0,
                       "frequencies_hz": [10.0, 20.0], "mechanisms": 0}],
        "models": [{"model": "springs", "kind": "volume_msm", "detail": "d", "poisson_ratio": 0.45,
                    "level": 0, "ok": true, "dofs": 90, "seconds": 0.1,
                    "frequencies_hz": [8.0, 30.0], "mechanisms": 0, "ratio_to_reference": [0.8, 1.5]},
                   {"model": "broken", "kind": "volume_msm", "detail": "d", "poisson_ratio": 0.45,
                    "level": 0, "ok": false, "dofs": 0, "seconds": 0.0, "failure": "not PSD"}]}}]})";
  const ResultsFile r = parse_results(text, "r.json");
  ASSERT_EQ(r.scenes.size(), 1u);
  const SceneRows& s = r.scenes[0];
  ASSERT_EQ(s.reference_modes.size(), 1u);
  ASSERT_EQ(s.model_modes.size(), 2u);
  EXPECT_EQ(s.reference_modes[0].frequencies_hz, (std::vector<double>{10.0, 20.0}));
  EXPECT_EQ(s.model_modes[0].ratio_to_reference, (std::vector<double>{0.8, 1.5}));
  EXPECT_FALSE(s.model_modes[1].ok);
  EXPECT_EQ(s.model_modes[1].failure, "not PSD");
  const Document doc = build_report(r, std::nullopt, "test");
  const std::string md = doc.markdown_text("figures");
  EXPECT_NE(md.find("### Natural frequencies"), std::string::npos);
  EXPECT_NE(md.find("| springs | 0.45 | 0 | 8, 30 | 0.8, 1.5 | 0 | 90 |"), std::string::npos) << md;
  EXPECT_NE(md.find("**failed**: not PSD"), std::string::npos);
  EXPECT_NE(md.find("m_natural_frequencies.svg"), std::string::npos);
}
