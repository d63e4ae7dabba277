// The report generator and the gate: plots' ticks and Pareto fronts against hand-worked cases,
// results files read back with clear errors, and the gate's verdicts on constructed baselines.
#include <gtest/gtest.h>

#include <cmath>

#include "meshes/errors.hpp"
#include "reports/document.hpp"
#include "reports/gate.hpp"
#include "reports/report.hpp"
#include "reports/representative_load.hpp"
#include "reports/svg_plot.hpp"

using namespace vessel;
using namespace vessel::reports;

namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

OutcomeRow outcome(const std::string& model, double magnitude, double max_mm, double solve_s,
                   bool beyond = false) {
  OutcomeRow o;
  o.model = model;
  o.kind = "volume_msm";
  o.magnitude = magnitude;
  o.poisson_ratio = 0.45;
  o.ok = true;
  o.max_mm = max_mm;
  o.rms_mm = max_mm / 2;
  o.relative_l2 = 0.1;
  o.solve_seconds = solve_s;
  o.qoi_mm = 10 * magnitude;
  o.qoi_reference_mm = 12 * magnitude;
  o.beyond_linear_regime = beyond;
  o.profile_s_mm = {0, 20, 40};
  o.profile_model_mm = {0, -0.1, 0};
  o.profile_reference_mm = {0, -0.12, 0};
  return o;
}

ResultsFile results_with(std::vector<OutcomeRow> outcomes, double kernel_s = 0.01) {
  ResultsFile r;
  r.path = "results.json";
  r.schema_version = 2;
  r.reference_kernel_seconds = kernel_s;
  SceneRows s;
  s.name = "contact_straight";
  s.load = "contact";
  s.load_unit = "N";
  s.model_levels = {0};
  s.tolerance_mm = 0.1;
  s.references.push_back({0.45, "P2", 1, 1000, 0.5, 40.0});
  s.outcomes = std::move(outcomes);
  r.scenes.push_back(s);
  return r;
}

}  // namespace

TEST(SvgPlot, LinearTicksAreOneTwoFiveSteps) {
  const auto near = [](const std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (std::abs(a[i] - b[i]) > 1e-12) return false;
    }
    return true;
  };
  EXPECT_TRUE(near(axis_ticks(0.0, 1.0, Scale::linear, 5), {0, 0.2, 0.4, 0.6, 0.8, 1.0}));
  EXPECT_TRUE(near(axis_ticks(-3.0, 47.0, Scale::linear, 5), {0, 10, 20, 30, 40}));
}

TEST(SvgPlot, LogTicksAreDecadesOrOneTwoFiveWithinTwoDecades) {
  // Log axes take log10 bounds: 1e-4 .. 1e2 → the six decades... every decade here.
  const auto decades = axis_ticks(-4.0, 2.0, Scale::log, 8);
  EXPECT_EQ(decades.size(), 7u);
  EXPECT_DOUBLE_EQ(decades.front(), 1e-4);
  EXPECT_DOUBLE_EQ(decades.back(), 100.0);
  const auto narrow = axis_ticks(std::log10(0.15), std::log10(3.0), Scale::log);
  EXPECT_EQ(narrow.size(), 4u);  // 0.2, 0.5, 1, 2
  EXPECT_DOUBLE_EQ(narrow[0], 0.2);
  EXPECT_DOUBLE_EQ(narrow[3], 2.0);
}

TEST(SvgPlot, ParetoFrontOfAHandPlacedSet) {
  // (time, error): a=(1,5) b=(2,3) c=(3,4) dominated by b, d=(4,1), e=(2,6) dominated by a and b.
  const std::vector<double> x{1, 2, 3, 4, 2};
  const std::vector<double> y{5, 3, 4, 1, 6};
  EXPECT_EQ(pareto_front(x, y), (std::vector<std::size_t>{0, 1, 3}));
}

TEST(SvgPlot, RendersSeriesEscapesTextAndCountsPointsALogAxisCannotShow) {
  Plot p;
  p.title = "error <&> speed";
  p.x = {"time", Scale::log};
  p.y = {"error", Scale::log};
  Series s;
  s.label = "a";
  s.x = {1, 10, -1};
  s.y = {1, 2, 3};
  s.lines = true;
  p.series.push_back(s);
  const std::string svg = render_svg(p);
  EXPECT_NE(svg.find("error &lt;&amp;&gt; speed"), std::string::npos);
  EXPECT_EQ(count(svg, "<polyline"), 1u);
  EXPECT_NE(svg.find("1 point(s) not shown"), std::string::npos);
  Plot empty;
  empty.title = "nothing";
  EXPECT_NE(render_svg(empty).find("no data to plot"), std::string::npos);
}

TEST(Document, MarkdownSectionsBecomeHtml) {
  const std::string html = markdown_to_html(
      "## Numerical stability\n\nSome *text* with `code`.\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n"
      "- one\n- two\n");
  EXPECT_NE(html.find("<h2>Numerical stability</h2>"), std::string::npos);
  EXPECT_NE(html.find("<em>text</em>"), std::string::npos);
  EXPECT_NE(html.find("<code>code</code>"), std::string::npos);
  EXPECT_NE(html.find("<th>a</th><th>b</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>1</td><td>2</td>"), std::string::npos);
  EXPECT_EQ(count(html, "<li>"), 2u);
}

TEST(ResultsFile, WrongSchemaVersionOrMissingFieldsNameTheFile) {
  const auto error_of = [](const std::string& text) {
    try {
      (void)parse_results(text, "r.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("{").find("r.json: not valid JSON"), std::string::npos);
  EXPECT_NE(error_of(R"({"schema":"other"})").find("not a vesselverify results file"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"schema":"vesselverify.results","schema_version":1})")
                .find("schema_version 1, expected 2"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"schema":"vesselverify.results","schema_version":2})")
                .find("r.json: missing field 'date'"),
            std::string::npos);
}

TEST(RepresentativeLoad, TheBudgetsMagnitudeElseTheLargestWithinTheLinearRegime) {
  // Strain 40 per unit load: the linear regime (5 %) ends at 0.05 / 40 = 1.25e-3.
  const std::vector<double> loads{1e-5, 1e-4, 5e-4, 1e-3, 0.01, 0.14};
  EXPECT_DOUBLE_EQ(representative_load(loads, 40.0, std::nullopt), 1e-3);
  EXPECT_DOUBLE_EQ(representative_load(loads, 40.0, 5e-4), 5e-4);
  EXPECT_DOUBLE_EQ(representative_load(loads, 40.0, 0.14), 0.14);  // the budget even beyond it
  EXPECT_DOUBLE_EQ(representative_load(loads, 1e6, std::nullopt), 1e-5);  // none within: smallest
}

TEST(Report, RepresentativeLoadOfAScene) {
  // results_with: the reference strains 40 per unit load, so 1e-3 N (4 %) is within 5 %, 0.14 N
  // (560 %) beyond.
  auto r = results_with({outcome("m", 1e-4, 0.01, 1), outcome("m", 1e-3, 0.1, 1),
                         outcome("m", 0.14, 5.0, 1, true)});
  EXPECT_DOUBLE_EQ(representative_load(r.scenes[0]), 1e-3);
  r.scenes[0].budget_magnitude = 1e-4;
  EXPECT_DOUBLE_EQ(representative_load(r.scenes[0]), 1e-4);
  r.scenes[0].budget_magnitude = 5e-4;  // a load the run does not have (a --quick run)
  EXPECT_DOUBLE_EQ(representative_load(r.scenes[0]), 1e-3);
  const auto all_beyond = results_with({outcome("m", 0.05, 2, 1, true), outcome("m", 0.14, 5, 1, true)});
  EXPECT_DOUBLE_EQ(representative_load(all_beyond.scenes[0]), 0.05);
}

TEST(Report, SummaryJudgesTheToleranceAndEveryFigureIsWritten) {
  const auto r = results_with({outcome("fast", 1e-4, 0.05, 0.01), outcome("fast", 1e-3, 0.5, 0.01),
                               outcome("slow", 1e-4, 0.01, 1.0), outcome("slow", 1e-3, 0.08, 1.0)});
  const Document doc = build_report(r, "## Numerical stability\n\ntable here\n", "vesselverify report");
  const std::string md = doc.markdown_text("figures");
  // Representative load 1 mN: fast misses 0.1 mm, slow meets it.
  EXPECT_NE(md.find("| contact_straight | fast | 0 | 1 mN | 0.5 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| no |"), std::string::npos);
  EXPECT_NE(md.find("| yes |"), std::string::npos);
  // Speed-error (both on the front: fast is faster, slow more accurate), load-displacement with
  // seed 000's Hooke line, wall profile.
  EXPECT_NE(md.find("figures/contact_straight_speed_error.svg"), std::string::npos);
  EXPECT_NE(md.find("Pareto front (no other point is both faster and more accurate): fast, slow"),
            std::string::npos);
  EXPECT_NE(md.find("figures/contact_straight_load_displacement.svg"), std::string::npos);
  EXPECT_NE(md.find("figures/contact_straight_wall_profile.svg"), std::string::npos);
  EXPECT_NE(md.find("## Numerical stability\n\ntable here"), std::string::npos);
  const std::string html = doc.html_text("t");
  EXPECT_EQ(count(html, "<svg"), 3u);
  EXPECT_NE(html.find("<h2>Numerical stability</h2>"), std::string::npos);
}

TEST(Gate, IdenticalResultsPass) {
  const auto r = results_with({outcome("m", 1e-3, 0.1, 1.0)});
  const auto g = compare_with_baseline(r, r);
  EXPECT_TRUE(g.passed());
  EXPECT_EQ(g.compared, 1u);
  EXPECT_TRUE(g.findings.empty());
}

TEST(Gate, AGrownErrorFailsAndAFallenOneIsOnlyANote) {
  const auto base = results_with({outcome("a", 1e-3, 0.100, 1.0), outcome("b", 1e-3, 0.100, 1.0)});
  const auto now = results_with({outcome("a", 1e-3, 0.103, 1.0), outcome("b", 1e-3, 0.05, 1.0)});
  const auto g = compare_with_baseline(base, now);  // tolerance 2 %
  EXPECT_FALSE(g.passed());
  ASSERT_EQ(g.findings.size(), 2u);
  EXPECT_TRUE(g.findings[0].failure);
  EXPECT_EQ(g.findings[0].model, "a");
  EXPECT_EQ(g.findings[0].what, "max error grew");
  EXPECT_FALSE(g.findings[1].failure);
  const auto within = results_with({outcome("a", 1e-3, 0.101, 1.0), outcome("b", 1e-3, 0.1, 1.0)});
  EXPECT_TRUE(compare_with_baseline(base, within).passed());
}

TEST(Gate, AModelThatNowFailsOrIsMissingFails) {
  const auto base = results_with({outcome("a", 1e-3, 0.1, 1.0), outcome("b", 1e-3, 0.1, 1.0)});
  OutcomeRow diverged = outcome("a", 1e-3, 0.1, 1.0);
  diverged.ok = false;
  diverged.failure = "diverged at step 12";
  const auto g = compare_with_baseline(base, results_with({diverged}));
  EXPECT_FALSE(g.passed());
  ASSERT_EQ(g.findings.size(), 2u);
  EXPECT_EQ(g.findings[0].what, "now fails");
  EXPECT_EQ(g.findings[0].current, "diverged at step 12");
  EXPECT_EQ(g.findings[1].what, "missing from this run");
}

TEST(Gate, TimingsAreComparedNormalisedByTheReferenceKernel) {
  const auto base = results_with({outcome("a", 1e-3, 0.1, 1.0)}, 0.010);
  // A machine twice as slow at everything: passes.
  EXPECT_TRUE(compare_with_baseline(base, results_with({outcome("a", 1e-3, 0.1, 2.0)}, 0.020)).passed());
  // The model 3× slower on the same machine: fails (ratio 2.5).
  const auto slower = compare_with_baseline(base, results_with({outcome("a", 1e-3, 0.1, 3.0)}, 0.010));
  EXPECT_FALSE(slower.passed());
  EXPECT_EQ(slower.findings.at(0).what, "slower (normalised solve time)");
  // Below the floor (50 ms in the baseline) times are noise: not gated.
  const auto tiny = results_with({outcome("a", 1e-3, 0.1, 0.01)}, 0.010);
  EXPECT_TRUE(compare_with_baseline(tiny, results_with({outcome("a", 1e-3, 0.1, 0.1)}, 0.010)).passed());
}
