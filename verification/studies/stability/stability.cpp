#include "verification/studies/stability/stability.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>

#include "meshes/foundation/errors.hpp"
#include "meshes/vessel_geometry.hpp"
#include "verification/harness/outcome_cache.hpp"
#include "verification/harness/parallel.hpp"
#include "verification/harness/timing.hpp"
#include "verification/studies/stability/rod_steps.hpp"
#include "verification/studies/stability/study_models.hpp"
#include "verification/studies/stability/tet_steps.hpp"

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

namespace {

nlohmann::json optional_bool(const std::optional<bool>& b) {
  return b ? nlohmann::json(*b) : nlohmann::json(nullptr);
}
std::optional<bool> optional_bool(const nlohmann::json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<bool>();
}

/// A hard case as bytes for the outcome cache (CBOR: doubles bit for bit).
std::string serialise_case(const HardCase& hc) {
  nlohmann::json outcomes = nlohmann::json::array();
  for (const HardCaseOutcome& x : hc.outcomes) {
    outcomes.push_back({x.model, x.finished, optional_bool(x.converged), optional_bool(x.bounded),
                        x.reported, x.values});
  }
  const std::vector<std::uint8_t> b =
      nlohmann::json::to_cbor({hc.id, hc.title, hc.setup, outcomes, hc.seconds});
  return {b.begin(), b.end()};
}

HardCase deserialise_case(const std::string& bytes) {
  const nlohmann::json j = nlohmann::json::from_cbor(bytes.begin(), bytes.end());
  HardCase hc;
  hc.id = j.at(0);
  hc.title = j.at(1);
  hc.setup = j.at(2);
  for (const nlohmann::json& x : j.at(3)) {
    HardCaseOutcome out;
    out.model = x.at(0);
    out.finished = x.at(1);
    out.converged = optional_bool(x.at(2));
    out.bounded = optional_bool(x.at(3));
    out.reported = x.at(4);
    x.at(5).get_to(out.values);
    hc.outcomes.push_back(std::move(out));
  }
  hc.seconds = j.at(4);
  return hc;
}

/// The hard case `fn` (one that cannot be set up is recorded as such, not allowed to stop the
/// study), timed.
HardCase run_case(HardCase (*fn)(const StabilityOptions&, std::ostream&), const char* what,
                  std::size_t k, const StabilityOptions& o, std::ostream& log) {
  Stopwatch c;
  HardCase hc;
  try {
    hc = fn(o, log);
  } catch (const std::exception& e) {
    hc.id = "case_" + std::to_string(k);
    hc.title = what;
    hc.setup = "the case could not be set up";
    hc.outcomes.push_back({"setup", false, {}, {}, "failed: " + short_error(e.what()), {}});
    log << "  failed: " << e.what() << std::endl;
  }
  hc.seconds = c.seconds();
  return hc;
}

using CaseFn = HardCase (*)(const StabilityOptions&, std::ostream&);

struct HardCaseEntry {
  const char* what;
  CaseFn fn;
  /// Its outcomes include a measured time (the long run's seconds): it runs alone, after the
  /// others, which may run side by side.
  bool timed;
};

/// Hard case `i` (kHardCaseIds), numbered k: computed, or read from the outcome cache.
HardCase run_or_recall_case(const HardCaseEntry& c, std::size_t i, std::size_t k,
                            const StabilityOptions& o, std::ostream& log, TimingProvenance& p) {
  if (!o.outcome_cache || !o.outcome_cache->enabled()) {
    p = {false, utc_now()};
    return run_case(c.fn, c.what, k, o, log);
  }
  // The options a case reads (the mode, its steps; the rest is code, in the key as the
  // executable's identity).
  const std::string key = "stability-case " + std::string(kHardCaseIds[i]) +
                          " quick=" + std::to_string(o.quick) +
                          " trial_steps=" + std::to_string(o.trial_steps) +
                          " long_run_steps=" + std::to_string(o.long_run_steps) +
                          " max_level=" + std::to_string(o.max_level);
  HardCase hc = deserialise_case(o.outcome_cache->get(
      key, [&] { return serialise_case(run_case(c.fn, c.what, k, o, log)); }, p));
  if (p.cached) log << "  from the outcome cache (measured " << p.measured_at << ")\n";
  return hc;
}

/// The hard cases (all, or o.only_cases) in kHardCaseIds' order. Those without a measured time
/// run o.jobs at a time, each logging into its own buffer (printed when it ends); the timed ones
/// then run alone.
void run_hard_cases(const StabilityOptions& o, const Stopwatch& clock, std::ostream& log,
                    StabilityReport& rep, std::vector<TimingProvenance>& provenance) {
  const HardCaseEntry all_cases[] = {{"ν → 0.5", case_poisson, false},
                                     {"E sweep", case_youngs_modulus, false},
                                     {"sliver tets", case_sliver, false},
                                     {"refined contact patch", case_refined_patch, false},
                                     {"inverting load", case_inverting_load, false},
                                     {"long run", case_long_run, true},
                                     {"tight bend", case_tight_bend, false},
                                     {"zero-length springs", case_zero_length, false}};
  static_assert(std::size(all_cases) == kHardCaseIds.size());
  std::vector<std::size_t> cases;
  for (std::size_t i = 0; i < kHardCaseIds.size(); ++i) {
    if (o.only_cases.empty() || std::find(o.only_cases.begin(), o.only_cases.end(),
                                          kHardCaseIds[i]) != o.only_cases.end()) {
      cases.push_back(i);
    }
  }
  std::vector<std::size_t> side_by_side;  // positions in `cases`
  std::vector<std::size_t> alone;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    (all_cases[cases[k]].timed ? alone : side_by_side).push_back(k);
  }
  std::vector<HardCase> done(cases.size());
  std::vector<TimingProvenance> done_provenance(cases.size());
  const auto header = [&](std::size_t k) {
    std::ostringstream h;
    h << "[stability] hard case " << k + 1 << "/" << cases.size() << ": "
      << all_cases[cases[k]].what;
    return h.str();
  };
  rep.hard_cases_at_a_time = std::max(1, std::min(o.jobs, static_cast<int>(side_by_side.size())));
  std::mutex log_mutex;
  parallel_solves(side_by_side.size(), o.jobs, [&](std::size_t t) {
    const std::size_t k = side_by_side[t];
    std::ostringstream case_log;
    done[k] =
        run_or_recall_case(all_cases[cases[k]], cases[k], k + 1, o, case_log, done_provenance[k]);
    const std::lock_guard lock(log_mutex);
    log << header(k) << ", done in " << fmt(done[k].seconds, 3) << " s (" << fmt(clock.seconds(), 3)
        << " s so far)\n"
        << case_log.str() << std::flush;
  });
  for (const std::size_t k : alone) {
    log << header(k) << ", alone (" << fmt(clock.seconds(), 3) << " s so far)" << std::endl;
    done[k] = run_or_recall_case(all_cases[cases[k]], cases[k], k + 1, o, log, done_provenance[k]);
  }
  for (std::size_t k = 0; k < cases.size(); ++k) {
    rep.hard_cases.push_back(std::move(done[k]));
    provenance.push_back(done_provenance[k]);
  }
}

}  // namespace

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
  std::vector<TimingProvenance> provenance;
  rep.rows = critical_step_table(o, max_level, rep.trial_steps, log, provenance);
  rep.fits = refinement_fits(rep.rows);
  if (o.rod_steps) {
    log << "[stability] the guidewire's critical steps (a metal wire, DER / CORDE / XPBD)"
        << std::endl;
    rep.rod_wire = o.rod_wire;
    rep.rod_rows = rod_critical_steps(o.rod_wire, rep.trial_steps, log);
  }
  if (o.tet_steps) {
    const int tet_level = std::min(max_level, o.tet_max_level);
    log << "[stability] corotational P1's and XPBD FEM's critical steps, levels 0.." << tet_level
        << std::endl;
    rep.tet_rows = tet_critical_steps(o, tet_level, rep.trial_steps, log, provenance);
  }
  if (o.hard_cases) run_hard_cases(o, clock, log, rep, provenance);
  rep.timed_items = provenance.size();
  for (const TimingProvenance& p : provenance) {
    if (p.cached) rep.cached_at.push_back(p.measured_at);
  }
  rep.seconds = clock.seconds();
  log << "[stability] done in " << fmt(rep.seconds, 3) << " s" << std::endl;
  return rep;
}

}  // namespace vessel
