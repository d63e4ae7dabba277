// report.html without a browser: its 3D data against the VTU files it was read from, the
// libraries inlined once and nothing that reaches the network, the page without the libraries,
// and the scene cards' answers on hand-made results.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <regex>

#include <nlohmann/json.hpp>

#include "meshes/foundation/errors.hpp"
#include "meshes/vtu_io.hpp"
#include "reports/report.hpp"
#include "reports/scene_card.hpp"
#include "reports/wall_view.hpp"
#include "reports/web_page.hpp"
#include "../test_helpers.hpp"

using namespace vessel;
using namespace vessel::reports;

namespace {

const std::filesystem::path kFixture = VESSEL_REPORT_FIXTURE;  // a small results folder

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

/// The report of the fixture written into `dir` (libraries from `js_dir`); report.html's text.
std::string write_fixture_report(const std::filesystem::path& dir, const std::string& js_dir) {
  setenv("VESSELVERIFY_JS_DIR", js_dir.c_str(), 1);
  ReportOptions o;
  o.results = kFixture / "results.json";
  o.output_dir = dir;
  o.command = "test";
  write_report(o);
  unsetenv("VESSELVERIFY_JS_DIR");
  return test::read_text(dir / "report.html");
}

/// The JSON inside <script type="application/json" id="`id`">.
nlohmann::json script_json(const std::string& page, const std::string& id) {
  const std::string open = "id=\"" + id + "\">";
  const auto begin = page.find(open);
  if (begin == std::string::npos) return nullptr;
  const auto start = begin + open.size();
  return nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
}

template <class T>
std::vector<T> decode_as(const std::string& b64) {
  const std::vector<std::uint8_t> bytes = base64_decode(b64);
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

}  // namespace

TEST(Base64, MatchesRfc4648TestVectors) {
  // RFC 4648 §10.
  const std::map<std::string, std::string> vectors{{"", ""},         {"f", "Zg=="},
                                                   {"fo", "Zm8="},   {"foo", "Zm9v"},
                                                   {"foob", "Zm9vYg=="}, {"fooba", "Zm9vYmE="},
                                                   {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(base64_encode(plain.data(), plain.size()), encoded) << plain;
    const auto back = base64_decode(encoded);
    EXPECT_EQ(std::string(back.begin(), back.end()), plain);
  }
  EXPECT_THROW(base64_decode("Zm9v!"), InputError);
}

TEST(BoundaryFaces, TwoTetsSharingAFaceKeepTheOtherSix) {
  // Tets (0,1,2,3) and (1,2,3,4) share face {1,2,3}.
  const std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  const auto faces = boundary_faces({0, 1, 2, 3, 1, 2, 3, 4}, p);
  ASSERT_EQ(faces.size(), 18U);
  for (std::size_t f = 0; f < faces.size(); f += 3) {
    std::array<std::uint32_t, 3> k{faces[f], faces[f + 1], faces[f + 2]};
    std::sort(k.begin(), k.end());
    EXPECT_NE(k, (std::array<std::uint32_t, 3>{1, 2, 3}));
  }
}

TEST(BoundaryFaces, FacesPointOutwardsWhateverTheTetsOrientation) {
  // The unit tet listed with positive and with negative orientation: each face's normal
  // (right-hand rule) points away from the tet's centroid.
  const std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Vec3 centroid = (p[0] + p[1] + p[2] + p[3]) / 4.0;
  for (const std::vector<std::size_t>& tet : {std::vector<std::size_t>{0, 1, 2, 3},
                                              std::vector<std::size_t>{0, 2, 1, 3}}) {
    const auto faces = boundary_faces(tet, p);
    ASSERT_EQ(faces.size(), 12U);
    for (std::size_t f = 0; f < faces.size(); f += 3) {
      const Vec3 n = (p[faces[f + 1]] - p[faces[f]]).cross(p[faces[f + 2]] - p[faces[f]]);
      EXPECT_GT(n.dot(p[faces[f]] - centroid), 0.0);
    }
  }
}

TEST(WallView, KeepsOnlyTheBoundaryNodesAndQuantisesTheErrorToHalfAStep) {
  test::TempDir dir;
  // Two tets around an interior-free pair, plus a node no cell uses (not drawn).
  const std::vector<Vec3> points{{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3},
                                 {1e-3, 1e-3, 1e-3}, {5e-3, 5e-3, 5e-3}};
  VtuCells cells{10, 4, {0, 1, 2, 3, 1, 2, 3, 4}};
  VtuField um{"displacement_model_m", 3, {}}, ur{"displacement_reference_m", 3, {}};
  VtuField err{"error_magnitude_mm", 1, {}};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 a{1e-6 * i, 0, 0}, b{0, 2e-6 * i, 0};
    for (int c = 0; c < 3; ++c) {
      um.values.push_back(a[c]);
      ur.values.push_back(b[c]);
    }
    err.values.push_back((a - b).norm() * 1e3);
  }
  write_vtu(dir / "w.vtu", points, cells, {um, ur, err});
  const WallView v = wall_view(read_vtu(dir / "w.vtu"), "w.vtu");
  EXPECT_FALSE(v.lines);
  EXPECT_EQ(v.indices.size(), 18U);
  ASSERT_EQ(v.rest_mm.size(), 15U);  // nodes 0-4; node 5 is in no cell
  for (std::size_t k = 0; k < 5; ++k) {
    // Node k of the view is a VTU node: find it by position, then compare every field.
    std::size_t i = 0;
    while (std::abs(points[i].x() * 1e3 - v.rest_mm[3 * k]) > 1e-6 ||
           std::abs(points[i].y() * 1e3 - v.rest_mm[3 * k + 1]) > 1e-6 ||
           std::abs(points[i].z() * 1e3 - v.rest_mm[3 * k + 2]) > 1e-6) {
      ++i;
    }
    EXPECT_NEAR(v.u_model_mm[3 * k], 1e-3 * i, 1e-9);
    EXPECT_NEAR(v.u_reference_mm[3 * k + 1], 2e-3 * i, 1e-9);
    EXPECT_NEAR(v.colour_code[k] * v.colour_step, err.values[i], 0.5 * v.colour_step + 1e-15);
  }
}

TEST(WallView, MissingFieldNamesTheFile) {
  test::TempDir dir;
  write_vtu(dir / "bare.vtu", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {5, 3, {0, 1, 2}});
  try {
    wall_view(read_vtu(dir / "bare.vtu"), "bare.vtu");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bare.vtu"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("displacement_model_m"), std::string::npos);
  }
}

TEST(WebReport, ThePageCarriesTheContactPatchWhereResultsJsonPutsIt) {
  test::TempDir dir;
  const std::string page = write_fixture_report(dir.path(), default_javascript_dir().string());
  const nlohmann::json scene = script_json(page, "vv-scene-0");
  ASSERT_TRUE(scene["patch"].is_object()) << scene["patch"];
  EXPECT_EQ(scene["patch"]["point_mm"], nlohmann::json({3, 0, 20}));  // the fixture's
  EXPECT_EQ(scene["patch"]["radius_mm"], 1.5);
  EXPECT_EQ(scene["patch"]["normal"], nlohmann::json({1, 0, 0}));
}

TEST(WebReport, ThePageCarriesTheWiresCentrelinesAsResultsJsonGivesThem) {
  test::TempDir dir;
  const std::string page = write_fixture_report(dir.path(), default_javascript_dir().string());
  const nlohmann::json wire = script_json(page, "vv-scene-0")["wire"];
  ASSERT_TRUE(wire.is_object()) << wire;
  const nlohmann::json g =
      nlohmann::json::parse(test::read_text(kFixture / "results.json"))["scenes"][0]["guidewire"];
  EXPECT_EQ(wire["rigid_mm"], g["rigid"][0]["centreline_mm"]);
  EXPECT_EQ(wire["coupled_mm"], g["rigid"][0]["reference_coupled"]["centreline_mm"]);
  EXPECT_DOUBLE_EQ(wire["radius_mm"].get<double>(), 0.178);  // the fixture's 0.356 mm wire
  EXPECT_EQ(wire["rigid_mm"].front(), nlohmann::json({0.0, 0.0, 0.0}));  // its clamp
  EXPECT_NE(page.find("class=\"vv-wire\""), std::string::npos);
  EXPECT_NE(page.find("Orange tube: the guidewire coupled with the reference"), std::string::npos);
  // Without the reference's coupled wire (rigid coupling) the page draws the rigid one alone.
  auto j = nlohmann::json::parse(test::read_text(kFixture / "results.json"));
  j["scenes"][0]["guidewire"]["rigid"][0]["reference_coupled"] = nullptr;
  const SceneViews v = read_scene_views(parse_results(j.dump(), "r.json").scenes[0], kFixture);
  ASSERT_TRUE(v.wire.has_value());
  EXPECT_TRUE(v.wire->coupled_mm.empty());
  EXPECT_EQ(v.wire->rigid_mm.size(), g["rigid"][0]["centreline_mm"].size());
  // A scene without a wire has none.
  j["scenes"][0].erase("guidewire");
  EXPECT_FALSE(read_scene_views(parse_results(j.dump(), "r.json").scenes[0], kFixture).wire);
}

TEST(WebReport, TheValiditySectionDrawsTheModelsAgainstTheFiniteStrainReference) {
  test::TempDir dir;
  setenv("VESSELVERIFY_JS_DIR", default_javascript_dir().c_str(), 1);
  ReportOptions o;
  o.results = kFixture / "results.json";
  o.validity = kFixture / "validity.json";
  o.output_dir = dir.path();
  o.command = "test";
  write_report(o);
  unsetenv("VESSELVERIFY_JS_DIR");
  const std::string page = test::read_text(dir / "report.html");
  // One view per results scene, then the validity scene's: its model at the largest load, read
  // from the VTU validity.json names (the fixture's copy of the run's volume_springs field).
  const nlohmann::json scene = script_json(page, "vv-scene-1");
  ASSERT_FALSE(scene.is_null());
  EXPECT_EQ(scene["name"], "validity-tube");
  ASSERT_EQ(scene["views"].size(), 1u);
  EXPECT_EQ(scene["views"][0]["model"], "volume_springs");
  EXPECT_EQ(scene["load"], "1 mN");
  EXPECT_EQ(count(page, "id=\"view-validity-tube\""), 1u) << "no section for the view";
  EXPECT_EQ(count(page, "Here the reference is the finite-strain"), 1u) << "caption";
  const nlohmann::json run_view = script_json(page, "vv-scene-0")["views"];
  for (const auto& v : run_view) {
    if (v["model"] == "volume_springs") EXPECT_EQ(v["err"], scene["views"][0]["err"]);
  }
}

TEST(WebReport, DecodedErrorsEqualTheVtusWithinTheQuantisationStep) {
  test::TempDir dir;
  const std::string page = write_fixture_report(dir.path(), default_javascript_dir().string());
  const ResultsFile results = read_results(kFixture / "results.json");
  std::size_t checked = 0;
  for (std::size_t s = 0; s < results.scenes.size(); ++s) {
    const nlohmann::json scene = script_json(page, "vv-scene-" + std::to_string(s));
    ASSERT_FALSE(scene.is_null()) << "no data for scene " << s;
    for (const auto& view : scene["views"]) {
      OutcomeRow o;
      for (const OutcomeRow& r : results.scenes[s].outcomes) {
        if (r.ok && r.model == view["model"] && r.level == view["level"] &&
            r.magnitude == representative_load(results.scenes[s]) &&
            r.poisson_ratio == results.scenes[s].references.front().poisson_ratio) {
          o = r;
        }
      }
      ASSERT_FALSE(o.fields.empty()) << view["model"];
      const VtuData vtu = read_vtu(kFixture / o.fields);
      const VtuField* err = VtuData::find(vtu.point_fields, "error_magnitude_mm");
      ASSERT_NE(err, nullptr);
      const auto rest = decode_as<float>(view["rest"]);
      const auto code = decode_as<std::uint16_t>(view["err"]);
      const double step = view["step"];
      ASSERT_EQ(rest.size(), 3 * code.size());
      std::map<std::array<long, 3>, std::size_t> node_at;  // VTU nodes by position (µm)
      for (std::size_t i = 0; i < vtu.points.size(); ++i) {
        node_at[{std::lround(vtu.points[i].x() * 1e6), std::lround(vtu.points[i].y() * 1e6),
                 std::lround(vtu.points[i].z() * 1e6)}] = i;
      }
      for (std::size_t k = 0; k < code.size(); ++k) {
        const auto it = node_at.find({std::lround(rest[3 * k] * 1e3),
                                      std::lround(rest[3 * k + 1] * 1e3),
                                      std::lround(rest[3 * k + 2] * 1e3)});
        ASSERT_NE(it, node_at.end()) << view["model"] << " node " << k;
        EXPECT_NEAR(code[k] * step, err->values[it->second], step) << view["model"] << " node " << k;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100U);
}

TEST(WebReport, InlinesEachLibraryOnceAndReachesNoNetwork) {
  test::TempDir dir;
  const std::string page = write_fixture_report(dir.path(), default_javascript_dir().string());
  EXPECT_EQ(count(page, "data-library=\"three.js\""), 1U);
  EXPECT_EQ(count(page, "data-library=\"Chart.js\""), 1U);
  EXPECT_EQ(count(page, "REVISION=\"111\""), 1U);  // three.js's own code, once
  EXPECT_EQ(count(page, "Chart.js v3.9.1"), 1U);
  // No element loads anything: in the markup (scripts' contents aside) no src, no href but to
  // the page's own anchors, no CSS url() or @import.
  std::string markup = page;
  for (auto at = markup.find("<script"); at != std::string::npos; at = markup.find("<script", at + 1)) {
    const auto end = markup.find("</script>", at);
    markup.erase(markup.find('>', at) + 1, end - markup.find('>', at) - 1);
  }
  EXPECT_EQ(count(markup, "src="), 0U);
  EXPECT_FALSE(std::regex_search(markup, std::regex(R"(href="[^#])")));
  EXPECT_EQ(count(markup, "url("), 0U);
  EXPECT_EQ(count(markup, "@import"), 0U);
  EXPECT_GT(markup.size(), 10000U);
  // "http" only in strings that fetch nothing: XML namespaces (three.js makes its canvas with
  // createElementNS; inline SVG) and the libraries' licence comments.
  const std::vector<std::string> inert{"http://www.w3.org/1999/xhtml", "http://www.w3.org/2000/svg",
                                       "https://www.chartjs.org", "https://github.com/kurkle/color#readme",
                                       "https://graphics.stanford.edu/papers/envmap/envmap.pdf"};
  for (auto at = page.find("http"); at != std::string::npos; at = page.find("http", at + 1)) {
    bool known = false;
    for (const std::string& s : inert) known = known || page.compare(at, s.size(), s) == 0;
    EXPECT_TRUE(known) << "network reference: " << page.substr(at, 60);
  }
  EXPECT_NE(page.find("MIT"), std::string::npos);  // the licences in the footer
}

TEST(WebReport, WithoutTheLibrariesKeepsTheSvgFiguresAndSaysWhichIsMissing) {
  test::TempDir dir, empty;
  const std::string page = write_fixture_report(dir.path(), empty.path().string());
  EXPECT_NE(page.find("libjs-three"), std::string::npos);
  EXPECT_NE(page.find("libjs-chart.js"), std::string::npos);
  EXPECT_EQ(count(page, "<script"), 0U);
  EXPECT_GT(count(page, "<svg"), 3U);
  EXPECT_NE(page.find("vv-card"), std::string::npos);  // the answers need no script
  EXPECT_TRUE(std::filesystem::exists(dir / "report.md"));
}

namespace {

OutcomeRow row(const std::string& model, const std::string& kind, double max_mm, double rel,
               double seconds) {
  OutcomeRow o;
  o.model = model;
  o.kind = kind;
  o.detail = kind == "fem" ? "P1, direct" : "springs";
  o.poisson_ratio = 0.45;
  o.magnitude = 1e-3;
  o.ok = true;
  o.max_mm = max_mm;
  o.relative_l2 = rel;
  o.solve_seconds = seconds;
  return o;
}

ResultsFile one_scene(std::vector<OutcomeRow> outcomes) {
  ResultsFile r;
  SceneRows s;
  s.name = "contact_straight";
  s.load = "contact";
  s.load_unit = "N";
  s.model_levels = {0};
  s.tolerance_mm = 0.1;
  s.references.push_back({0.45, "P2", 1, 1000, 0.5, 1.0});
  s.outcomes = std::move(outcomes);
  r.scenes.push_back(s);
  return r;
}

}  // namespace

TEST(SceneCards, RecommendTheFastestWithinToleranceAndNameTheMostAccurateSpringModel) {
  OutcomeRow failed = row("surface_pbd", "surface_msm", 0, 0, 0.1);
  failed.ok = false;
  failed.failure = "diverged at step 12: energy 3e5 J. Try a smaller dt; see docs.";
  const auto cards = scene_cards(one_scene({row("fem_p1", "fem", 0.05, 0.02, 0.004),
                                            row("springs_fast", "volume_msm", 0.08, 0.30, 0.001),
                                            row("springs_good", "volume_msm", 0.2, 0.10, 0.0005),
                                            row("springs_slow", "volume_msm", 0.09, 0.20, 0.01),
                                            failed}));
  ASSERT_EQ(cards.size(), 1U);
  const SceneCard& c = cards.front();
  // Within 0.1 mm: fem_p1 (0.004 s), springs_fast (0.001 s), springs_slow (0.01 s).
  ASSERT_TRUE(c.recommended);
  EXPECT_EQ(c.recommended->outcome.model, "springs_fast");
  EXPECT_TRUE(c.recommended->passes);
  EXPECT_NEAR(*c.recommended->ratio_to_p1, 0.30 / 0.02, 1e-12);
  // Lowest relative L2 among the spring models, whether or not it passes.
  ASSERT_TRUE(c.best_spring);
  EXPECT_EQ(c.best_spring->outcome.model, "springs_good");
  EXPECT_FALSE(c.best_spring->passes);
  ASSERT_EQ(c.failures.size(), 1U);
  EXPECT_EQ(c.failures[0].reason, "diverged at step 12: energy 3e5 J");
  EXPECT_EQ(c.failures[0].message, failed.failure);
}

TEST(SceneCards, WithABudgetJudgeTheBudgetsQuantityAndTime) {
  ResultsFile r = one_scene({row("a", "volume_msm", 0.01, 0.1, 0.02),
                             row("b", "volume_msm", 0.5, 0.1, 0.001)});
  r.scenes[0].budget = BudgetRow{"contact_point", "mm", 0.05, 30.0, 1.0 / 30};
  r.scenes[0].outcomes[0].budget_error = 0.01;   // accurate,
  r.scenes[0].outcomes[0].update_seconds = 0.05;  // but 50 ms per update: over the 33 ms budget
  r.scenes[0].outcomes[1].budget_error = 0.04;
  r.scenes[0].outcomes[1].update_seconds = 0.001;
  const auto cards = scene_cards(r);
  ASSERT_TRUE(cards[0].recommended);
  EXPECT_EQ(cards[0].recommended->outcome.model, "b");  // max error 0.5 mm, but the budget's
                                                        // quantity is within 0.05 mm
  EXPECT_DOUBLE_EQ(cards[0].recommended->update_seconds, 0.001);
}

TEST(SceneCards, FirstSentenceCutsLongMessagesWithoutSplittingACharacter) {
  EXPECT_EQ(first_sentence("short one"), "short one");
  EXPECT_EQ(first_sentence("a. b"), "a");
  const std::string long_message(200, 'x');
  EXPECT_EQ(first_sentence(long_message), std::string(139, 'x') + "…");
  std::string greek;
  for (int i = 0; i < 100; ++i) greek += "ν";  // two bytes each
  const std::string cut = first_sentence(greek);
  EXPECT_EQ(cut.substr(cut.size() - 3), "…");
  EXPECT_EQ((cut.size() - 3) % 2, 0U);
}

TEST(ScenePicture, ACoarseArchsOutlineFollowsItsOuterWallInEveryBin) {
  // A half annulus (radii 1 and 1.3 mm) of 6 sectors in z = 0, seen along z: the card's outline
  // takes the highest point per bin along x. Its top must follow the outer wall's chords: no bin
  // left to an inner node (a dip of up to 0.3 mm), none left empty.
  constexpr int kSectors = 6;
  constexpr double kInner = 1.0, kOuter = 1.3, kPi = 3.14159265358979323846;
  WallView w;
  for (int i = 0; i <= kSectors; ++i) {
    const double a = kPi * i / kSectors;
    for (const double r : {kInner, kOuter}) {
      w.rest_mm.insert(w.rest_mm.end(), {float(r * std::cos(a)), float(r * std::sin(a)), 0.0F});
    }
  }
  for (std::uint32_t i = 0; i < kSectors; ++i) {  // node 2i inner, 2i + 1 outer
    w.indices.insert(w.indices.end(), {2 * i, 2 * i + 1, 2 * i + 3, 2 * i, 2 * i + 3, 2 * i + 2});
  }
  SceneViews views;
  views.views.push_back(w);
  const std::string svg = scene_picture_svg(views, "pressure");
  // The outline: 40 bins along the top, then back along the bottom; the drawing's scale from
  // its extent (x from −1.3 to 1.3 mm over the first and last bins' centres).
  const std::string d = svg.substr(svg.find("d=\"") + 3);
  std::vector<std::pair<double, double>> points;
  const std::regex pair(R"(([-0-9.e]+),([-0-9.e]+))");
  for (auto it = std::sregex_iterator(d.begin(), d.begin() + d.find('"'), pair);
       it != std::sregex_iterator(); ++it) {
    points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  }
  ASSERT_EQ(points.size(), 80U);
  const double bin = 2 * kOuter / 40, scale = (points[39].first - points[0].first) / (39 * bin);
  const double base_y = points[40].second;  // the bottom's last bin: y = 0 in the drawing
  const auto outer_chord = [&](double x) {  // the outer polygon's height above x
    for (int i = 0; i < kSectors; ++i) {
      const double a0 = kPi * (i + 1) / kSectors, a1 = kPi * i / kSectors;  // x rising
      const double x0 = kOuter * std::cos(a0), x1 = kOuter * std::cos(a1);
      if (x >= x0 && x <= x1) {
        const double t = (x - x0) / (x1 - x0);
        return kOuter * ((1 - t) * std::sin(a0) + t * std::sin(a1));
      }
    }
    return 0.0;
  };
  for (int b = 2; b < 38; ++b) {  // away from the ends, where the wall is steep within a bin
    const double x = -kOuter + (b + 0.5) * bin;
    const double height = (base_y - points[b].second) / scale;
    EXPECT_NEAR(height, outer_chord(x), 0.05) << "bin " << b << " at x = " << x;
  }
}
