#pragma once
/// The report's sections built from the studies' JSON documents (read as data,
/// reports/study_files.hpp): numerical stability, model recommendation, the linear reference's
/// validity and calibration, with the Document's own blocks. The studies' own Markdown files
/// (stability.md, recommend.md, calibrate's --summary) are these sections alone (*_markdown).
#include "reports/document.hpp"
#include "reports/study_files.hpp"

namespace vessel::reports {

/// "## Numerical stability": predicted against found critical steps, their exponent under
/// refinement, and what every model did on each hard case.
void stability_section(Document& doc, const StabilityFile& stability);

/// What a recommendation's "time per update" and "set-up" are (the paragraph under its answer,
/// in `vesselverify recommend`'s recommend.md and the report).
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

/// "# Calibration of <model> (<scene>, <granularity>)": the fit (its factors, or their range for
/// per-spring fits), then P1's, the base and the calibrated model's relative L2 errors on the
/// training and on the held-out loads, and why a model could not be evaluated on a case.
void calibration_section(Document& doc, const CalibrateFile& calibration);

/// Each section alone as Markdown: what the study's command writes beside its JSON document
/// (stability.md, recommend.md) or prints (calibrate).
std::string stability_markdown(const StabilityFile& stability);
std::string recommendation_markdown(const RecommendFile& recommendation);
std::string calibration_markdown(const CalibrateFile& calibration);

}  // namespace vessel::reports
