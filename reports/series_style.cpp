#include "reports/series_style.hpp"

#include <array>

namespace vessel::reports {

namespace {

// Okabe & Ito 2008's colour-blind-safe colours without black (the reference's), then darker
// distinct ones; the markers change first, so two models never share colour and marker until
// 40 models.
constexpr std::array<const char*, 10> kColours{"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                               "#E69F00", "#56B4E9", "#8c564b", "#b8a000",
                                               "#1b9e77", "#e7298a"};
constexpr std::array<const char*, 8> kMarkers{"circle",   "triangle", "rect",  "rectRot",
                                              "crossRot", "star",     "cross", "rectRounded"};

}  // namespace

SeriesStyles::SeriesStyles(const ResultsFile& results) {
  for (const SceneRows& s : results.scenes) {
    for (const OutcomeRow& o : s.outcomes) index_.try_emplace(o.model, index_.size());
    for (const ModalRow& m : s.model_modes) index_.try_emplace(m.model, index_.size());
  }
}

void SeriesStyles::apply(Series& series, const std::string& model) {
  const std::size_t i = index_.try_emplace(model, index_.size()).first->second;
  series.colour = kColours[i % kColours.size()];
  series.marker = kMarkers[(i / kColours.size() + i) % kMarkers.size()];
}

}  // namespace vessel::reports
