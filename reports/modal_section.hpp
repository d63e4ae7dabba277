#pragma once
/// A scene's natural frequencies in the report (issue 14): each model's lowest modes beside the
/// modal reference's, their ratios mode by mode, and a figure of those ratios.
#include "reports/document.hpp"
#include "reports/results_file.hpp"
#include "reports/series_style.hpp"

namespace vessel::reports {

/// Nothing when the scene has no modes (run without [modes]).
void natural_frequency_section(Document& doc, const SceneRows& scene, SeriesStyles& styles);

}  // namespace vessel::reports
