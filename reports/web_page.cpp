#include "reports/web_page.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "meshes/foundation/errors.hpp"
#include "reports/report.hpp"
#include "reports/svg_plot.hpp"

namespace vessel::reports {

extern const char* const kReportScript;  // reports/web/report.js, embedded at build time
extern const char* const kReportStyle;   // reports/web/report.css

namespace {

using nlohmann::json;

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The text after `marker` up to the first character in `stops`, or "".
std::string after(const std::string& text, const std::string& marker, const char* stops) {
  const auto at = text.find(marker);
  if (at == std::string::npos) return "";
  const auto begin = at + marker.size();
  return text.substr(begin, text.find_first_of(stops, begin) - begin);
}

/// Text safe inside <script>: no "</" that could close it.
std::string script_safe(std::string text) {
  for (auto at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3)) {
    text.replace(at, 2, "<\\/");
  }
  return text;
}

template <class T>
std::string b64(const std::vector<T>& v) {
  return base64_encode(v.data(), v.size() * sizeof(T));
}

/// The contact patch the page outlines on the wall: centre and radius, mm (null without one).
json patch_json(const std::optional<ContactPatchRow>& patch) {
  if (!patch) return nullptr;
  return {{"point_mm", patch->point_mm},
          {"radius_mm", patch->radius_mm},
          {"normal", patch->outward_normal}};
}

json view_json(const WallView& v) {
  return {{"model", v.model},
          {"kind", v.kind},
          {"level", v.level >= 0 ? json(v.level) : json(nullptr)},
          {"lines", v.lines},
          {"springs", v.network_faces},
          {"nodes", v.rest_mm.size() / 3},
          {"rest", b64(v.rest_mm)},
          {"um", b64(v.u_model_mm)},
          {"ur", b64(v.u_reference_mm)},
          {"idx", v.rest_mm.size() / 3 <= 65536
                      ? b64(std::vector<std::uint16_t>(v.indices.begin(), v.indices.end()))
                      : b64(v.indices)},
          {"idx_bytes", v.rest_mm.size() / 3 <= 65536 ? 2 : 4},
          {"err", b64(v.colour_code)},
          {"step", v.colour_step},
          {"max", v.colour_max}};
}

/// The wire the view draws (null without one).
json wire_json(const std::optional<WireView>& w) {
  if (!w) return nullptr;
  return {{"radius_mm", w->radius_mm},
          {"rigid_mm", w->rigid_mm},
          {"coupled_mm", w->coupled_mm.empty() ? json(nullptr) : json(w->coupled_mm)},
          {"coupled_row", w->coupled_row}};
}

json plot_json(const Plot& p) {
  json series = json::array();
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const Series& s = p.series[k];
    // A series without its own colour: the SVG's palette colour and shape for its index.
    const bool styled = !s.colour.empty();
    json x = json::array(), y = json::array();
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      x.push_back(std::isfinite(s.x[i]) ? json(s.x[i]) : json(nullptr));
      y.push_back(std::isfinite(s.y[i]) ? json(s.y[i]) : json(nullptr));
    }
    series.push_back({{"label", s.label},
                      {"colour", styled ? s.colour : palette_colour(k)},
                      {"marker", styled ? s.marker : palette_marker(k)},
                      {"lines", s.lines},
                      {"markers", s.markers},
                      {"dashed", s.dashed},
                      {"emphasis", s.emphasis},
                      {"x", x},
                      {"y", y},
                      {"labels", s.point_labels},
                      {"views", s.point_views}});
  }
  return {{"title", p.title},
          {"x", {{"label", p.x.label}, {"log", p.x.scale == Scale::log}}},
          {"y", {{"label", p.y.label}, {"log", p.y.scale == Scale::log}}},
          {"series", series}};
}

std::string model_line(const char* role, const std::optional<CardModel>& m, const SceneCard& c) {
  std::ostringstream out;
  out << "<div class=\"vv-card-model\"><span class=\"vv-role\">" << role << "</span> ";
  if (!m) {
    out << "<strong>none</strong>"
        << (std::string(role) == "recommended"
                ? " <span class=\"vv-fail\">no model meets " +
                      std::string(c.budget ? "the budget" : "the tolerance") + "</span>"
                : "")
        << "</div>\n";
    return out.str();
  }
  out << "<strong>" << escape_xml(m->outcome.model) << "</strong> (L" << m->outcome.level
      << ")<br>max error <strong>" << significant(m->outcome.max_mm) << " mm</strong>";
  if (m->ratio_to_p1) out << " (" << significant(*m->ratio_to_p1) << "× P1's rel. L2)";
  out << ", " << significant(m->update_seconds) << " s per update "
      << (m->passes ? "<span class=\"vv-pass\">passes</span>"
                    : "<span class=\"vv-fail\">fails</span>")
      << "</div>\n";
  return out.str();
}

std::string card_html(const SceneCard& c, const std::string& picture) {
  std::ostringstream out;
  out << "<div class=\"vv-card\" data-scene=\"" << escape_xml(c.scene) << "\">\n<h3><a href=\"#view-"
      << escape_xml(c.scene) << "\">" << escape_xml(c.scene) << "</a></h3>\n"
      << picture << "<p class=\"vv-card-load\">" << escape_xml(c.load) << " " << escape_xml(c.load_text)
      << ", ν = " << significant(c.poisson_ratio) << "; ";
  if (c.budget) {
    out << "budget: " << escape_xml(c.budget->quantity) << " error ≤ "
        << significant(c.budget->tolerance) << " " << escape_xml(c.budget->unit) << " in "
        << significant(c.budget->seconds_per_update) << " s per update";
  } else {
    out << "tolerance: max error ≤ " << significant(c.tolerance_mm) << " mm";
  }
  out << "</p>\n" << model_line("recommended", c.recommended, c)
      << model_line("best mass-spring", c.best_spring, c);
  for (const CardFailure& f : c.failures) {
    out << "<details class=\"vv-failure\"><summary><span class=\"vv-fail\">failed</span> "
        << escape_xml(f.model) << " (L" << f.level << "): " << escape_xml(f.reason)
        << "</summary><p>" << escape_xml(f.message) << "</p></details>\n";
  }
  out << "</div>\n";
  return out.str();
}

/// The caption's sentence on the guidewire (empty without one).
std::string wire_caption(const SceneViews& v) {
  if (!v.wire) return "";
  if (v.wire->coupled_mm.empty()) {
    return " Orange tube: the guidewire against the rigid lumen, whose contact force loads every "
           "model (drawn through the wall).";
  }
  return " Orange tube: the guidewire coupled with the reference's wall (C_ref from " +
         escape_xml(v.wire->coupled_row) +
         "), its give from the rigid solve magnified as the walls are; dark line: the wire "
         "against the rigid lumen (both drawn through the wall).";
}

std::string view_html(const SceneViews& v, std::size_t index) {
  std::ostringstream out;
  out << "<section class=\"vv-view\" id=\"view-" << escape_xml(v.scene) << "\" data-scene-index=\""
      << index << "\">\n";
  if (v.views.empty()) {
    out << "<p class=\"vv-note\">No VTU fields for this scene at " << escape_xml(v.load_text)
        << ": " << escape_xml(v.no_fields_note) << "</p>\n</section>\n";
    return out.str();
  }
  out << "<div class=\"vv-view-controls\">"
      << "<label>left <select class=\"vv-pick\" data-pane=\"0\"></select></label> "
      << "<label>right <select class=\"vv-pick\" data-pane=\"1\"></select></label> "
      << "<label>deformation × <input class=\"vv-scale\" type=\"range\" min=\"0\" max=\"3\" "
         "step=\"0.05\" value=\"1\"><span class=\"vv-scale-text\"></span></label> "
      << "<label><input class=\"vv-ghost\" type=\"checkbox\" checked> reference (ghost)</label>"
      << "<label><input class=\"vv-log\" type=\"checkbox\"> log colour scale</label>"
      << (v.wire ? "<label><input class=\"vv-wire\" type=\"checkbox\" checked> guidewire</label>"
                 : "")
      << "</div>\n<div class=\"vv-panes\"><div class=\"vv-pane\" data-pane=\"0\"></div>"
      << "<div class=\"vv-pane\" data-pane=\"1\"></div></div>\n<div class=\"vv-colourbar\"></div>\n"
      << "<p class=\"vv-view-caption\">";
  if (!v.caption.empty()) {
    out << escape_xml(v.caption);
  } else {
    out << "Each model's wall at " << escape_xml(v.load_text)
        << ", deformed by its own displacement and coloured by |model − reference| at its nodes "
           "(viridis, one scale for every model of the scene, logarithmic when their errors span "
           "more than a decade; the tick marks the tolerance, "
        << significant(v.tolerance_mm.value_or(0.0)) << " mm). " << escape_xml(v.reference_note)
        << "Grey ghost: the reference's deformed wall. Red sphere: the QoI point"
        << (v.contact_patch ? "; red disc: the contact patch the force is spread over (both" : " (")
        << " at rest, drawn through the wall). Drag to turn, wheel to zoom; both panes share "
           "the camera; hover a node for its error and both displacements."
        << wire_caption(v);
  }
  out << "</p>\n";
  if (!v.missing.empty()) {
    out << "<p class=\"vv-note\">" << v.missing.size() << " finished model(s) have no VTU here ("
        << escape_xml(v.missing.front()) << (v.missing.size() > 1 ? ", …" : "") << ").</p>\n";
  }
  out << "</section>\n";
  return out.str();
}

}  // namespace

std::filesystem::path default_javascript_dir() {
  if (const char* dir = std::getenv("VESSELVERIFY_JS_DIR"); dir && *dir) return dir;
  return "/usr/share/javascript";
}

WebLibraries load_web_libraries(const std::filesystem::path& dir) {
  struct Wanted {
    const char* name;
    const char* file;
    const char* package;
    const char* version_marker;
    const char* licence;
  };
  const Wanted wanted[] = {
      {"three.js", "three/three.min.js", "libjs-three", "REVISION=\"",
       "MIT (Expat) licence, © 2010-2019 three.js authors; from Debian's libjs-three"},
      {"Chart.js", "chart.js/chart.min.js", "libjs-chart.js", "Chart.js v",
       "MIT licence, © 2022 Chart.js Contributors; from Debian's libjs-chart.js"}};
  WebLibraries out;
  for (const Wanted& w : wanted) {
    const std::filesystem::path path = dir / w.file;
    if (!std::filesystem::is_regular_file(path)) {
      out.missing.push_back(std::string(w.name) + " (" + w.package + ": " + path.string() + ")");
      continue;
    }
    WebLibrary lib{w.name, "", w.licence, path, read_file(path)};
    lib.version = after(lib.code, w.version_marker, "\"\n ");
    if (lib.name == "three.js" && !lib.version.empty()) lib.version = "r" + lib.version;
    out.found.push_back(std::move(lib));
  }
  return out;
}

/// A load as the views' captions give it: contact forces in mN, else in the scene's unit.
std::string load_text(double load, const std::string& unit) {
  return unit == "N" ? significant(load * 1e3) + " mN" : significant(load) + " " + unit;
}

SceneViews validity_scene_views(const ValiditySceneEntry& s,
                                const std::filesystem::path& validity_dir, double tolerance_mm) {
  SceneViews out;
  out.scene = "validity-" + s.scene;
  out.tolerance_mm = tolerance_mm;
  out.qoi_mm = s.qoi_point_mm;
  out.reference_note = "Here the reference is the finite-strain (neo-Hookean) one. ";
  out.no_fields_note = "`vesselverify validity` writes them unless --fields none.";
  if (s.rows.empty()) return out;
  const ValidityRowEntry& largest = s.rows.back();
  out.load_text = load_text(largest.magnitude, s.load_unit);
  for (const ValidityModelEntry& m : largest.models) {
    if (!m.ok || m.fields.empty()) continue;
    const std::filesystem::path path = validity_dir / m.fields;
    if (!std::filesystem::exists(path)) {
      out.missing.push_back(path.string());
      continue;
    }
    WallView v = wall_view(read_vtu(path), path.string());
    v.model = m.model;
    v.kind = "msm";
    v.level = s.model_level;
    v.poisson_ratio = s.poisson_ratio;
    v.magnitude = largest.magnitude;
    out.views.push_back(std::move(v));
  }
  return out;
}

SceneViews read_scene_views(const SceneRows& s, const std::filesystem::path& results_dir) {
  SceneViews out;
  out.scene = s.name;
  out.tolerance_mm = s.tolerance_mm;
  out.qoi_mm = s.qoi_point_mm;
  out.contact_patch = s.contact_patch;
  const double load = representative_load(s);
  out.load_text = load_text(load, s.load_unit);
  const double nu = s.references.empty()
                        ? (s.outcomes.empty() ? 0.0 : s.outcomes.front().poisson_ratio)
                        : s.references.front().poisson_ratio;
  // The finest level only, as the cards judge it: a level-1 wall has about 4 times the
  // level-0 wall's nodes, so coarser levels would add little but size.
  const int finest = s.model_levels.empty() ? 0 : s.model_levels.back();
  std::set<std::pair<std::string, int>> seen;
  for (const OutcomeRow& o : s.outcomes) {
    if (!o.ok || o.magnitude != load || o.poisson_ratio != nu || o.level != finest) continue;
    if (!seen.emplace(o.model, o.level).second) continue;
    if (o.fields.empty()) {
      out.missing.push_back(o.model + ": results.json names no fields file");
      continue;
    }
    const std::filesystem::path path = results_dir / o.fields;
    if (!std::filesystem::exists(path)) {
      out.missing.push_back(path.string());
      continue;
    }
    WallView v = wall_view(read_vtu(path), path.string());
    v.model = o.model;
    v.kind = o.kind;
    v.level = o.level;
    v.poisson_ratio = o.poisson_ratio;
    v.magnitude = o.magnitude;
    out.views.push_back(std::move(v));
  }
  if (s.guidewire && !s.guidewire->rigid.empty() && s.guidewire->rigid.front().centreline_mm.size() > 1) {
    const GuidewireRigidRow& r = s.guidewire->rigid.front();
    WireView w;
    w.radius_mm = 0.5 * s.guidewire->diameter_mm;
    w.rigid_mm = r.centreline_mm;
    if (r.reference_centreline_mm.size() == r.centreline_mm.size()) {
      w.coupled_mm = r.reference_centreline_mm;
      w.coupled_row = r.reference_row;
    }
    out.wire = std::move(w);
  }
  return out;
}

namespace {

/// A wall's outline seen along its bounding box's thinnest axis: per bin along the longest axis
/// (u), the lowest and highest extent along the other (w) of its cells' edges, each sampled at
/// least twice per bin, so a coarse mesh's long edges leave no bin to a few inner nodes.
struct WallOutline {
  static constexpr int kBins = 40;
  int u = 0, w = 1;
  double lo_u = 0.0, lo_w = 0.0, span_u = 1.0, span_w = 1.0;
  std::vector<double> low = std::vector<double>(kBins, 1e300), high = std::vector<double>(kBins, -1e300);
};

WallOutline wall_outline(const WallView& wall) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < wall.rest_mm.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], double(wall.rest_mm[i]));
    hi[i % 3] = std::max(hi[i % 3], double(wall.rest_mm[i]));
  }
  int axes[3] = {0, 1, 2};
  std::sort(axes, axes + 3, [&](int a, int b) { return hi[a] - lo[a] > hi[b] - lo[b]; });
  WallOutline o;
  o.u = axes[0];
  o.w = axes[1];
  o.lo_u = lo[o.u];
  o.lo_w = lo[o.w];
  o.span_u = std::max(hi[o.u] - lo[o.u], 1e-9);
  o.span_w = std::max(hi[o.w] - lo[o.w], 1e-9);
  const auto coord = [&](std::uint32_t node, int axis) { return double(wall.rest_mm[3 * node + axis]); };
  const std::size_t corners = wall.lines ? 2 : 3, edges = wall.lines ? 1 : 3;
  for (std::size_t c = 0; c + corners <= wall.indices.size(); c += corners) {
    for (std::size_t k = 0; k < edges; ++k) {
      const std::uint32_t a = wall.indices[c + k], e = wall.indices[c + (k + 1) % corners];
      const int samples = 1 + int(std::abs(coord(e, o.u) - coord(a, o.u)) / o.span_u * 2 * o.kBins);
      for (int j = 0; j <= samples; ++j) {
        const double t = double(j) / samples;
        const double cu = (1 - t) * coord(a, o.u) + t * coord(e, o.u);
        const double cw = (1 - t) * coord(a, o.w) + t * coord(e, o.w);
        const int b = std::clamp(int((cu - o.lo_u) / o.span_u * o.kBins), 0, o.kBins - 1);
        o.low[b] = std::min(o.low[b], cw);
        o.high[b] = std::max(o.high[b], cw);
      }
    }
  }
  return o;
}

}  // namespace

std::string scene_picture_svg(const SceneViews& v, const std::string& load) {
  // The wall with the most nodes, drawn as its outline (wall_outline).
  const WallView* wall = nullptr;
  for (const WallView& w : v.views) {
    if (!wall || w.rest_mm.size() > wall->rest_mm.size()) wall = &w;
  }
  if (!wall || wall->rest_mm.empty()) return "";
  const WallOutline outline = wall_outline(*wall);
  const int u = outline.u, w = outline.w, kBins = WallOutline::kBins;
  const double lo_u = outline.lo_u, lo_w = outline.lo_w, span_u = outline.span_u;
  const std::vector<double>& bmin = outline.low;
  const std::vector<double>& bmax = outline.high;
  constexpr double kWidth = 260, kHeight = 110, kPad = 14;
  const double scale = std::min((kWidth - 2 * kPad) / span_u, (kHeight - 2 * kPad) / outline.span_w);
  const auto px = [&](double a) { return kPad + (a - lo_u) * scale; };
  const auto py = [&](double b) { return kHeight - kPad - (b - lo_w) * scale; };
  std::ostringstream path;
  bool first = true;
  for (int b = 0; b < kBins; ++b) {
    if (bmax[b] < bmin[b]) continue;
    path << (first ? "M" : "L") << significant(px(lo_u + (b + 0.5) * span_u / kBins), 4) << ","
         << significant(py(bmax[b]), 4);
    first = false;
  }
  for (int b = kBins - 1; b >= 0; --b) {
    if (bmax[b] < bmin[b]) continue;
    path << "L" << significant(px(lo_u + (b + 0.5) * span_u / kBins), 4) << ","
         << significant(py(bmin[b]), 4);
  }
  std::ostringstream out;
  out << "<svg class=\"vv-picture\" viewBox=\"0 0 " << kWidth << " " << kHeight
      << "\" role=\"img\"><title>" << escape_xml(v.scene) << ": the vessel and its load</title>"
      << "<path d=\"" << path.str() << "Z\" fill=\"#d9d9d9\" stroke=\"#555\"/>";
  if (v.qoi_mm) {
    const double x = px((*v.qoi_mm)[u]), y = py((*v.qoi_mm)[w]);
    if (load == "contact") {
      out << "<line x1=\"" << significant(x, 4) << "\" y1=\"" << significant(y - 28, 4)
          << "\" x2=\"" << significant(x, 4) << "\" y2=\"" << significant(y - 6, 4)
          << "\" stroke=\"#c00\" stroke-width=\"2.5\"/><path d=\"M" << significant(x - 5, 4) << ","
          << significant(y - 10, 4) << "L" << significant(x + 5, 4) << "," << significant(y - 10, 4)
          << "L" << significant(x, 4) << "," << significant(y - 3, 4) << "Z\" fill=\"#c00\"/>";
    }
    out << "<circle cx=\"" << significant(x, 4) << "\" cy=\"" << significant(y, 4)
        << "\" r=\"3.5\" fill=\"#c00\"/>";
  }
  out << "</svg>\n";
  return out.str();
}

std::string interactive_html(const Document& doc, const std::vector<SceneCard>& cards,
                             const std::vector<SceneViews>& views, const WebLibraries& libraries,
                             const std::string& title) {
  const bool live = libraries.complete();
  std::ostringstream body;
  json plots = json::array();
  for (const Block& b : doc.blocks()) {
    if (b.text_only) continue;
    if (b.kind == Block::Kind::slot && b.text == "cards") {
      body << "<div class=\"vv-cards\">\n";
      for (std::size_t i = 0; i < cards.size(); ++i) {
        body << card_html(cards[i], i < views.size() ? scene_picture_svg(views[i], cards[i].load) : "");
      }
      body << "</div>\n";
    } else if (b.kind == Block::Kind::slot && b.text.rfind("view:", 0) == 0) {
      for (std::size_t i = 0; i < views.size(); ++i) {
        if (live && "view:" + views[i].scene == b.text) body << view_html(views[i], i);
      }
    } else if (b.kind == Block::Kind::figure && b.plot && live) {
      body << "<figure class=\"vv-plot\"><div class=\"vv-chart\" data-plot=\"" << plots.size()
           << "\"><canvas></canvas></div><button class=\"vv-reset\" type=\"button\">reset zoom"
              "</button><figcaption>" << inline_html(b.text) << "</figcaption></figure>\n";
      plots.push_back(plot_json(*b.plot));
    } else {
      body << block_html(b);
    }
  }
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>"
      << escape_xml(title) << "</title>\n<style>" << document_style() << "\n" << kReportStyle
      << "</style>\n</head>\n<body>\n";
  if (!live) {
    out << "<p class=\"vv-note\">Static figures: the interactive plots and 3D views need ";
    for (std::size_t i = 0; i < libraries.missing.size(); ++i) {
      out << (i ? " and " : "") << escape_xml(libraries.missing[i]);
    }
    out << ", not found when this report was written (scripts/install_deps.sh installs them).</p>\n";
  }
  out << body.str();
  out << "<footer class=\"vv-footer\"><p>Written by vesselverify. ";
  if (live) out << "Inlined libraries: ";
  for (const WebLibrary& lib : libraries.found) {
    if (!live) break;
    out << escape_xml(lib.name) << " " << escape_xml(lib.version) << " (" << escape_xml(lib.licence)
        << "); ";
  }
  out << "the page loads nothing from the network.</p></footer>\n";
  if (live) {
    out << "<script type=\"application/json\" id=\"vv-plots\">" << script_safe(plots.dump())
        << "</script>\n";
    for (std::size_t i = 0; i < views.size(); ++i) {
      json scene{
          {"name", views[i].scene},
          {"tolerance_mm", views[i].tolerance_mm ? json(*views[i].tolerance_mm) : json(nullptr)},
          {"colour", {{"name", views[i].colour_name}, {"unit", views[i].colour_unit}}},
          {"true_scale", views[i].true_scale},
          {"view_from", views[i].view_from ? json(*views[i].view_from) : json(nullptr)},
          {"qoi_mm", views[i].qoi_mm ? json(*views[i].qoi_mm) : json(nullptr)},
          {"patch", patch_json(views[i].contact_patch)},
          {"load", views[i].load_text},
          {"wire", wire_json(views[i].wire)},
          {"views", json::array()}};
      for (const WallView& v : views[i].views) scene["views"].push_back(view_json(v));
      out << "<script type=\"application/json\" id=\"vv-scene-" << i << "\">"
          << script_safe(scene.dump()) << "</script>\n";
    }
    for (const WebLibrary& lib : libraries.found) {
      out << "<script data-library=\"" << escape_xml(lib.name) << "\">\n" << script_safe(lib.code)
          << "\n</script>\n";
    }
    out << "<script>\n" << kReportScript << "\n</script>\n";
  }
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace vessel::reports
