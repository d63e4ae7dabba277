// `vesselverify report` and `vesselverify gate` end to end on the committed baseline (a real
// results file of the gate scenes): the report's files, and the gate's verdict when the baseline
// is doctored to make this run look like a regression.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../test_helpers.hpp"

using vessel::test::CommandResult;
using vessel::test::read_text;
using vessel::test::run_command;
using vessel::test::TempDir;
using vessel::test::write_text;
using vessel::test::vv;

namespace {

const std::string kBaseline = VESSEL_BASELINE;


bool contains(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

/// The baseline with `edit` applied to every outcome of `model`, written to `path`.
template <class Edit>
void doctored_baseline(const std::filesystem::path& path, const std::string& model, Edit&& edit) {
  nlohmann::json j = nlohmann::json::parse(read_text(kBaseline));
  int edited = 0;
  for (auto& scene : j["scenes"]) {
    for (auto& o : scene["outcomes"]) {
      if (o["model"] == model && o["ok"] == true) {
        edit(o);
        ++edited;
      }
    }
  }
  ASSERT_GT(edited, 0) << "no finished outcome of " << model << " in the baseline";
  write_text(path, j.dump(1));
}

}  // namespace

TEST(ReportCli, WritesMarkdownHtmlAndEveryFigure) {
  TempDir dir;
  const auto r = vv("report " + kBaseline + " -o " + dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string md = read_text(dir / "report.md");
  const std::string html = read_text(dir / "report.html");
  EXPECT_TRUE(contains(md, "## Summary"));
  EXPECT_TRUE(contains(md, "## Scene `contact_straight`"));
  EXPECT_TRUE(contains(md, "## Numerical stability"));
  std::size_t figures = 0;
  for (const auto& f : std::filesystem::directory_iterator(dir / "figures")) {
    EXPECT_EQ(f.path().extension(), ".svg");
    EXPECT_TRUE(contains(md, "figures/" + f.path().filename().string())) << f.path();
    ++figures;
  }
  EXPECT_GE(figures, 6u);  // at least speed-error and wall profile per scene
  // Self-contained: every figure inline, as an interactive plot (its data in the page) or, without
  // the JavaScript libraries, as its SVG.
  EXPECT_EQ(count(html, "<figure"), figures);
  EXPECT_EQ(count(html, "<figure class=\"vv-plot\">") + count(html, "<figure>\n<svg"), figures);
  EXPECT_FALSE(contains(html, "src=\""));    // and nothing linked
}

TEST(ReportCli, ANonResultsFileIsAClearError) {
  TempDir dir;
  write_text(dir / "x.json", "{\"schema\": \"something else\"}");
  const auto r = vv("report " + (dir / "x.json").string() + " -o " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "x.json: not a vesselverify results file")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "report.md"));
}

TEST(ReportCli, DrawsTheStudiesFromTheirJsonFiles) {
  TempDir dir;
  // Hand-written: a critical step predicted at 12.34 µs and found at 10 µs (ratio 0.8104), and a
  // recommendation of one candidate at 0.0421 mm; the recommend run's results.json beside it
  // (the baseline: contact_straight, load unit N, reference P2) gives the load in mN.
  write_text(dir / "stability.json", R"({"schema": "vesselverify.stability", "schema_version": 1,
    "command": "vesselverify stability --quick", "quick": true, "steps_per_trial": 400,
    "critical_steps": [{"model": "volume / seed001", "integrator": "verlet", "zeta": 0,
      "level": 0, "nodes": 321, "omega_max": 81234.4, "omega_gershgorin": 99000,
      "predicted_dt": 1.234e-5, "guaranteed_dt": null, "found_dt": 1.0e-5}],
    "refinement": [], "hard_cases": [], "total_seconds": 42.0})");
  std::filesystem::create_directories(dir / "rec");
  std::filesystem::copy_file(kBaseline, dir / "rec" / "results.json");
  write_text(dir / "rec" / "recommend.json", R"({"schema": "vesselverify.recommend",
    "schema_version": 1, "command": "vesselverify recommend --quick", "scene": "contact_straight",
    "model_levels": [0], "reference_level": 1, "reference_contact_point_mm": 0.25,
    "budget": {"quantity": "contact_point", "unit": "mm", "tolerance": 0.1,
               "seconds_per_update": 0.001, "rate_hz": 1000},
    "loads": [{"poisson_ratio": 0.45, "magnitude": 0.0005}],
    "recommended": "volume/lloyd/static @ L0", "closest": null,
    "candidates": [{"name": "volume/lloyd/static @ L0", "detail": "Newton", "unknowns": 600,
      "ok": true, "pareto": true, "verdict": "recommended", "reason": "the fastest",
      "error": 0.0421, "update_seconds": 0.0005}]})");
  const auto r = vv("report " + kBaseline + " --stability " + (dir / "stability.json").string() +
                    " --recommend " + (dir / "rec" / "recommend.json").string() + " -o " +
                    dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string html = read_text(dir / "report.html");
  EXPECT_TRUE(contains(html, "<td>12.34</td><td>–</td><td>10</td><td>0.8104</td><td>–</td>"))
      << html;
  EXPECT_TRUE(contains(html, "<h2>Model recommendation: contact_straight at 1000 Hz</h2>"));
  EXPECT_TRUE(contains(html, "the load is 0.5 mN (reference P2, level 1)")) << html;
  EXPECT_TRUE(contains(html, "<strong>Recommended: <code>volume/lloyd/static @ L0</code></strong>"));
  EXPECT_TRUE(contains(read_text(dir / "report.md"), "| `volume/lloyd/static @ L0` | 600 | 0.0421 |"));
}

// The insertion's document (hand-written: one converged step of 0.45 mN at 20 mm, one failed)
// drawn as its section, and a document without its steps refused naming the file.
TEST(ReportCli, DrawsTheInsertionFromItsJsonFile) {
  TempDir dir;
  write_text(dir / "insertion.json", R"({"schema": "vesselverify.insertion", "schema_version": 1,
    "command": "vesselverify insertion s.toml", "total_seconds": 30.0,
    "insertions": [{"scene": "guidewire_straight", "model": "reference",
      "model_detail": "FEM P1 (deal.II), neo-Hookean", "bending_stiffness_Nm2": 4e-7,
      "wall": "neo-Hookean", "mesh_nodes": 5546, "refined_balls": 2, "mesh_seconds": 1.0,
      "steps": [{"insertion_m": 0.02, "converged": true, "failure": "", "force_N": 4.5e-4,
                 "pressed": 18, "zones": [{"force_N": 4.5e-4, "centroid_m": [0.003, 0, 0.0195],
                 "extent_m": 0.001, "nodes": 18}], "clamp_axial_N": 1.4e-4,
                 "clamp_moment_Nm": 1e-6, "push_N": 4.5e-5, "push_by_energy_N": null,
                 "energy_J": 1e-8, "tip_m": [0.00307, 0, 0.01972], "dent_m": 2.48e-4,
                 "newton_steps": 19, "seconds": 18.9},
                {"insertion_m": 0.0205, "converged": false, "failure": "Newton did not converge",
                 "force_N": 0, "pressed": 0, "zones": [], "clamp_axial_N": 0,
                 "clamp_moment_Nm": 0, "push_N": 0, "push_by_energy_N": null, "energy_J": 0,
                 "tip_m": [0, 0, 0], "dent_m": 0, "newton_steps": 300, "seconds": 99.0}]}]})");
  auto r = vv("report " + kBaseline + " --insertion " + (dir / "insertion.json").string() + " -o " +
              dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string md = read_text(dir / "report.md");
  EXPECT_TRUE(contains(md, "## The guidewire pushed in")) << md;
  EXPECT_TRUE(contains(md, "### guidewire_straight, reference, EI 4e-07 N·m²")) << md;
  EXPECT_TRUE(contains(md, "FEM P1 (deal.II), neo-Hookean; 5546 nodes")) << md;
  EXPECT_TRUE(contains(md,
                       "| 20.000 | 0.45000 | 18 | 19.50: 0.4500 | 0.248 | 0.14000 | 0.04500 | — | "
                       "(3.07, 0.00, 19.72) | 19 | 18.9 |"))
      << md;
  EXPECT_TRUE(contains(md, "| 20.500 | not converged: Newton did not converge |")) << md;
  EXPECT_TRUE(std::filesystem::exists(dir / "figures" / "insertion.svg"));

  write_text(dir / "broken.json", R"({"schema": "vesselverify.insertion", "schema_version": 1,
    "command": "c", "total_seconds": 1.0})");
  r = vv("report " + kBaseline + " --insertion " + (dir / "broken.json").string() + " -o " +
         (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "broken.json: missing field 'insertions'")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "report.md"));
}

TEST(ReportCli, AStudyFileOfAnotherKindIsAClearErrorNamingIt) {
  TempDir dir;
  auto r = vv("report " + kBaseline + " --stability " + kBaseline + " -o " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "baseline.json: not a vesselverify stability file (expected "
                                 "\"schema\": \"vesselverify.stability\""))
      << r.output;
  write_text(dir / "recommend.json", "{\"schema\": \"vesselverify.recommend\", \"schema_version\": 1");
  r = vv("report " + kBaseline + " --recommend " + (dir / "recommend.json").string() + " -o " +
         dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "recommend.json: not valid JSON")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "report.md"));
}

TEST(GateCli, TheBaselineAgainstItselfPasses) {
  TempDir dir;
  const auto r = vv("gate --baseline " + kBaseline + " --current " + kBaseline + " --output-dir " +
                    dir.path().string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "Gate passed")) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "gate.md"));
}

TEST(GateCli, AModelWhoseErrorGrewFailsWithATable) {
  // A baseline where the volume model was 2x more accurate: this run's error "grew".
  TempDir dir;
  doctored_baseline(dir / "baseline.json", "volume_mollemans", [](nlohmann::json& o) {
    o["error"]["max_mm"] = o["error"]["max_mm"].get<double>() / 2;
  });
  const auto r = vv("gate --baseline " + (dir / "baseline.json").string() + " --current " +
                    kBaseline + " --output-dir " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "Gate FAILED")) << r.output;
  EXPECT_TRUE(contains(r.output, "| FAIL | contact_straight | volume_mollemans |")) << r.output;
  EXPECT_TRUE(contains(r.output, "max error grew")) << r.output;
}

TEST(GateCli, AModelThatFinishedAndNowFailsFailsTheGate) {
  // Here the baseline is this run and the "current" results have the surface model diverging.
  TempDir dir;
  doctored_baseline(dir / "current.json", "surface_seed000", [](nlohmann::json& o) {
    o["ok"] = false;
    o["failure"] = "diverged at step 7 (node 3, energy 1e9 J)";
  });
  const auto r = vv("gate --baseline " + kBaseline + " --current " +
                    (dir / "current.json").string() + " --output-dir " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "now fails")) << r.output;
  EXPECT_TRUE(contains(r.output, "diverged at step 7")) << r.output;
}

TEST(GateCli, AMissingBaselineSaysHowToCreateIt) {
  TempDir dir;
  const auto r = vv("gate --baseline " + (dir / "none.json").string() + " --current " + kBaseline +
                    " --output-dir " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "none.json: baseline not found")) << r.output;
  EXPECT_TRUE(contains(r.output, "--update-baseline")) << r.output;
}
