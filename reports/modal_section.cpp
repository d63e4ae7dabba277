#include "reports/modal_section.hpp"

#include <algorithm>
#include <cctype>
#include <iomanip>
#include <sstream>

#include "reports/svg_plot.hpp"

namespace vessel::reports {

namespace {

std::string list(const std::vector<double>& v, int digits = 3) {
  std::string s;
  for (const double x : v) s += (s.empty() ? "" : ", ") + significant(x, digits);
  return s;
}

std::string file_safe(const std::string& name) {
  std::string out;
  for (const char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

}  // namespace

void natural_frequency_section(Document& doc, const SceneRows& s, SeriesStyles& styles) {
  if (s.reference_modes.empty() && s.model_modes.empty()) return;
  doc.heading(3, "Natural frequencies");
  std::string reference_text = "the modal reference";
  if (!s.reference_modes.empty()) {
    const ModalRow& r = s.reference_modes.front();
    reference_text = "the FEM's (" + r.detail + ", level " + std::to_string(r.level) + ")";
  }
  doc.paragraph(
      "The lowest natural frequencies of each model at rest (K φ = ω² M φ, the scene's supports "
      "held) beside " + reference_text + ". Mass-spring models: K their exact Hessian at rest "
      "(springs and any volume term), M their lumped masses; FEM models: the consistent mass. "
      "Modes are paired by rank (both lists sorted ascending), so a ratio compares the k-th "
      "lowest of each, not matched shapes; a straight tube's bending modes come in nearly equal "
      "pairs. *zero modes*: mechanisms (ω ≈ 0: motions the model does not resist at rest).");
  Table t;
  t.header = {"model", "ν", "level", "frequencies (Hz)", "f / f_FEM", "zero modes", "free dofs",
              "s"};
  for (const ModalRow& r : s.reference_modes) {
    t.rows.push_back({"**FEM reference** (" + r.detail + ")", significant(r.poisson_ratio),
                      std::to_string(r.level),
                      r.ok ? list(r.frequencies_hz) : "**failed**: " + r.failure, "1", "–",
                      std::to_string(r.dofs), significant(r.seconds)});
  }
  for (const ModalRow& m : s.model_modes) {
    t.rows.push_back({m.model, significant(m.poisson_ratio), std::to_string(m.level),
                      m.ok ? list(m.frequencies_hz) : "**failed**: " + m.failure,
                      m.ratio_to_reference.empty() ? "–" : list(m.ratio_to_reference),
                      m.ok ? std::to_string(m.mechanisms) : "–", std::to_string(m.dofs),
                      significant(m.seconds)});
  }
  doc.table(t);

  // Figure: f/f_FEM against mode number at the first ν.
  const double nu = s.reference_modes.empty() ? 0.0 : s.reference_modes.front().poisson_ratio;
  Plot plot;
  plot.title = s.name + ": natural frequencies against the FEM's";
  plot.x = {"mode (k-th lowest)", Scale::linear};
  plot.y = {"f_model / f_FEM", Scale::log};
  std::size_t modes = 0;
  for (const ModalRow& m : s.model_modes) {
    if (m.poisson_ratio != nu || m.ratio_to_reference.empty()) continue;
    Series series;
    series.label = m.model + (s.model_levels.size() > 1 ? " (L" + std::to_string(m.level) + ")" : "");
    series.lines = true;
    styles.apply(series, m.model);
    for (std::size_t k = 0; k < m.ratio_to_reference.size(); ++k) {
      series.x.push_back(static_cast<double>(k + 1));
      series.y.push_back(m.ratio_to_reference[k]);
    }
    modes = std::max(modes, m.ratio_to_reference.size());
    plot.series.push_back(series);
  }
  if (plot.series.empty()) return;
  Series one;
  one.label = "FEM reference";
  one.lines = true;
  one.markers = false;
  one.emphasis = true;
  one.colour = kReferenceColour;
  one.x = {1.0, static_cast<double>(modes)};
  one.y = {1.0, 1.0};
  plot.series.insert(plot.series.begin(), one);
  doc.figure(file_safe(s.name) + "_natural_frequencies.svg", plot,
             "Natural frequencies of each model over the FEM reference's, mode by mode (k-th "
             "lowest against k-th lowest), ν = " + significant(nu) +
                 ". Above 1: stiffer (or lighter) than the continuum in that mode; a zero-frequency "
                 "mechanism shows as a point missing from the log axis.");
}

}  // namespace vessel::reports
