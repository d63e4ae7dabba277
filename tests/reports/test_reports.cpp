// The report generator and the gate: plots' ticks and Pareto fronts against hand-worked cases,
// results files read back with clear errors, and the gate's verdicts on constructed baselines.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "../test_helpers.hpp"
#include "meshes/foundation/errors.hpp"
#include "reports/document.hpp"
#include "reports/gate.hpp"
#include "reports/report.hpp"
#include "reports/representative_load.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "reports/svg_plot.hpp"
#include "reports/web_page.hpp"

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


/// A stability.json as `vesselverify stability` writes it, by hand: one critical-step row
/// (predicted 12.34 µs, found 10 µs: found / predicted = 0.8104; guaranteed 8 µs: 1.25), one
/// refinement fit and one hard case whose report has a pipe in it.
const char* kStability = R"({
  "schema": "vesselverify.stability", "schema_version": 1,
  "command": "vesselverify stability --quick", "quick": true, "units": {},
  "steps_per_trial": 400,
  "critical_steps": [{"model": "volume / seed001", "integrator": "symplectic-euler", "zeta": 0,
    "point_damping": 0, "level": 0, "nodes": 321, "springs": 1500, "h_nominal": 0.001,
    "omega_max": 81234.4, "omega_gershgorin": 99000, "omega_min": 10, "gamma_max": 0,
    "predicted_dt": 1.234e-5, "guaranteed_dt": 8e-6, "found_over_guaranteed": 1.25,
    "found_dt": 1.0e-5, "unstable_dt": 1.1e-5, "found_over_predicted": 0.8104, "trials": 9,
    "seconds": 1.5}],
  "refinement": [{"model": "volume / seed001", "integrator": "verlet", "zeta": 0.1,
    "levels": [0, 1], "found_exponent": 0.987, "predicted_exponent": 1.02}],
  "hard_cases": [{"id": "sliver", "title": "Sliver tets", "setup": "one tet flattened to 1e-3",
    "seconds": 2.5, "outcomes": [{"model": "fem_p1", "finished": true, "converged": true,
    "bounded": null, "reported": "max |u| 0.123 mm", "values": {}}]}],
  "total_seconds": 42.0
})";

/// A recommend.json by hand: three candidates, the recommended one with error 0.0421 mm at
/// 1.5 ms per update, one too slow, one failed; the budget's load 0.5 mN at ν = 0.45.
const char* kRecommend = R"({
  "schema": "vesselverify.recommend", "schema_version": 1,
  "command": "vesselverify recommend --quick --rate 30 contact_straight.toml",
  "scene": "contact_straight", "source": "contact_straight.toml", "model_levels": [0],
  "reference_level": 1, "reference_contact_point_mm": 0.25,
  "budget": {"quantity": "contact_point", "unit": "mm", "tolerance": 0.1,
             "seconds_per_update": 0.0333333, "update_period_s": 0.0333333, "rate_hz": 30},
  "loads": [{"poisson_ratio": 0.45, "magnitude": 0.0005}],
  "recommended": "volume/lloyd/static @ L0", "closest": null,
  "candidates": [
    {"name": "fem_p1 @ L0", "model": "fem_p1", "detail": "P1", "level": 0, "unknowns": 900,
     "ok": true, "pareto": true, "verdict": "too slow", "reason": "77 ms per update", "error": 0.01,
     "update_seconds": 0.077},
    {"name": "surface/seed000/explicit @ L0", "model": "s", "detail": "explicit", "level": 0,
     "unknowns": 300, "ok": false, "pareto": false, "verdict": "failed", "reason": "diverged",
     "failure": "energy grew"},
    {"name": "volume/lloyd/static @ L0", "model": "v", "detail": "Newton", "level": 0,
     "unknowns": 600, "ok": true, "pareto": true, "verdict": "recommended",
     "reason": "the fastest meeting both", "error": 0.0421, "update_seconds": 0.0015,
     "setup_seconds": 0.02}]
})";

template <class Parse>
std::string error_of(Parse&& parse, const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
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

// The legend has two columns while every label fits in half the width (7 px a character at the
// 12 px font, from 38 px past the column's edge), else one: a long label ran off the figure.
TEST(SvgPlot, ALegendLabelTooLongForHalfTheWidthPutsTheLegendInOneColumn) {
  const auto plot_with = [](const std::string& second_label) {
    Plot p;
    p.title = "legend";
    for (const std::string& label : {std::string("short"), second_label}) {
      Series s;
      s.label = label;
      s.x = {1.0, 2.0};
      s.y = {1.0, 2.0};
      p.series.push_back(s);
    }
    return render_svg(p, 640, 360);
  };
  // 40 characters (41 bytes: a character of two counts once): 38 + 280 = 318 px ≤ 320, the
  // second column's label starts at 320 + 38.
  const std::string fits = plot_with(std::string(39, 'a') + "·");
  EXPECT_NE(fits.find("height=\"378\""), std::string::npos) << fits;  // 360 + one row of 18
  EXPECT_NE(fits.find("<text x=\"358.0\""), std::string::npos) << fits;
  // 41 characters: 325 px, one column, two rows.
  const std::string wide = plot_with(std::string(41, 'a'));
  EXPECT_NE(wide.find("height=\"396\""), std::string::npos) << wide;
  EXPECT_EQ(wide.find("<text x=\"358.0\""), std::string::npos) << wide;
  EXPECT_EQ(count(wide, "<text x=\"38.0\""), 2u) << wide;
}

// A series without its own colour is drawn alike in the SVG and in report.html's interactive plot:
// the palette's colour and marker shape for its index (report.html drew such series grey).
TEST(Document, AnUnstyledSeriesHasTheSameColourAndShapeInTheSvgAndTheInteractivePlot) {
  Plot plot;
  plot.title = "two curves";
  for (const char* name : {"first", "second"}) {
    Series s;
    s.label = name;
    s.x = {1.0, 2.0};
    s.y = {1.0, 3.0};
    plot.series.push_back(s);
  }
  Document doc;
  doc.figure("two.svg", plot, "two curves");
  const std::string svg = render_svg(plot);
  const std::string html = interactive_html(doc, {}, {}, WebLibraries{}, "t");
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_NE(svg.find("\"" + palette_colour(k) + "\""), std::string::npos) << svg;
    EXPECT_NE(html.find("\"colour\":\"" + palette_colour(k) + "\""), std::string::npos) << html;
    EXPECT_NE(html.find("\"marker\":\"" + palette_marker(k) + "\""), std::string::npos) << html;
  }
  EXPECT_EQ(palette_colour(0), "#0072B2");
  EXPECT_EQ(palette_marker(1), "rect");
  EXPECT_NE(svg.find("<rect x="), std::string::npos);  // the second series' square markers
}

TEST(Document, BlocksRenderAsMarkdownAndHtml) {
  Document doc;
  doc.heading(2, "Numerical stability");
  doc.paragraph("Some *text* with `code` and **bold**.");
  doc.code("vesselverify run a<b.toml");
  doc.table({{"a", "b"}, {{"1", "x|y\nz"}}});
  const std::string md = doc.markdown_text("figures");
  EXPECT_NE(md.find("## Numerical stability\n\nSome *text*"), std::string::npos) << md;
  EXPECT_NE(md.find("\n    vesselverify run a<b.toml\n"), std::string::npos) << md;
  EXPECT_NE(md.find("| 1 | x\\|y z |"), std::string::npos) << md;  // one row, pipe escaped
  const std::string html = doc.html_text("t");
  EXPECT_NE(html.find("<h2>Numerical stability</h2>"), std::string::npos);
  EXPECT_NE(html.find("<p>Some <em>text</em> with <code>code</code> and <strong>bold</strong>.</p>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<pre>vesselverify run a&lt;b.toml</pre>"), std::string::npos) << html;
  EXPECT_NE(html.find("<th>a</th><th>b</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>1</td><td>x|y\nz</td>"), std::string::npos) << html;
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

TEST(Report, TheSummaryIsAtTheBudgetsLoad) {
  auto r = results_with({outcome("m", 1e-4, 0.01, 1), outcome("m", 1e-3, 0.25, 1)});
  r.scenes[0].budget_magnitude = 1e-4;
  const std::string md = build_report(r, std::nullopt, "vesselverify report").markdown_text("f");
  EXPECT_NE(md.find("| contact_straight | m | 0 | 0.1 mN | 0.01 |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| contact_straight | m | 0 | 1 mN |"), std::string::npos) << md;
}

TEST(Report, SummaryJudgesTheToleranceAndEveryFigureIsWritten) {
  const auto r = results_with({outcome("fast", 1e-4, 0.05, 0.01), outcome("fast", 1e-3, 0.5, 0.01),
                               outcome("slow", 1e-4, 0.01, 1.0), outcome("slow", 1e-3, 0.08, 1.0)});
  const Document doc = build_report(r, std::nullopt, "vesselverify report");
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
  EXPECT_NE(md.find("## Numerical stability\n\nNot part of these results"), std::string::npos);
  const std::string html = doc.html_text("t");
  EXPECT_EQ(count(html, "<svg"), 3u);
  EXPECT_NE(html.find("<h2>Numerical stability</h2>"), std::string::npos);
}

TEST(StudyFiles, TheReportDrawsTheStabilityFilesFigures) {
  const StabilityFile st = parse_stability(kStability, "stability.json");
  const Document doc = build_report(results_with({outcome("m", 1e-3, 0.1, 1)}), st, "cmd");
  const std::string md = doc.markdown_text("figures");
  const std::string html = doc.html_text("t");
  // The critical step in µs, the hand-worked ratios, the refinement exponent, the hard case.
  EXPECT_NE(html.find("<td>volume / seed001</td><td>symplectic-euler</td><td>0</td><td>0</td>"
                      "<td>321</td><td>81234</td><td>99000</td><td>12.34</td><td>8</td><td>10</td>"
                      "<td>0.8104</td><td>1.25</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<td>0,1</td><td>0.987</td><td>1.02</td>"), std::string::npos);
  EXPECT_NE(html.find("<h4>Sliver tets</h4>"), std::string::npos);
  EXPECT_NE(md.find("| fem_p1 | yes | yes | – | max \\|u\\| 0.123 mm |"), std::string::npos) << md;
  EXPECT_NE(md.find("400 steps per trial"), std::string::npos);
  EXPECT_NE(md.find("`vesselverify stability --quick` (quick mode) in 42 s"), std::string::npos);
  EXPECT_EQ(md.find("Timings (per level"), std::string::npos) << "no provenance record, no line";

  // With the record stability.json carries: 2 of 5 items from the cache, measured at two times.
  nlohmann::json j = nlohmann::json::parse(kStability);
  j["timing_provenance"] = {{"items", 5},
                            {"cached_measured_at", {"2026-11-25T06:51:34Z", "2026-11-25T06:50:00Z"}}};
  const StabilityFile cached = parse_stability(j.dump(), "stability.json");
  const std::string md2 =
      build_report(results_with({outcome("m", 1e-3, 0.1, 1)}), cached, "cmd").markdown_text("f");
  EXPECT_NE(md2.find("Timings (per level and model's rows, per hard case): 2 of 5 timings from "
                     "the cache, measured 2026-11-25T06:50:00Z to 2026-11-25T06:51:34Z by the "
                     "same executable on this machine"),
            std::string::npos)
      << md2;
}

TEST(StudyFiles, TheReportDrawsTheRecommendationWithItsRunsUnitAndReference) {
  RecommendFile rec = parse_recommend(kRecommend, "rec/recommend.json");
  auto run = results_with({});
  run.scenes[0].references[0].element = "Taylor-Hood P2-P1";
  attach_run(rec, run);
  const Document doc = build_report(results_with({outcome("m", 1e-3, 0.1, 1)}), std::nullopt,
                                    "cmd", {rec});
  const std::string md = doc.markdown_text("figures");
  EXPECT_NE(md.find("## Model recommendation: contact_straight at 30 Hz"), std::string::npos) << md;
  EXPECT_NE(md.find("at ν = 0.45 the load is 0.5 mN (reference Taylor-Hood P2-P1, level 1)"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("**Recommended: `volume/lloyd/static @ L0`** (Newton): error 0.0421 mm, "
                    "1.5 ms per update, 600 unknowns."),
            std::string::npos)
      << md;
  // Winner first, then by time, the failure last; set-up (ms) beside the time per update, "–"
  // where the file has none (written before set-up was reported).
  const auto winner =
      md.find("| `volume/lloyd/static @ L0` | 600 | 0.0421 | 1.5 | 20 | ★ | recommended |");
  const auto slow = md.find("| `fem_p1 @ L0` | 900 | 0.01 | 77 | – | ★ | too slow |");
  const auto failed = md.find("| `surface/seed000/explicit @ L0` | 300 | – | – | – |  | failed |");
  ASSERT_NE(winner, std::string::npos) << md;
  ASSERT_NE(slow, std::string::npos) << md;
  ASSERT_NE(failed, std::string::npos) << md;
  EXPECT_LT(winner, slow);
  EXPECT_LT(slow, failed);
  // 0.1 mm against a reference moving 0.25 mm: the tolerance discriminates, no warning.
  EXPECT_EQ(md.find("does not discriminate"), std::string::npos);
}

TEST(StudyFiles, ARecommendationWhoseCandidatesAllFailAlikeSaysWhyOnce) {
  RecommendFile rec = parse_recommend(kRecommend, "rec/recommend.json");
  rec.recommended.reset();
  rec.closest.reset();
  rec.whole_vessel.reset();
  for (auto& c : rec.candidates) {
    c.verdict = "failed";
    c.reason = "failed: the reference is beyond its validity";
  }
  EXPECT_NE(recommendation_markdown(rec).find(
                "**No candidate meets the budget**, and none finished; every one failed: the "
                "reference is beyond its validity."),
            std::string::npos)
      << recommendation_markdown(rec);
  rec.candidates.back().reason = "failed: diverged";
  EXPECT_EQ(recommendation_markdown(rec).find("every one"), std::string::npos);
}

TEST(StudyFiles, MalformedOrForeignFilesAreClearErrorsNamingTheFile) {
  const auto stability = [](const std::string& t) { (void)parse_stability(t, "s.json"); };
  const auto recommend = [](const std::string& t) { (void)parse_recommend(t, "r.json"); };
  EXPECT_NE(error_of(stability, "{").find("s.json: not valid JSON"), std::string::npos);
  EXPECT_NE(error_of(stability, kRecommend)
                .find("s.json: not a vesselverify stability file (expected \"schema\": "
                      "\"vesselverify.stability\""),
            std::string::npos)
      << error_of(stability, kRecommend);
  EXPECT_NE(error_of(recommend, kStability).find("r.json: not a vesselverify recommend file"),
            std::string::npos);
  EXPECT_NE(error_of(stability, R"({"schema":"vesselverify.stability","schema_version":2})")
                .find("s.json: schema_version 2, expected 1"),
            std::string::npos);
  std::string no_found = kStability;
  no_found.replace(no_found.find("\"found_dt\""), 10, "\"lost_dt\"");
  EXPECT_NE(error_of(stability, no_found)
                .find("s.json: critical_steps[0]: missing field 'found_dt'"),
            std::string::npos)
      << error_of(stability, no_found);
  std::string bad_candidate = kRecommend;
  bad_candidate.replace(bad_candidate.find("\"unknowns\": 600"), 15, "\"unknowns\": \"x\"");
  EXPECT_NE(error_of(recommend, bad_candidate)
                .find("r.json: candidates[2]: field 'unknowns' has the wrong type"),
            std::string::npos)
      << error_of(recommend, bad_candidate);
}

namespace {
/// results_with one model and a guidewire block: the wire's force error against the continuum
/// (mN) at one EI, and one coupled row's force and the reference's (mN).
ResultsFile with_wire(double wire_error_mN, double force_mN, bool coupled_ok = true) {
  ResultsFile r = results_with({outcome("m", 1e-3, 0.1, 1.0)});
  GuidewireRows g;
  g.model = "der";
  g.coupling = "compliant";
  GuidewireRigidRow rigid;
  rigid.bending_stiffness = 4e-7;
  rigid.force_mN = 0.471;
  rigid.force_error_mN = wire_error_mN;
  g.rigid.push_back(rigid);
  GuidewireCoupledRow row;
  row.model = "m";
  row.poisson_ratio = 0.45;
  row.bending_stiffness = 4e-7;
  row.ok = coupled_ok;
  row.failure = coupled_ok ? "" : "secant did not converge";
  row.force_mN = force_mN;
  row.reference_force_mN = 0.44;
  g.coupled.push_back(row);
  r.scenes[0].guidewire = g;
  return r;
}
}  // namespace

TEST(Gate, TheWiresForceErrorAndEachCoupledForceErrorMayNotGrow) {
  const auto base = with_wire(2.0e-4, 0.45);  // coupled error 0.01 mN
  EXPECT_TRUE(compare_with_baseline(base, with_wire(2.0e-4, 0.45)).passed());
  EXPECT_TRUE(compare_with_baseline(base, with_wire(1.0e-4, 0.4401)).passed());  // both better
  // The rod model's error against the continuum grew by 10 %.
  const GateOutcome wire = compare_with_baseline(base, with_wire(2.2e-4, 0.45));
  ASSERT_FALSE(wire.passed());
  EXPECT_EQ(wire.findings.front().model, "wire (der)");
  EXPECT_NE(wire.findings.front().what.find("wire force error"), std::string::npos);
  EXPECT_EQ(wire.findings.front().magnitude, 4e-7);  // the EI
  // A vessel model's coupled contact-force error grew (0.01 → 0.02 mN), or its row now fails.
  const GateOutcome coupled = compare_with_baseline(base, with_wire(2.0e-4, 0.46));
  ASSERT_FALSE(coupled.passed());
  EXPECT_EQ(coupled.findings.front().model, "m");
  EXPECT_NE(coupled.findings.front().what.find("coupled contact-force error"), std::string::npos);
  EXPECT_FALSE(compare_with_baseline(base, with_wire(2.0e-4, 0.45, false)).passed());
  // The wire's block gone from a scene that had it.
  auto gone = with_wire(2.0e-4, 0.45);
  gone.scenes[0].guidewire.reset();
  EXPECT_FALSE(compare_with_baseline(base, gone).passed());
}

namespace {
/// with_wire's results with a contact block at EI 4e-7: model "m"'s contact force error (mN)
/// against the reference's, or its failed solve.
ResultsFile with_contact(double error_mN, bool ok = true) {
  ResultsFile r = with_wire(2.0e-4, 0.45);
  GuidewireContactRows c;
  ContactRun run;
  run.bending_stiffness = 4e-7;
  run.reference.model = "reference_fem_p2";
  run.reference.ok = true;
  run.reference.force_mN = 0.43;
  ContactWallRow m;
  m.model = "m";
  m.ok = ok;
  m.failure = ok ? "" : "did not converge in 400 Newton steps";
  m.force_mN = 0.43 + error_mN;
  if (ok) m.force_error_mN = error_mN;
  run.models.push_back(m);
  c.runs.push_back(run);
  r.scenes[0].guidewire->contact = c;
  return r;
}
}  // namespace

TEST(Gate, EachModelsContactForceErrorMayNotGrow) {
  const auto base = with_contact(-0.01);
  EXPECT_TRUE(compare_with_baseline(base, with_contact(-0.01)).passed());
  EXPECT_TRUE(compare_with_baseline(base, with_contact(0.005)).passed());  // smaller |error|
  const GateOutcome grew = compare_with_baseline(base, with_contact(0.02));
  ASSERT_FALSE(grew.passed());
  EXPECT_EQ(grew.findings.front().model, "m");
  EXPECT_EQ(grew.findings.front().magnitude, 4e-7);  // the EI
  EXPECT_NE(grew.findings.front().what.find("contact-force error"), std::string::npos);
  const GateOutcome fails = compare_with_baseline(base, with_contact(-0.01, false));
  ASSERT_FALSE(fails.passed());
  EXPECT_EQ(fails.findings.front().current, "did not converge in 400 Newton steps");
  // The contact block gone, or the model's row gone from it.
  auto gone = with_contact(-0.01);
  gone.scenes[0].guidewire->contact.reset();
  EXPECT_FALSE(compare_with_baseline(base, gone).passed());
  auto no_row = with_contact(-0.01);
  no_row.scenes[0].guidewire->contact->runs[0].models.clear();
  EXPECT_FALSE(compare_with_baseline(base, no_row).passed());
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

TEST(GuidewireSection, TheWiresForcesAndEachModelsCoupledForceAsResultsJsonGivesThem) {
  // The fixture's results with a guidewire block written by hand: two stiffnesses against the
  // rigid lumen, a coupled row inside the patch, one that slid out of it and whose reference wall
  // is dented deeper than it is thick, and a failed one.
  auto j = nlohmann::json::parse(test::read_text(
      std::filesystem::path(VESSEL_REPORT_FIXTURE) / "results.json"));
  const auto row = [](const std::string& model, double ei, bool within) {
    return nlohmann::json{{"model", model}, {"poisson_ratio", 0.45}, {"level", 0},
                          {"bending_stiffness_Nm2", ei}, {"ok", true}, {"failure", ""},
                          {"force_mN", 0.45}, {"reference_force_mN", 0.44},
                          {"contact_displacement_mm", 0.15},
                          {"reference_contact_displacement_mm", 0.21}, {"slide_mm", within ? 0.02 : 1.5},
                          {"within_patch", within}};
  };
  nlohmann::json failed = row("volume_springs", 4e-5, true);
  failed["ok"] = false;
  failed["failure"] = "secant did not converge";
  j["scenes"][0]["guidewire"] = {
      {"model", "der"},
      {"coupling", "compliant"},
      {"rigid",
       {{{"bending_stiffness_Nm2", 4e-7}, {"contact_force_N", 4.707e-4},
         {"wire_compliance_m_per_N", 6.95}},
        {{"bending_stiffness_Nm2", 4e-5}, {"contact_force_N", 4.707e-2},
         {"wire_compliance_m_per_N", 0.0695}}}},
      {"coupling_rows", {row("fem_p1", 4e-7, true), row("other_springs", 4e-5, false), failed}}};
  j["scenes"][0]["guidewire"]["coupling_rows"][1]["reference_within_wall"] = false;
  const ResultsFile r = parse_results(j.dump(), "results.json");
  ASSERT_TRUE(r.scenes[0].guidewire.has_value());
  const GuidewireRows& g = *r.scenes[0].guidewire;
  ASSERT_EQ(g.rigid.size(), 2u);
  EXPECT_DOUBLE_EQ(g.rigid[1].force_mN, 47.07);
  ASSERT_EQ(g.coupled.size(), 3u);
  EXPECT_FALSE(g.coupled[1].within_patch);
  const std::string md = build_report(r, std::nullopt, "test").markdown_text("figures");
  EXPECT_EQ(count(md, "### The guidewire"), 1u) << md;
  EXPECT_EQ(count(md, "| 4e-07 | 0.471 | 6.95 |"), 1u) << md;
  EXPECT_EQ(count(md, "| fem_p1 | 0.45 | 0 | 4e-07 | 0.45 | 0.44 | 0.01 | 0.15 | 0.21 | 0.02 |"), 1u)
      << md;
  EXPECT_EQ(count(md, "| 1.5 ⚠ |"), 1u) << md;
  // The row without the field (results from before it) is not marked.
  EXPECT_TRUE(g.coupled[0].reference_within_wall);
  EXPECT_EQ(count(md, "| 0.21 ✗ |"), 1u) << md;
  EXPECT_EQ(count(md, "failed: secant did not converge"), 1u) << md;
  // A scene without a wire has no such section.
  j["scenes"][0].erase("guidewire");
  EXPECT_EQ(count(build_report(parse_results(j.dump(), "r.json"), std::nullopt, "t")
                      .markdown_text("figures"),
                  "The guidewire"),
            0u);
}

TEST(GuidewireSection, TheContactSolvesModelsAndShortcutsAsResultsJsonGivesThem) {
  // A contact block written by hand: at EI 4e-7 a reference, a model 2 % low and a failed one;
  // at 4e-5 a reference beyond the linear wall's validity.
  auto j = nlohmann::json::parse(
      test::read_text(std::filesystem::path(VESSEL_REPORT_FIXTURE) / "results.json"));
  const auto wall = [](const std::string& model, double force, double error_percent) {
    return nlohmann::json{{"model", model},
                          {"wall", "at rest"},
                          {"ok", true},
                          {"force_mN", force},
                          {"force_error_mN", force - 0.43},
                          {"force_error_percent", error_percent},
                          {"pressed", 12},
                          {"axial_extent_mm", 0.75},
                          {"circumferential_extent_mm", 0.35},
                          {"dent_mm", 0.21},
                          {"largest_strain", 0.04},
                          {"tip_error_mm", 0.012},
                          {"setup_seconds", 1.5},
                          {"solve_seconds", 0.25}};
  };
  nlohmann::json failed{{"model", "volume_springs"},
                        {"wall", "at rest"},
                        {"ok", false},
                        {"failure", "did not converge"}};
  nlohmann::json stiff_reference = wall("reference_fem_p2", 5.2, 0.0);
  stiff_reference["largest_strain"] = 0.31;
  const auto run = [&](double ei, bool valid, const nlohmann::json& reference,
                       const nlohmann::json& models) {
    return nlohmann::json{
        {"bending_stiffness_Nm2", ei},
        {"rigid_force_mN", 0.471},
        {"within_linear_validity", valid},
        {"reference", reference},
        {"models", models},
        {"shortcuts",
         {{{"name", "rigid lumen"}, {"force_mN", 0.471}, {"force_error_percent", 9.53}}}}};
  };
  j["scenes"][0]["guidewire"] = {
      {"model", "der"},
      {"coupling", "contact"},
      {"rigid", {{{"bending_stiffness_Nm2", 4e-7}, {"contact_force_N", 4.71e-4}}}},
      {"coupling_rows", nlohmann::json::array()},
      {"contact",
       {{"poisson_ratio", 0.45},
        {"mesh_nodes", 7072},
        {"mesh_tets", 30000},
        {"fine_size_mm", 0.08},
        {"fine_radius_mm", 1.0},
        {"reference_degree", 2},
        {"strain_limit", 0.1},
        {"runs",
         {run(4e-7, true, wall("reference_fem_p2", 0.43, 0.0),
              {wall("fem_p1", 0.4214, -2.0), failed}),
          run(4e-5, false, stiff_reference, nlohmann::json::array())}}}}};
  const ResultsFile r = parse_results(j.dump(), "results.json");
  const GuidewireRows& g = *r.scenes[0].guidewire;
  ASSERT_TRUE(g.contact.has_value());
  ASSERT_EQ(g.contact->runs.size(), 2u);
  EXPECT_FALSE(g.contact->runs[1].within_linear_validity);
  const std::string md = build_report(r, std::nullopt, "test").markdown_text("figures");
  EXPECT_EQ(count(md, "7072 nodes refined to 0.08 mm"), 1u) << md;
  EXPECT_EQ(count(md, "| fem_p1 | 0.4214 | -2 | 12 | 0.75 × 0.35 | 0.21 | 0.012 | 1.5 | 0.25 |"),
            1u)
      << md;
  EXPECT_EQ(count(md, "failed: did not converge"), 1u) << md;
  EXPECT_EQ(count(md, "| rigid lumen | 0.471 | 9.53 |"), 2u) << md;
  EXPECT_EQ(count(md, "⚠ Beyond the linear reference's validity"), 1u) << md;
  EXPECT_EQ(count(md, "model's wall linearised at rest"), 1u) << md;
  // A finite-strain contact: the walls at their own equilibrium, and a surface model's strain,
  // which it cannot compute (no tets), written as null.
  j["scenes"][0]["guidewire"]["contact"]["wall"] = "neo-Hookean";
  nlohmann::json surface = wall("surface_seed000", 0.3994, -7.0);
  surface["largest_strain"] = nullptr;
  j["scenes"][0]["guidewire"]["contact"]["runs"][0]["models"].push_back(surface);
  const ResultsFile neo = parse_results(j.dump(), "results.json");
  const GuidewireContactRows& c = *neo.scenes[0].guidewire->contact;
  EXPECT_EQ(c.wall, "neo-Hookean");
  ASSERT_EQ(c.runs[0].models.size(), 3u);
  EXPECT_TRUE(std::isnan(c.runs[0].models[2].largest_strain));
  const std::string neo_md = build_report(neo, std::nullopt, "test").markdown_text("figures");
  EXPECT_EQ(count(neo_md, "at its own nonlinear equilibrium (the reference the neo-Hookean FEM "
                          "wall)"),
            1u)
      << neo_md;
  EXPECT_EQ(count(neo_md, "| surface_seed000 | 0.3994 |"), 1u) << neo_md;
  // Its strained run (largest strain 0.31) is judged: the strain limit is the linear wall's.
  EXPECT_EQ(count(neo_md, "⚠ Beyond the linear reference's validity"), 0u) << neo_md;
  // A contact block without its runs is a clear error naming the field.
  j["scenes"][0]["guidewire"]["contact"].erase("runs");
  try {
    (void)parse_results(j.dump(), "results.json");
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("runs"), std::string::npos) << e.what();
  }
}
