#pragma once
/// The CI gate's comparison: this run's results against a committed baseline (both results files
/// of the same gate scenes). A model fails the gate if its error grows beyond the tolerance, if it
/// finished in the baseline and fails now (diverged, did not converge), if it disappeared, or if
/// its solve time — normalised by a reference kernel timed in the same run, so a faster or slower
/// machine does not count — grew beyond a noise-tolerant ratio. The solve time is results.json's
/// solve_seconds, set-up excluded: for static and linear mass-spring models the time per update
/// (median over the load ramp's warm-started updates), for integrators the run's steps, for FEM
/// the ramp's median update prepared as linear models are. Set-up (build, assembly and
/// factorisation at rest) is not gated.
#include <string>
#include <vector>

#include "reports/document.hpp"
#include "reports/results_file.hpp"

namespace vessel::reports {

struct GateTolerances {
  double error_relative = 0.02;     ///< max and RMS error may grow by this fraction...
  double error_absolute_mm = 1e-6;  ///< ...plus this much (round-off of near-zero errors)
  double error_absolute_mN = 1e-6;  ///< the same for the guidewire's force errors
  double timing_ratio = 2.5;        ///< normalised solve time may grow by this factor (shared, noisy machines)
  double timing_floor_s = 0.05;     ///< solves faster than this in the baseline are too noisy to gate
};

struct GateFinding {
  std::string scene, model;
  double poisson_ratio = 0.0;
  int level = 0;
  double magnitude = 0.0;
  std::string what;      ///< "error grew", "now fails", "missing", "slower", or a note
  std::string baseline;  ///< the baseline's value, as text
  std::string current;   ///< this run's
  bool failure = false;  ///< false: a note (improvement, new model)
};

struct GateOutcome {
  std::vector<GateFinding> findings;
  std::size_t compared = 0;  ///< cases present in both
  [[nodiscard]] bool passed() const;
};

/// Compares every (scene, model, ν, level, load) case of the baseline with this run's, and each
/// guidewire scene's wire: per EI its force error against the continuum wire, and per coupled
/// row (model, ν, level, EI) the contact-force error |F − F_ref|, and with coupling = "contact"
/// per model and EI its contact-force error against the reference's in the same contact solve
/// (their findings name the model "wire (<rod model>)" or the vessel model, with EI in the load
/// column; a contact row's level is 0: every wall is on the contact's own mesh).
/// Timings are compared only when both files carry reference_kernel_seconds.
GateOutcome compare_with_baseline(const ResultsFile& baseline, const ResultsFile& current,
                                  const GateTolerances& tolerances = {});

/// The findings as a table (failures first).
Table gate_table(const GateOutcome& outcome);

}  // namespace vessel::reports
