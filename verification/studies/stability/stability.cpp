#include "verification/studies/stability/stability.hpp"

#include <algorithm>
#include <cmath>

#include "meshes/errors.hpp"
#include "meshes/vessel_geometry.hpp"
#include "verification/studies/stability/study_models.hpp"
#include "verification/timing.hpp"

namespace vessel {

using namespace stability_study;

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<std::pair<double, double>> p;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (x[i] > 0 && y[i] > 0 && std::isfinite(x[i]) && std::isfinite(y[i]))
      p.emplace_back(std::log(x[i]), std::log(y[i]));
  }
  if (p.size() < 2) throw InputError("loglog_slope: expected at least two positive pairs");
  double mx = 0, my = 0;
  for (auto [a, b] : p) {
    mx += a;
    my += b;
  }
  mx /= static_cast<double>(p.size());
  my /= static_cast<double>(p.size());
  double sxy = 0, sxx = 0;
  for (auto [a, b] : p) {
    sxy += (a - mx) * (b - my);
    sxx += (a - mx) * (a - mx);
  }
  if (!(sxx > 0)) throw InputError("loglog_slope: expected at least two distinct x values");
  return sxy / sxx;
}

StabilityReport run_stability(const StabilityOptions& o) {
  std::ostream& log = o.log ? *o.log : null_stream();
  Stopwatch clock;
  StabilityReport rep;
  rep.quick = o.quick;
  rep.command_line = o.command_line;
  rep.trial_steps = o.trial_steps > 0 ? o.trial_steps : (o.quick ? 500 : 1000);
  const int max_level = o.max_level >= 0 ? o.max_level : (o.quick ? 1 : 2);
  for (const auto& id : o.only_cases) {
    if (std::find(kHardCaseIds.begin(), kHardCaseIds.end(), id) == kHardCaseIds.end()) {
      std::string known;
      for (const auto k : kHardCaseIds) known += (known.empty() ? "" : ", ") + std::string(k);
      throw InputError("--hard-case: unknown case '" + id + "'; expected one of " + known);
    }
  }
  if (max_level > kMaxMeshLevel) {
    throw InputError("--max-level: expected 0.." + std::to_string(kMaxMeshLevel) + ", got " +
                     std::to_string(max_level));
  }
  log << "[stability] critical steps, levels 0.." << max_level << ", " << rep.trial_steps
      << " steps per trial" << std::endl;
  rep.rows = critical_step_table(o, max_level, rep.trial_steps, log);
  rep.fits = refinement_fits(rep.rows);
  if (o.hard_cases) {
    using CaseFn = HardCase (*)(const StabilityOptions&, std::ostream&);
    const std::pair<const char*, CaseFn> all_cases[] = {
        {"ν → 0.5", case_poisson},          {"E sweep", case_youngs_modulus},
        {"sliver tets", case_sliver},       {"refined contact patch", case_refined_patch},
        {"inverting load", case_inverting_load}, {"long run", case_long_run},
        {"tight bend", case_tight_bend},    {"zero-length springs", case_zero_length}};
    static_assert(std::size(all_cases) == kHardCaseIds.size());
    std::vector<std::pair<const char*, CaseFn>> cases;
    for (std::size_t i = 0; i < kHardCaseIds.size(); ++i) {
      if (o.only_cases.empty() || std::find(o.only_cases.begin(), o.only_cases.end(),
                                            kHardCaseIds[i]) != o.only_cases.end()) {
        cases.push_back(all_cases[i]);
      }
    }
    std::size_t k = 0;
    for (const auto& [what, fn] : cases) {
      ++k;
      log << "[stability] hard case " << k << "/" << std::size(cases) << ": " << what << " ("
          << fmt(clock.seconds(), 3) << " s so far)" << std::endl;
      Stopwatch c;
      HardCase hc;
      try {
        hc = fn(o, log);
      } catch (const std::exception& e) {
        // A case that cannot even be set up is recorded, not allowed to stop the study.
        hc.id = "case_" + std::to_string(k);
        hc.title = what;
        hc.setup = "the case could not be set up";
        hc.outcomes.push_back({"setup", false, {}, {}, "failed: " + short_error(e.what()), {}});
        log << "  failed: " << e.what() << std::endl;
      }
      hc.seconds = c.seconds();
      rep.hard_cases.push_back(std::move(hc));
    }
  }
  rep.seconds = clock.seconds();
  log << "[stability] done in " << fmt(rep.seconds, 3) << " s" << std::endl;
  return rep;
}

}  // namespace vessel
