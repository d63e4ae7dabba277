#include "reports/svg_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace vessel::reports {

namespace {

// Colour-blind-safe palette (Okabe & Ito 2008), then greys.
const std::vector<std::string> kPalette{"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00",
                                        "#56B4E9", "#000000", "#F0E442", "#999999", "#666666"};

constexpr int kMarginLeft = 72;
constexpr int kMarginRight = 16;
constexpr int kMarginTop = 30;
constexpr int kMarginBottom = 46;
constexpr int kLegendRow = 18;
constexpr double kLegendText = 38.0;  ///< a legend label's start from its column's edge, px

/// Tick label: plain for moderate values, 1e-5 style for the rest.
std::string tick_label(double v) {
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  std::ostringstream s;
  if (a >= 1e-3 && a < 1e5) {
    s << std::setprecision(6) << v;
  } else {
    const int e = static_cast<int>(std::floor(std::log10(a) + 1e-9));
    const double m = v / std::pow(10.0, e);
    if (std::abs(m - std::round(m)) < 1e-9 && std::abs(std::round(m)) == 1.0) {
      s << (m < 0 ? "-" : "") << "1e" << e;
    } else {
      s << std::setprecision(3) << m << "e" << e;
    }
  }
  return s.str();
}

bool drawable(double v, Scale scale) { return std::isfinite(v) && (scale == Scale::linear || v > 0); }

/// Maps data to pixels along one axis.
struct Mapping {
  double lo, hi;  // data range (log10 for log axes)
  double p0, p1;  // pixel range
  Scale scale;
  [[nodiscard]] double operator()(double v) const {
    const double t = scale == Scale::log ? std::log10(v) : v;
    return p0 + (t - lo) / (hi - lo) * (p1 - p0);
  }
};

/// Data range of one axis over the drawable points, padded so no point sits on the frame.
std::pair<double, double> range(const Plot& plot, bool x_axis) {
  const Scale scale = x_axis ? plot.x.scale : plot.y.scale;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const auto& s : plot.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!drawable(s.x[i], plot.x.scale) || !drawable(s.y[i], plot.y.scale)) continue;
      const double v = x_axis ? s.x[i] : s.y[i];
      const double t = scale == Scale::log ? std::log10(v) : v;
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
  }
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    const double pad = scale == Scale::log ? 0.5 : std::max(std::abs(hi) * 0.1, 1e-12);
    lo -= pad;
    hi += pad;
  }
  const double pad = 0.05 * (hi - lo);
  return {lo - pad, hi + pad};
}

/// Coordinates are written with the stream's fixed-point format set by render_svg; `shape`'s
/// order is palette_marker's.
void marker(std::ostream& out, int shape, double x, double y, double r, const std::string& colour) {
  switch (shape % 4) {
    case 0:
      out << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"" << r << "\"";
      break;
    case 1:
      out << "<rect x=\"" << x - r << "\" y=\"" << y - r << "\" width=\"" << 2 * r << "\" height=\""
          << 2 * r << "\"";
      break;
    case 2:
      out << "<polygon points=\"" << x << "," << y - 1.2 * r << " " << x - 1.1 * r << ","
          << y + 0.8 * r << " " << x + 1.1 * r << "," << y + 0.8 * r << "\"";
      break;
    default:
      out << "<polygon points=\"" << x << "," << y - 1.3 * r << " " << x + 1.3 * r << "," << y
          << " " << x << "," << y + 1.3 * r << " " << x - 1.3 * r << "," << y << "\"";
      break;
  }
  out << " fill=\"" << colour << "\" fill-opacity=\"0.85\" stroke=\"#fff\" stroke-width=\"0.6\"/>\n";
}

/// A legend label's width in pixels at the 12 px font, for laying out the legend: 7 px per code
/// point, a little over sans-serif's mean glyph (digits and lower case are ~6.7 px).
double label_width(const std::string& label) {
  const auto code_points = std::count_if(label.begin(), label.end(), [](char c) {
    return (static_cast<unsigned char>(c) & 0xC0U) != 0x80U;  // not a UTF-8 continuation byte
  });
  return 7.0 * static_cast<double>(code_points);
}

/// Two legend columns under the plot, or one where a label would not fit in half the width.
int legend_columns(const Plot& plot, int width) {
  for (const Series& s : plot.series) {
    if (kLegendText + label_width(s.label) > width / 2.0) return 1;
  }
  return 2;
}

}  // namespace

std::string palette_colour(std::size_t index) { return kPalette[index % kPalette.size()]; }

std::string palette_marker(std::size_t index) {
  static const std::array<const char*, 4> kShapes{"circle", "rect", "triangle", "rectRot"};
  return kShapes[index % kShapes.size()];
}

std::string escape_xml(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::vector<double> axis_ticks(double lo, double hi, Scale scale, int target) {
  std::vector<double> ticks;
  if (!(hi > lo)) return ticks;
  if (scale == Scale::log) {
    // lo, hi are log10 values here.
    const int e0 = static_cast<int>(std::ceil(lo - 1e-9));
    const int e1 = static_cast<int>(std::floor(hi + 1e-9));
    const int step = std::max(1, (e1 - e0 + 1) / target + ((e1 - e0 + 1) % target ? 1 : 0));
    if (hi - lo < 2.0) {
      for (int e = static_cast<int>(std::floor(lo)); e <= static_cast<int>(std::ceil(hi)); ++e) {
        for (const double m : {1.0, 2.0, 5.0}) {
          const double v = std::log10(m) + e;
          if (v >= lo - 1e-9 && v <= hi + 1e-9) ticks.push_back(m * std::pow(10.0, e));
        }
      }
      return ticks;
    }
    for (int e = e0; e <= e1; e += step) ticks.push_back(std::pow(10.0, e));
    return ticks;
  }
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  }
  // Integer multiples of the step, so labels do not accumulate round-off.
  const auto first = static_cast<long>(std::ceil(lo / step - 1e-9));
  const auto last = static_cast<long>(std::floor(hi / step + 1e-9));
  for (long k = first; k <= last; ++k) ticks.push_back(static_cast<double>(k) * step);
  return ticks;
}

std::vector<std::size_t> pareto_front(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<std::size_t> order(std::min(x.size(), y.size()));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return x[a] < x[b] || (x[a] == x[b] && y[a] < y[b]);
  });
  std::vector<std::size_t> front;
  double best_y = std::numeric_limits<double>::infinity();
  for (const std::size_t i : order) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    if (y[i] < best_y) {  // strictly better than every faster point
      front.push_back(i);
      best_y = y[i];
    }
  }
  return front;
}

std::string render_svg(const Plot& plot, int width, int height) {
  std::size_t left_out = 0;
  bool any = false;
  for (const auto& s : plot.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (drawable(s.x[i], plot.x.scale) && drawable(s.y[i], plot.y.scale)) {
        any = true;
      } else {
        ++left_out;
      }
    }
  }
  const int columns = legend_columns(plot, width);
  const int legend_rows = static_cast<int>((plot.series.size() + columns - 1) / columns);
  const int total_height = height + legend_rows * kLegendRow + (left_out ? kLegendRow : 0);
  std::ostringstream out;
  out << std::fixed << std::setprecision(1);  // pixel coordinates; labels are formatted as text
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
      << total_height << "\" viewBox=\"0 0 " << width << " " << total_height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n";
  out << "<text x=\"" << width / 2 << "\" y=\"18\" text-anchor=\"middle\" font-size=\"14\" "
         "font-weight=\"bold\">"
      << escape_xml(plot.title) << "</text>\n";
  if (!any) {
    out << "<text x=\"" << width / 2 << "\" y=\"" << height / 2
        << "\" text-anchor=\"middle\" fill=\"#a00\">no data to plot</text>\n</svg>\n";
    return out.str();
  }
  const auto [xlo, xhi] = range(plot, true);
  const auto [ylo, yhi] = range(plot, false);
  const Mapping mx{xlo, xhi, double(kMarginLeft), double(width - kMarginRight), plot.x.scale};
  const Mapping my{ylo, yhi, double(height - kMarginBottom), double(kMarginTop), plot.y.scale};
  const int x0 = kMarginLeft, x1 = width - kMarginRight, y0 = kMarginTop, y1 = height - kMarginBottom;
  // Grid and ticks.
  for (const double t : axis_ticks(xlo, xhi, plot.x.scale)) {
    const double px = mx(t);
    out << "<line x1=\"" << px << "\" y1=\"" << y0 << "\" x2=\"" << px << "\" y2=\"" << y1
        << "\" stroke=\"#e4e4e4\"/>\n<text x=\"" << px << "\" y=\"" << y1 + 15
        << "\" text-anchor=\"middle\">" << tick_label(t) << "</text>\n";
  }
  for (const double t : axis_ticks(ylo, yhi, plot.y.scale)) {
    const double py = my(t);
    out << "<line x1=\"" << x0 << "\" y1=\"" << py << "\" x2=\"" << x1 << "\" y2=\"" << py
        << "\" stroke=\"#e4e4e4\"/>\n<text x=\"" << x0 - 5 << "\" y=\"" << py + 4
        << "\" text-anchor=\"end\">" << tick_label(t) << "</text>\n";
  }
  out << "<rect x=\"" << x0 << "\" y=\"" << y0 << "\" width=\"" << x1 - x0 << "\" height=\""
      << y1 - y0 << "\" fill=\"none\" stroke=\"#333\"/>\n";
  out << "<text x=\"" << (x0 + x1) / 2 << "\" y=\"" << height - 10 << "\" text-anchor=\"middle\">"
      << escape_xml(plot.x.label) << (plot.x.scale == Scale::log ? " (log)" : "") << "</text>\n";
  out << "<text transform=\"translate(14," << (y0 + y1) / 2
      << ") rotate(-90)\" text-anchor=\"middle\">" << escape_xml(plot.y.label)
      << (plot.y.scale == Scale::log ? " (log)" : "") << "</text>\n";
  // Series.
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const Series& s = plot.series[k];
    const std::string colour = s.colour.empty() ? palette_colour(k) : s.colour;
    std::vector<std::pair<double, double>> pts;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (drawable(s.x[i], plot.x.scale) && drawable(s.y[i], plot.y.scale)) {
        pts.emplace_back(mx(s.x[i]), my(s.y[i]));
      }
    }
    if (s.lines && pts.size() > 1) {
      out << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\""
          << (s.emphasis ? 2.6 : 1.5) << "\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "")
          << " points=\"";
      for (const auto& [px, py] : pts) out << px << "," << py << " ";
      out << "\"/>\n";
    }
    if (s.markers) {
      for (const auto& [px, py] : pts) {
        marker(out, static_cast<int>(k), px, py, s.emphasis ? 5.0 : 3.6, colour);
      }
    }
    // Legend entry, in `columns` columns under the plot.
    const auto column = k % static_cast<std::size_t>(columns);
    const auto row = k / static_cast<std::size_t>(columns);
    const double edge = static_cast<double>(column) * (width / 2.0);
    const double lx = edge + 10.0;
    const double ly = height + kLegendRow * static_cast<double>(row) + 4.0;
    if (s.lines) {
      out << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 22 << "\" y2=\"" << ly
          << "\" stroke=\"" << colour << "\" stroke-width=\"2\""
          << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
    }
    if (s.markers) marker(out, static_cast<int>(k), lx + 11, ly, 4.0, colour);
    out << "<text x=\"" << edge + kLegendText << "\" y=\"" << ly + 4 << "\">" << escape_xml(s.label)
        << "</text>\n";
  }
  if (left_out) {
    out << "<text x=\"10\" y=\"" << total_height - 5 << "\" fill=\"#a00\">" << left_out
        << " point(s) not shown (not finite, or ≤ 0 on a log axis)</text>\n";
  }
  out << "</svg>\n";
  return out.str();
}

}  // namespace vessel::reports
