#include "reports/gate.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

namespace vessel::reports {

namespace {

using Key = std::tuple<std::string, std::string, double, int, double>;

Key key_of(const SceneRows& s, const OutcomeRow& o) {
  return {s.name, o.model, o.poisson_ratio, o.level, o.magnitude};
}

std::map<Key, const OutcomeRow*> index(const ResultsFile& r) {
  std::map<Key, const OutcomeRow*> out;
  for (const auto& s : r.scenes) {
    for (const auto& o : s.outcomes) out[key_of(s, o)] = &o;
  }
  return out;
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

GateFinding finding(const Key& k, std::string what, std::string baseline, std::string current,
                    bool failure) {
  return {std::get<0>(k), std::get<1>(k), std::get<2>(k), std::get<3>(k), std::get<4>(k),
          std::move(what), std::move(baseline), std::move(current), failure};
}

/// coupling = "contact": each model's contact-force error against the reference's in the same
/// contact solve, per EI, may not grow (nor a finished row fail, nor a row disappear).
void compare_contact_rows(const std::string& scene, const GuidewireContactRows& b,
                          const std::optional<GuidewireContactRows>& c,
                          const std::function<bool(double, double)>& grew, GateOutcome& out) {
  const std::string what = "wire-wall contact-force error |F − F_ref|";
  for (const ContactRun& run : b.runs) {
    const ContactRun* now = nullptr;
    if (c) {
      for (const ContactRun& r : c->runs) {
        if (r.bending_stiffness == run.bending_stiffness) now = &r;
      }
    }
    for (const ContactWallRow& m : run.models) {
      ++out.compared;
      const ContactWallRow* is = nullptr;
      if (now) {
        for (const ContactWallRow& r : now->models) {
          if (r.model == m.model) is = &r;
        }
      }
      if (!is) {
        out.findings.push_back({scene, m.model, b.poisson_ratio, 0, run.bending_stiffness,
                                what + " missing", "present", "absent", true});
        continue;
      }
      if (!m.ok || !m.force_error_mN) continue;
      if (!is->ok || !is->force_error_mN) {
        out.findings.push_back({scene, m.model, b.poisson_ratio, 0, run.bending_stiffness,
                                "contact solve now fails", "finished",
                                is->ok ? "the reference failed" : is->failure, true});
        continue;
      }
      const double was = std::abs(*m.force_error_mN), is_now = std::abs(*is->force_error_mN);
      if (grew(was, is_now)) {
        out.findings.push_back({scene, m.model, b.poisson_ratio, 0, run.bending_stiffness,
                                what + " grew", num(was) + " mN", num(is_now) + " mN", true});
      }
    }
  }
}

/// The guidewire's figures: the wire's force error against the continuum per EI, each coupled
/// row's contact-force error and each contact row's, may not grow (nor a finished row fail, nor a
/// row disappear).
void compare_guidewires(const ResultsFile& baseline, const ResultsFile& current,
                        const GateTolerances& tol, GateOutcome& out) {
  const auto grew = [&](double was, double is) {
    return is > was * (1.0 + tol.error_relative) + tol.error_absolute_mN;
  };
  for (const SceneRows& b : baseline.scenes) {
    if (!b.guidewire) continue;
    const auto it = std::find_if(current.scenes.begin(), current.scenes.end(),
                                 [&](const SceneRows& s) { return s.name == b.name; });
    const std::string wire = "wire (" + b.guidewire->model + ")";
    if (it == current.scenes.end()) continue;  // the scene's outcomes are reported missing
    if (!it->guidewire) {
      out.findings.push_back({b.name, wire, 0.0, 0, 0.0, "guidewire missing", "present", "absent", true});
      continue;
    }
    const GuidewireRows& c = *it->guidewire;
    for (const GuidewireRigidRow& r : b.guidewire->rigid) {
      if (!r.force_error_mN) continue;
      const auto now = std::find_if(c.rigid.begin(), c.rigid.end(), [&](const auto& x) {
        return x.bending_stiffness == r.bending_stiffness;
      });
      ++out.compared;
      if (now == c.rigid.end() || !now->force_error_mN) {
        out.findings.push_back({b.name, wire, 0.0, 0, r.bending_stiffness,
                                "wire force error (vs continuum) missing", num(*r.force_error_mN) + " mN",
                                "absent", true});
      } else if (grew(*r.force_error_mN, *now->force_error_mN)) {
        out.findings.push_back({b.name, wire, 0.0, 0, r.bending_stiffness,
                                "wire force error (vs continuum) grew", num(*r.force_error_mN) + " mN",
                                num(*now->force_error_mN) + " mN", true});
      }
    }
    for (const GuidewireCoupledRow& r : b.guidewire->coupled) {
      const auto now = std::find_if(c.coupled.begin(), c.coupled.end(), [&](const auto& x) {
        return x.model == r.model && x.poisson_ratio == r.poisson_ratio && x.level == r.level &&
               x.bending_stiffness == r.bending_stiffness;
      });
      const std::string what = "coupled contact-force error |F − F_ref|";
      ++out.compared;
      if (now == c.coupled.end()) {
        out.findings.push_back({b.name, r.model, r.poisson_ratio, r.level, r.bending_stiffness,
                                what + " missing", "present", "absent", true});
        continue;
      }
      if (!r.ok) continue;
      if (!now->ok) {
        out.findings.push_back({b.name, r.model, r.poisson_ratio, r.level, r.bending_stiffness,
                                "coupled force now fails", "finished", now->failure, true});
        continue;
      }
      const double was = std::abs(r.force_mN - r.reference_force_mN);
      const double is = std::abs(now->force_mN - now->reference_force_mN);
      if (grew(was, is)) {
        out.findings.push_back({b.name, r.model, r.poisson_ratio, r.level, r.bending_stiffness,
                                what + " grew", num(was) + " mN", num(is) + " mN", true});
      }
    }
    if (b.guidewire->contact)
      compare_contact_rows(b.name, *b.guidewire->contact, c.contact, grew, out);
  }
}

}  // namespace

bool GateOutcome::passed() const {
  return std::none_of(findings.begin(), findings.end(), [](const auto& f) { return f.failure; });
}

GateOutcome compare_with_baseline(const ResultsFile& baseline, const ResultsFile& current,
                                  const GateTolerances& tol) {
  GateOutcome out;
  const auto base = index(baseline);
  const auto now = index(current);
  const bool timed = baseline.reference_kernel_seconds && current.reference_kernel_seconds &&
                     *baseline.reference_kernel_seconds > 0 && *current.reference_kernel_seconds > 0;
  for (const auto& [k, b] : base) {
    const auto it = now.find(k);
    if (it == now.end()) {
      out.findings.push_back(finding(k, "missing from this run", "present", "absent", true));
      continue;
    }
    const OutcomeRow& c = *it->second;
    ++out.compared;
    if (b->ok && !c.ok) {
      out.findings.push_back(finding(k, "now fails", "finished", c.failure, true));
      continue;
    }
    if (!b->ok) {
      if (c.ok) out.findings.push_back(finding(k, "now finishes (was failing)", b->failure, "finished", false));
      continue;
    }
    const auto grew = [&](double was, double is) {
      return is > was * (1.0 + tol.error_relative) + tol.error_absolute_mm;
    };
    const auto shrank = [&](double was, double is) {
      return is < was * (1.0 - tol.error_relative) - tol.error_absolute_mm;
    };
    if (grew(b->max_mm, c.max_mm)) {
      out.findings.push_back(finding(k, "max error grew", num(b->max_mm) + " mm", num(c.max_mm) + " mm", true));
    } else if (grew(b->rms_mm, c.rms_mm)) {
      out.findings.push_back(finding(k, "RMS error grew", num(b->rms_mm) + " mm", num(c.rms_mm) + " mm", true));
    } else if (shrank(b->max_mm, c.max_mm)) {
      out.findings.push_back(finding(k, "max error fell (update the baseline to keep it)",
                                     num(b->max_mm) + " mm", num(c.max_mm) + " mm", false));
    }
    if (timed && b->solve_seconds >= tol.timing_floor_s) {
      const double was = b->solve_seconds / *baseline.reference_kernel_seconds;
      const double is = c.solve_seconds / *current.reference_kernel_seconds;
      if (is > tol.timing_ratio * was) {
        out.findings.push_back(finding(k, "slower (normalised solve time)", num(was) + " kernels",
                                       num(is) + " kernels", true));
      } else if (is * tol.timing_ratio < was) {
        out.findings.push_back(finding(k, "faster (normalised solve time)", num(was) + " kernels",
                                       num(is) + " kernels", false));
      }
    }
  }
  compare_guidewires(baseline, current, tol, out);
  for (const auto& [k, c] : now) {
    if (!base.count(k)) out.findings.push_back(finding(k, "new, not in the baseline", "", c->ok ? "finished" : c->failure, false));
  }
  std::stable_sort(out.findings.begin(), out.findings.end(),
                   [](const auto& a, const auto& b) { return a.failure && !b.failure; });
  return out;
}

Table gate_table(const GateOutcome& outcome) {
  Table t;
  t.header = {"", "scene", "model", "ν", "level", "load", "what", "baseline", "this run"};
  for (const auto& f : outcome.findings) {
    t.rows.push_back({f.failure ? "FAIL" : "note", f.scene, f.model, num(f.poisson_ratio),
                      std::to_string(f.level), num(f.magnitude), f.what, f.baseline, f.current});
  }
  return t;
}

}  // namespace vessel::reports
