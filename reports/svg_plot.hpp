#pragma once
/// Small, dependency-free SVG charts for the report: scatter and line series on linear or
/// logarithmic axes, with a legend. The output is a standalone <svg> element, so the HTML report
/// can inline it and the Markdown report can link it as a file.
#include <string>
#include <vector>

namespace vessel::reports {

enum class Scale { linear, log };

struct Axis {
  std::string label;
  Scale scale = Scale::linear;
};

struct Series {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  bool lines = false;    ///< join the points in the given order
  bool markers = true;
  bool dashed = false;
  bool emphasis = false;  ///< thicker line, larger markers (e.g. the reference, the Pareto front)
  /// Colour as "#rrggbb"; empty: the palette colour of the series' index.
  std::string colour;
  /// Marker shape in report.html's plots (circle, triangle, rect, rectRot, star, crossRot, cross,
  /// rectRounded) for a series with its own colour; the SVG draws palette_marker's shapes.
  std::string marker = "circle";
  /// Optional, one per point: what hovering the point names (model, ν, level, load), and the
  /// 3D view it opens when clicked ("<scene>|<model>|<level>").
  std::vector<std::string> point_labels, point_views;
};

struct Plot {
  std::string title;
  Axis x;
  Axis y;
  std::vector<Series> series;
};

/// The colour a series without its own is drawn with, by its index in the plot (the SVG and
/// report.html's plots agree): the Okabe–Ito palette, then greys.
std::string palette_colour(std::size_t index);
/// The marker shape the SVG draws series `index` with, by its name in report.html's plots
/// (circle, rect, triangle, rectRot in turn).
std::string palette_marker(std::size_t index);

/// The plot as an <svg> element `width` × `height` pixels (plus the legend's rows). Points that a
/// log axis cannot show (≤ 0) or that are not finite are left out, and the count left out is
/// written under the plot. An empty plot (no drawable point) says so instead of drawing axes.
std::string render_svg(const Plot& plot, int width = 640, int height = 360);

/// Tick positions for an axis spanning [lo, hi]: 1-2-5 steps for linear axes (about `target`
/// ticks), decades (or 1-2-5 within a decade when the span is under two decades) for log axes.
std::vector<double> axis_ticks(double lo, double hi, Scale scale, int target = 6);

/// Indices of the points on the Pareto front when both coordinates are to be minimised (no other
/// point is at least as good in both and better in one), sorted by x ascending.
std::vector<std::size_t> pareto_front(const std::vector<double>& x, const std::vector<double>& y);

/// Escapes &, <, >, " for XML/HTML text and attributes.
std::string escape_xml(const std::string& text);

}  // namespace vessel::reports
