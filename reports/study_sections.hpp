#pragma once
/// The report's sections built from the studies' files (read as data, reports/study_files.hpp):
/// numerical stability and model recommendation, with the Document's own blocks.
#include "reports/document.hpp"
#include "reports/study_files.hpp"

namespace vessel::reports {

/// "## Numerical stability": predicted against found critical steps, their exponent under
/// refinement, and what every model did on each hard case.
void stability_section(Document& doc, const StabilityFile& stability);

/// "## Model recommendation: <scene> at <rate>": the budget and its loads, the answer, a warning
/// when the tolerance cannot discriminate, and every candidate's evidence (winners first, then
/// by time per update, failures last).
void recommendation_section(Document& doc, const RecommendFile& recommendation);

}  // namespace vessel::reports
