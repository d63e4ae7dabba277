#pragma once
/// report.html with its answers first and its figures interactive: a card per scene, each scene's
/// models in 3D (their deformed walls coloured by the displacement error, read from the run's
/// fields/*.vtu), and the plots drawn by Chart.js with hover, series toggles and zoom. The
/// libraries are Debian's (libjs-three, libjs-chart.js), read when the report is written and
/// inlined, so the page is one file that needs no network. Without them the page keeps the static
/// SVG figures and says which library was missing.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/results_file.hpp"
#include "reports/scene_card.hpp"
#include "reports/study_files.hpp"
#include "reports/wall_view.hpp"

namespace vessel::reports {

struct WebLibrary {
  std::string name;     ///< "three.js", "Chart.js"
  std::string version;  ///< read from the file ("r111", "3.9.1"); empty if not found
  std::string licence;  ///< the footer's line: licence and copyright
  std::filesystem::path path;
  std::string code;
};

struct WebLibraries {
  std::vector<WebLibrary> found;
  std::vector<std::string> missing;  ///< "three.js (libjs-three: <path>)" per library not found
  [[nodiscard]] bool complete() const { return missing.empty(); }
};

/// Where Debian installs the libraries; the environment variable VESSELVERIFY_JS_DIR replaces it
/// (tests point it at an empty directory to see the page without them).
std::filesystem::path default_javascript_dir();

/// three.js (three/three.min.js) and Chart.js (chart.js/chart.min.js) under `dir`.
WebLibraries load_web_libraries(const std::filesystem::path& dir);

/// A guidewire scene's wire as its 3D view draws it: the scene's own EI (results.json's first
/// rigid entry), through the wall.
struct WireView {
  double radius_mm = 0.0;
  std::vector<std::array<double, 3>> rigid_mm;  ///< against the rigid lumen, clamp to tip
  /// Compliant coupling: coupled with the reference's wall (same nodes), else empty.
  std::vector<std::array<double, 3>> coupled_mm;
  std::string coupled_row;  ///< the coupling row whose C_ref the coupled wire used
};

/// One scene's 3D data: its models' walls at the representative load and first ν (a validity
/// scene's: at the largest load reached, against the finite-strain reference).
struct SceneViews {
  std::string scene;  ///< the page's anchor (view-<scene>) and slot (view:<scene>)
  std::string reference_note;  ///< a sentence naming the reference when it is not the run's
  /// What the view says when it has no walls (no VTU written).
  std::string no_fields_note = "`vesselverify run` writes them unless --fields none.";
  std::optional<double> tolerance_mm = 0.1;  ///< the colour bar's mark (none: no mark)
  /// What the walls' colours are (WallView::colour_code) and in what unit.
  std::string colour_name = "|error|", colour_unit = "mm";
  /// The caption's first sentences in place of the model-against-reference one, if set.
  std::string caption;
  bool true_scale = false;  ///< open the view at the displacements' true scale (the wire in place)
  /// Where the camera first looks from: a unit vector from the view's centre (none: the default)
  std::optional<std::vector<double>> view_from;
  std::optional<std::vector<double>> qoi_mm;
  std::optional<ContactPatchRow> contact_patch;
  std::string load_text;
  std::vector<WallView> views;
  std::optional<WireView> wire;  ///< guidewire loads with a centreline in results.json
  std::vector<std::string> missing;  ///< outcomes whose VTU was not found (their paths)
};

/// The walls of each finished outcome of `scene` at its representative load, first ν and finest
/// model level, read from the VTU its `fields` names (relative to `results_dir`, the results
/// file's folder); an outcome without one or whose file is absent is listed in `missing`, an
/// unreadable file is an InputError.
SceneViews read_scene_views(const SceneRows& scene, const std::filesystem::path& results_dir);

/// The walls of each model the validity study judged, at the largest load it reached, read from
/// the VTUs its `fields` name (relative to `validity_dir`, the validity file's folder); scene
/// "validity-<scene>", the tolerance `tolerance_mm`. InputError for an unreadable file.
SceneViews validity_scene_views(const ValiditySceneEntry& scene,
                                const std::filesystem::path& validity_dir, double tolerance_mm);

/// A picture of the scene for its card: the vessel's outline seen along its thinnest extent, the
/// QoI point and the load, as a small <svg> (empty without a wall to draw).
std::string scene_picture_svg(const SceneViews& views, const std::string& load);

/// The whole page. `views` in the order of results.scenes (one per scene).
std::string interactive_html(const Document& doc, const std::vector<SceneCard>& cards,
                             const std::vector<SceneViews>& views, const WebLibraries& libraries,
                             const std::string& title);

}  // namespace vessel::reports
