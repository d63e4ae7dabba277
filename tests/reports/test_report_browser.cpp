// report.html in a real browser: Debian's chromium, headless, WebGL by SwiftShader
// (scripts/headless_chromium.sh). The report of a small committed results folder is written, a
// copy gets tests/reports/browser_probe.js at the top of its <head>, and chromium's --dump-dom
// returns what the probe found. The expected counts come from results.json, not from the page.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "../test_helpers.hpp"
#include "reports/report.hpp"

using namespace vessel;
using namespace vessel::reports;

namespace {

const std::filesystem::path kFixture = VESSEL_REPORT_FIXTURE;
const std::filesystem::path kProbe = VESSEL_BROWSER_PROBE;
const std::filesystem::path kScreenshots = VESSEL_SCREENSHOT_SCRIPT;

std::filesystem::path headless_chromium() {
  return kScreenshots.parent_path() / "headless_chromium.sh";
}

/// A point of a straight tube along z (its length `length`) bent into an arch standing on two
/// legs in the y-z plane: a leg up (0.3 of the length), a half circle over the top (0.4), a leg
/// down (0.3). The tube's x stays x, its y follows the arch's outward normal; `vector` turns a
/// vector at the point instead of moving the point.
std::array<double, 3> on_arch(const std::array<double, 3>& p, double length, bool vector = false,
                              const std::array<double, 3>& at = {}) {
  const double s = vector ? at[2] : p[2], leg = 0.3 * length, rb = 0.4 * length / M_PI;
  std::array<double, 3> c{}, t{}, n{};  // centreline point, tangent, outward normal
  if (s < leg) {
    c = {0, s, 0}, t = {0, 1, 0}, n = {0, 0, -1};
  } else if (s < leg + M_PI * rb) {
    const double th = (s - leg) / rb;
    c = {0, leg + rb * std::sin(th), rb * (1 - std::cos(th))};
    t = {0, std::cos(th), std::sin(th)}, n = {0, std::sin(th), -std::cos(th)};
  } else {
    c = {0, leg - (s - leg - M_PI * rb), 2 * rb}, t = {0, -1, 0}, n = {0, 0, 1};
  }
  if (vector) c = {0, 0, 0};
  const double along = vector ? p[2] : 0.0;
  return {c[0] + p[0], c[1] + p[1] * n[1] + along * t[1], c[2] + p[1] * n[2] + along * t[2]};
}

/// The fixture's tube scene as a second scene, "arch": its VTU fields' points bent by on_arch
/// and their displacements turned with them, its QoI point and contact patch moved alike, no
/// guidewire. A shape whose bounding box is a poor guess of its extent on screen.
void add_arch_scene(const std::filesystem::path& results_dir) {
  auto results = nlohmann::json::parse(test::read_text(results_dir / "results.json"));
  nlohmann::json arch = results["scenes"][0];
  const std::string tube = arch["name"];
  arch["name"] = "arch";
  arch["guidewire"] = nullptr;
  const double length_mm = 40.0;  // the fixture tube's z from 0 to 40 mm
  auto moved = [&](const nlohmann::json& mm) {
    const auto q = on_arch({mm[0].get<double>(), mm[1].get<double>(), mm[2].get<double>()}, length_mm);
    return nlohmann::json::array({q[0], q[1], q[2]});
  };
  arch["qoi_point_mm"] = moved(arch["qoi_point_mm"]);
  if (arch["contact_patch"].is_object()) {
    const auto p = arch["contact_patch"]["point_mm"];
    arch["contact_patch"]["point_mm"] = moved(p);
    const auto& n = arch["contact_patch"]["outward_normal"];
    const auto q = on_arch({n[0].get<double>(), n[1].get<double>(), n[2].get<double>()}, length_mm,
                           true, {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
    arch["contact_patch"]["outward_normal"] = {q[0], q[1], q[2]};
  }
  results["scenes"].push_back(arch);
  test::write_text(results_dir / "results.json", results.dump(1));
  std::filesystem::create_directories(results_dir / "fields" / "arch");
  for (const auto& entry : std::filesystem::directory_iterator(results_dir / "fields" / tube)) {
    std::istringstream in(test::read_text(entry.path()));
    std::ostringstream out;
    std::string line;
    std::vector<std::array<double, 3>> points;  // the tube's, to turn the displacements at
    enum { kNone, kPoints, kVectors } next = kNone;
    while (std::getline(in, line)) {
      if (next != kNone) {
        std::istringstream values(line);
        std::vector<double> v{std::istream_iterator<double>(values), std::istream_iterator<double>()};
        std::ostringstream bent;
        bent.precision(12);
        for (std::size_t i = 0; i + 2 < v.size(); i += 3) {
          const std::array<double, 3> x{v[i], v[i + 1], v[i + 2]};
          if (next == kPoints) points.push_back(x);
          const auto q = next == kPoints ? on_arch(x, length_mm * 1e-3)
                                         : on_arch(x, length_mm * 1e-3, true, points.at(i / 3));
          bent << q[0] << ' ' << q[1] << ' ' << q[2] << ' ';
        }
        line = bent.str();
        next = kNone;
      } else if (line.rfind("<DataArray", 0) == 0 && line.find("Name=") == std::string::npos) {
        next = kPoints;  // the <Points> array, which alone has no name
      } else if (line.rfind("<DataArray", 0) == 0 && line.find("Name=\"displacement_") != std::string::npos) {
        next = kVectors;
      }
      out << line << '\n';
    }
    test::write_text(results_dir / "fields" / "arch" / entry.path().filename(), out.str());
  }
}

/// The fixture's report written and probed in chromium once, on first use; the probe's JSON.
/// (Done in the first test that asks, not in SetUpTestSuite, so a failure here fails tests
/// rather than skipping them.)
struct Probed {
  test::TempDir dir;
  nlohmann::json probe;
  std::string problem;  ///< why there is no probe, else empty
};

Probed& probed() {
  // Owned by a static (not leaked): its directory is removed when the test program exits.
  static const std::unique_ptr<Probed> p = [] {
    auto p = std::make_unique<Probed>();
    std::filesystem::copy(kFixture, p->dir / "results", std::filesystem::copy_options::recursive);
    add_arch_scene(p->dir / "results");
    ReportOptions o;
    o.results = p->dir / "results" / "results.json";
    o.output_dir = p->dir.path();
    o.command = "report_browser_tests";
    write_report(o);
    std::string page = test::read_text(p->dir / "report.html");
    const auto head = page.find("<head>");
    page.insert(head + 6, "<script>" + test::read_text(kProbe) + "</script>");
    test::write_text(p->dir / "probed.html", page);
    // stdout (the DOM) to a file of its own: chromium's log lines on stderr would interleave.
    const test::CommandResult r = test::run_command(
        headless_chromium().string() + " --window-size=1280,900 --virtual-time-budget=30000 "
        "--dump-dom file://" + (p->dir / "probed.html").string() + " > " +
        (p->dir / "dom.html").string() + " 2> " + (p->dir / "chromium.log").string());
    if (r.exit_code != 0) {
      p->problem = "chromium failed (" + std::to_string(r.exit_code) + "): " + r.output +
                   test::read_text(p->dir / "chromium.log");
      return p;
    }
    const std::string dom = test::read_text(p->dir / "dom.html");
    const std::string open = "<pre id=\"vv-probe\">";
    const auto at = dom.rfind(open);
    if (at == std::string::npos) {
      p->problem = "the probe wrote nothing; chromium's log:\n" + test::read_text(p->dir / "chromium.log");
      return p;
    }
    const auto start = at + open.size();
    std::string text = dom.substr(start, dom.find("</pre>", start) - start);
    // --dump-dom escapes &, < and > in text.
    for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
             {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
      for (auto q = text.find(from); q != std::string::npos; q = text.find(from, q + 1)) {
        text.replace(q, from.size(), to);
      }
    }
    p->probe = nlohmann::json::parse(text);
    return p;
  }();
  return *p;
}

class ReportInBrowser : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(probed().problem, ""); }
  static const nlohmann::json& probe() { return probed().probe; }
  static const std::filesystem::path& dir() { return probed().dir.path(); }
};

}  // namespace

TEST_F(ReportInBrowser, NoConsoleError) {
  ASSERT_TRUE(probe().contains("errors"));
  EXPECT_TRUE(probe()["errors"].empty()) << probe()["errors"].dump(1);
}

TEST_F(ReportInBrowser, EachThreeDViewDrawsItsModels) {
  const ResultsFile results = read_results(dir() / "results" / "results.json");
  ASSERT_EQ(probe()["views"].size(), results.scenes.size());
  for (const auto& view : probe()["views"]) {
    ASSERT_EQ(view["panes"].size(), 2U) << view["scene"];
    // Every finished model of the scene has a wall to draw (the fixture has a VTU for each).
    std::size_t finished = 0;
    for (const SceneRows& s : results.scenes) {
      if (s.name != view["scene"]) continue;
      std::set<std::string> models;
      for (const OutcomeRow& o : s.outcomes) {
        if (o.ok && o.magnitude == representative_load(s)) models.insert(o.model);
      }
      finished = models.size();
    }
    EXPECT_EQ(view["models"].size(), finished) << view["scene"];
    auto panes = view["panes"];
    for (const auto& m : view["models"]) panes.push_back(m);
    for (const auto& pane : panes) {
      // The wall covers part of the pane (not all background) and is shaded and coloured by the
      // error (many colours, not one flat fill).
      const double pixels = pane["pixels"];
      EXPECT_GT(pane["drawn"].get<double>(), 0.02 * pixels) << view["scene"] << " " << pane["model"];
      EXPECT_LT(pane["drawn"].get<double>(), pixels) << view["scene"] << " " << pane["model"];
      EXPECT_GT(pane["colours"].get<int>(), 20) << view["scene"] << " " << pane["model"];
    }
  }
}

TEST_F(ReportInBrowser, EachThreeDViewShowsItsWholeVessel) {
  // The camera fits the models' bounding sphere: no drawn pixel on the pane's outermost rows and
  // columns, for every model in every view, the arch (legs far from its bounding box's centre)
  // included.
  bool arch = false;
  for (const auto& view : probe()["views"]) {
    arch = arch || view["scene"] == "arch";
    auto panes = view["panes"];
    for (const auto& m : view["models"]) panes.push_back(m);
    for (const auto& pane : panes) {
      EXPECT_EQ(pane["edge_drawn"].get<int>(), 0) << view["scene"] << " " << pane["model"];
    }
  }
  EXPECT_TRUE(arch) << "the arch scene has no view";
}

TEST_F(ReportInBrowser, BothPanesDrawOneModelAlike) {
  // The two panes share one camera and are the same size, so one model in both is one picture
  // (lit alike: each pane has its own headlight), up to the pixel the panes' edges round to.
  ASSERT_FALSE(probe()["views"].empty());
  for (const auto& view : probe()["views"]) {
    const auto& twin = view["twin"];
    ASSERT_EQ(twin["pixels"], twin["other_pixels"]) << view["scene"];
    EXPECT_LT(twin["differing"].get<double>(), 0.01 * twin["pixels"].get<double>())
        << view["scene"] << " " << twin.dump();
  }
}

TEST_F(ReportInBrowser, TheGuidewireIsDrawnThroughTheWallWhereResultsJsonHasOne) {
  const ResultsFile results = read_results(dir() / "results" / "results.json");
  std::size_t wires = 0;
  for (const auto& view : probe()["views"]) {
    for (const SceneRows& s : results.scenes) {
      if (s.name != view["scene"]) continue;
      if (!s.guidewire || s.guidewire->rigid.empty()) {
        EXPECT_TRUE(view["wire"].is_null()) << s.name;
        continue;
      }
      ++wires;
      const auto& w = view["wire"];
      ASSERT_TRUE(w.is_object()) << s.name << ": no wire drawn";
      EXPECT_EQ(w["points"].get<std::size_t>(), s.guidewire->rigid[0].centreline_mm.size());
      EXPECT_EQ(w["coupled"].get<bool>(), !s.guidewire->rigid[0].reference_centreline_mm.empty());
      // Hiding the wire changes the pane (it is drawn over the wall, not hidden by it), and
      // takes its orange away.
      EXPECT_GT(w["changed"].get<int>(), 150) << w.dump();
      EXPECT_GT(w["orange_on"].get<int>(), w["orange_off"].get<int>() + 100) << w.dump();
    }
  }
  EXPECT_GE(wires, 1u) << "the fixture has a guidewire scene";
}

TEST_F(ReportInBrowser, HoveringTheWallGivesTheNodesErrorAndDisplacements) {
  const auto& n = probe()["node_hover"];
  ASSERT_TRUE(n.is_object()) << "no node found under the pointer in the first pane";
  EXPECT_GE(n["colour_value"].get<double>(), 0.0);
  ASSERT_EQ(n["u_model_mm"].size(), 3U);
  ASSERT_EQ(n["u_reference_mm"].size(), 3U);
  // |u_model − u_reference| is the error the page shows, within its quantisation and float32.
  double d2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double d = n["u_model_mm"][c].get<double>() - n["u_reference_mm"][c].get<double>();
    d2 += d * d;
  }
  EXPECT_NEAR(std::sqrt(d2), n["colour_value"].get<double>(), 1e-3 + 1e-3 * std::sqrt(d2));
}

TEST_F(ReportInBrowser, SpeedErrorPlotHasAPointPerFinishedOutcome) {
  const ResultsFile results = read_results(dir() / "results" / "results.json");
  for (const SceneRows& s : results.scenes) {
    const double load = representative_load(s);
    std::size_t expected = 0;
    for (const OutcomeRow& o : s.outcomes) expected += o.ok && o.magnitude == load;
    bool found = false;
    for (const auto& chart : probe()["charts"]) {
      if (chart["title"].get<std::string>().rfind(s.name + ": speed against error", 0) != 0) continue;
      found = true;
      std::size_t points = 0;
      for (const auto& series : chart["series"]) points += series["labelled"].get<std::size_t>();
      EXPECT_EQ(points, expected) << s.name;
    }
    EXPECT_TRUE(found) << "no speed-error plot for " << s.name;
  }
}

TEST_F(ReportInBrowser, EveryPlotOfTheReportIsDrawnWithItsSeries) {
  // Every figure with data becomes a chart, and each series keeps its points.
  const std::string page = test::read_text(dir() / "report.html");
  std::size_t figures = 0;
  for (auto at = page.find("class=\"vv-chart\""); at != std::string::npos;
       at = page.find("class=\"vv-chart\"", at + 1)) {
    ++figures;
  }
  EXPECT_EQ(probe()["charts"].size(), figures);
  for (const auto& chart : probe()["charts"]) {
    std::size_t points = 0;
    for (const auto& series : chart["series"]) points += series["points"].get<std::size_t>();
    EXPECT_GT(points, 1U) << chart["title"];
  }
}

TEST_F(ReportInBrowser, HoverOnAPointNamesItsModel) {
  const auto& h = probe()["hover"];
  ASSERT_TRUE(h.is_object());
  EXPECT_TRUE(h["visible"].get<bool>());
  const std::string dataset = h["dataset"];
  const std::string model = dataset.substr(0, dataset.find(" (L"));
  EXPECT_NE(h["text"].get<std::string>().find(model), std::string::npos) << h.dump();
  EXPECT_NE(h["text"].get<std::string>().find("ν ="), std::string::npos) << h.dump();
}

TEST_F(ReportInBrowser, ScreenshotScriptWritesTheFirstScreenAndAThreeDView) {
  const std::filesystem::path out = dir() / "shots";
  const test::CommandResult r = test::run_command(
      kScreenshots.string() + " " + (dir() / "report.html").string() + " " + out.string() +
      " " + read_results(dir() / "results" / "results.json").scenes.front().name);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* png : {"report_first_screen.png", "report_3d_view.png"}) {
    const std::string bytes = test::read_text(out / png);
    ASSERT_GT(bytes.size(), 10000U) << png;
    EXPECT_EQ(bytes.substr(1, 3), "PNG") << png;
  }
}
