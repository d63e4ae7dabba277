#pragma once
/// The report's sections built from the studies' files (read as data, reports/study_files.hpp):
/// numerical stability and model recommendation, with the Document's own blocks.
#include "reports/document.hpp"
#include "reports/study_files.hpp"

namespace vessel::reports {

/// "## Numerical stability": predicted against found critical steps, their exponent under
/// refinement, and what every model did on each hard case.
void stability_section(Document& doc, const StabilityFile& stability);

/// What a recommendation's "time per update" and "set-up" are (the paragraph under its answer,
/// shared by `vesselverify recommend`'s recommend.md and the report).
inline constexpr const char* kTimePerUpdateText =
    "Time per update, on which the budget is judged: for static and linear solvers the median "
    "over a load ramp of warm-started updates ending at the budget's load, each from the "
    "previous state (the linear model one solve with its factorisation at rest, or, for a load "
    "on the prepared load's dofs, the superposition of their responses precomputed at set-up; "
    "static Newton "
    "reusing the factorisation it holds while it converges fast, refactorising where not); for "
    "integrators the time per step × the steps one update period needs. Set-up (model build, "
    "assembly and factorisation at rest) is done once and shown apart.";

/// "## Model recommendation: <scene> at <rate>": the budget and its loads, the answer, a warning
/// when the tolerance cannot discriminate, and every candidate's evidence (winners first, then
/// by time per update, failures last).
void recommendation_section(Document& doc, const RecommendFile& recommendation);

/// "## Limit of the linear reference, and the models at finite strain": per scene of
/// validity.json, the loads where the linear and the finite-strain references part by 1, 5 and
/// 10 %, how far the continuation went (and why it stopped), its cost, and each model's errors
/// against the finite-strain reference at every load of the ladder reached.
void validity_section(Document& doc, const ValidityFile& validity);

}  // namespace vessel::reports
