#include "reports/study_sections.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numeric>
#include <sstream>

namespace vessel::reports {

namespace {

std::string yes_no(const std::optional<bool>& b) {
  if (!b) return "–";
  return *b ? "yes" : "**no**";
}

std::string ms(double seconds) { return significant(seconds * 1e3, 3) + " ms"; }

/// "30 Hz", "1000 Hz" (3 digits would print 1e+03).
std::string hz(double rate) { return significant(rate, 6) + " Hz"; }

Table critical_step_table(const StabilityFile& s) {
  Table t;
  t.header = {"model",
              "integrator",
              "ζ",
              "level",
              "nodes",
              "ω_max (rad/s)",
              "Gershgorin bound",
              "predicted (µs)",
              "guaranteed (µs)",
              "found stable (µs)",
              "found / predicted",
              "found / guaranteed"};
  for (const auto& r : s.critical_steps) {
    const bool proven = r.guaranteed_dt.has_value();
    t.rows.push_back(
        {r.model, r.integrator, significant(r.zeta, 4), std::to_string(r.level),
         std::to_string(r.nodes), significant(r.omega_max, 5), significant(r.omega_gershgorin, 5),
         significant(r.predicted_dt * 1e6, 5),
         proven ? significant(*r.guaranteed_dt * 1e6, 5) : "–", significant(r.found_dt * 1e6, 5),
         significant(r.found_dt / r.predicted_dt, 4),
         proven && *r.guaranteed_dt > 0 ? significant(r.found_dt / *r.guaranteed_dt, 4) : "–"});
  }
  return t;
}

Table refinement_table(const StabilityFile& s) {
  Table t;
  t.header = {"model", "integrator", "ζ", "levels", "p (found)", "p (predicted)"};
  for (const auto& f : s.refinement) {
    std::string levels;
    for (const int l : f.levels) {
      if (!levels.empty()) levels += ',';
      levels += std::to_string(l);
    }
    t.rows.push_back({f.model, f.integrator, significant(f.zeta, 4), levels,
                      significant(f.found_exponent, 3), significant(f.predicted_exponent, 3)});
  }
  return t;
}

/// What an implicit rod row did at its steps: "bounded at every step tried" or the first that
/// was not.
std::string rod_ladder_text(const RodStepEntry& r) {
  if (r.steps_tried.empty()) return "–";
  for (std::size_t k = 0; k < r.steps_tried.size(); ++k) {
    if (!r.bounded[k]) {
      return "**unbounded at " + significant(r.steps_tried[k] * 1e6, 4) + " µs**" +
             (r.failure.empty() ? "" : " (" + r.failure + ")");
    }
  }
  return "bounded at every step tried, " + significant(r.steps_tried.front() * 1e6, 3) + " µs to " +
         significant(r.steps_tried.back() * 1e3, 3) + " ms";
}

void rod_steps(Document& doc, const StabilityFile& s) {
  if (!s.rod_wire || s.rod_steps.empty()) return;
  const RodWireEntry& w = *s.rod_wire;
  doc.heading(3, "The guidewire's critical step");
  doc.paragraph(
      "A metal wire clamped at one end (length " + significant(w.length * 1e3, 4) + " mm, d = " +
      significant(w.diameter * 1e3, 4) + " mm, E = " + significant(w.young * 1e-9, 4) +
      " GPa, G = " + significant(w.shear * 1e-9, 4) + " GPa, ρ = " + significant(w.density, 4) +
      " kg/m³). At rest the straight discrete rod's axial, twist and bending waves decouple, "
      "each with a closed-form highest frequency on segments of length h: axial (2/h)·√(E/ρ), a "
      "chain of springs EA/h and masses ρA·h, so dt = 2/ω = h/c with c = √(E/ρ) (Courant); twist "
      "(2/h)·√(G/ρ); bending (4/h²)·√(EI/ρA), from K = (EI/h³)·Δ⁴ (the turning angle "
      "(w_{i+1} − 2w_i + w_{i−1})/h, energy EI/(2h) per vertex) whose symbol (2 − 2cos kh)² peaks "
      "at 16 — the Euler–Bernoulli dispersion ω = k²√(EI/ρA) with k → 2 sin(kh/2)/h. Symplectic "
      "Euler and Verlet are stable to 2/ω_max; the smallest of the three binds (for a slender wire "
      "the axial one: bending's dt is the axial one times 2h/d). Found: bisection on the "
      "integrator running the Discrete Elastic Rod (msm/rods/der_rod.hpp), as for the vessels. "
      "The implicit integrators — DER and seed 002's CORDE by the same implicit Euler (each "
      "step Newton on the rod's KKT system to convergence), the XPBD rod — ran at steps from "
      "1 µs to a 30 Hz frame instead (from a 1 mm/s random velocity; XPBD from a released tip "
      "load): "
      "bounded means the energy stayed within 1000× its start. Steps in µs.");
  Table t;
  t.header = {"model",        "integrator",         "N",
              "h (mm)",       "axial h/c",          "twist",
              "bending",      "closed form",        "2/ω_max (Lanczos)",
              "found stable", "found / closed form"};
  for (const RodStepEntry& r : s.rod_steps) {
    const bool explicit_row = r.found_dt.has_value();
    t.rows.push_back({r.model, r.integrator, std::to_string(r.segments), significant(r.h * 1e3, 4),
                      significant(r.axial_dt * 1e6, 4), significant(r.twist_dt * 1e6, 4),
                      significant(r.bending_dt * 1e6, 4), significant(r.closed_form_dt * 1e6, 4),
                      r.predicted_dt ? significant(*r.predicted_dt * 1e6, 4) : "–",
                      explicit_row ? significant(*r.found_dt * 1e6, 4) : rod_ladder_text(r),
                      explicit_row ? significant(*r.found_dt / r.closed_form_dt, 4) : "–"});
  }
  doc.table(t);
  doc.paragraph(
      "What each integrator needs: symplectic Euler and Verlet the closed-form step or less, about "
      "h/c (" +
      significant(1e-3 / std::sqrt(w.young / w.density) * 1e6, 3) +
      " µs per mm of segment for this wire), i.e. thousands of steps per 1 ms haptic frame; "
      "explicit Euler no stable step at all without damping; implicit Euler (DER, CORDE) "
      "and XPBD any step tried, at the price of numerical damping (implicit Euler) or of "
      "stiffness lost with few sweeps per step (XPBD, measured in tests/rods/test_xpbd.cpp).");
}

/// An implicit P1 row's ladder: bounded everywhere, or the first step that was not.
std::string tet_ladder_text(const TetStepEntry& r) {
  for (std::size_t k = 0; k < r.steps_tried.size(); ++k) {
    if (!r.bounded[k]) return "unbounded at " + significant(r.steps_tried[k] * 1e3, 4) + " ms";
  }
  return "bounded at every step tried, " + significant(r.steps_tried.front() * 1e3, 3) + " to " +
         significant(r.steps_tried.back() * 1e3, 3) + " ms";
}

void tet_steps(Document& doc, const StabilityFile& s) {
  if (s.tet_steps.empty()) return;
  doc.heading(3, "Corotational P1 and XPBD FEM");
  doc.paragraph(
      "The P1 tet models simulators run instead of springs, on the same tube (ν = " +
      significant(s.tet_steps.front().nu, 3) +
      ", the contact scenes'; the springs' rows above are at ν = 1/4, their Cauchy value). "
      "Corotational P1 (Müller & Gross 2004) by symplectic Euler and Verlet: found by bisection as "
      "for the springs, against 2/ω_max of M⁻¹K at rest (its Hessian there is linear P1's "
      "stiffness) by Lanczos and, independently, by power iteration. By implicit Euler, with the "
      "warped stiffness R K₀ Rᵀ re-assembled each step (SOFA's TetrahedronFEMForceField) and with "
      "K₀ factorised once (what a simulator pays for speed): both are unconditionally stable at "
      "rest, so they ran from rest under a step contact load at steps up to a 30 Hz frame; where "
      "one diverged, its largest bounded step under that load was bisected (no closed form "
      "predicts it: the rest stiffness lacks the turned wall's rotation, integrated explicitly). "
      "XPBD FEM (Macklin & Müller 2021, multipliers carried, its scene defaults: 4 sweeps, 2 % "
      "velocity damping a step): its constraint solve is implicit, but the multipliers it carries "
      "act as an explicit force whose stiffness at rest is linear P1's shear stiffness (λ = "
      "−2μ/3, no bulk stiffness), so its critical step is predicted as 2/ω_max of that stiffness; "
      "below it the steady state is the energy's equilibrium whatever the sweep count, above it "
      "the run diverges. Steps in ms.");
  Table t;
  t.header = {"model",
              "integrator",
              "level",
              "nodes",
              "load (mN)",
              "2/ω_max Lanczos",
              "2/ω_max power iteration",
              "found stable",
              "found / predicted"};
  const auto ms = [](const std::optional<double>& v) {
    return v ? significant(*v * 1e3, 4) : std::string("–");
  };
  for (const TetStepEntry& r : s.tet_steps) {
    std::string found = ms(r.found_dt);
    if (!r.steps_tried.empty()) {
      found = r.found_dt ? found + " (" + tet_ladder_text(r) + ")" : tet_ladder_text(r);
    }
    t.rows.push_back(
        {r.model, r.integrator, std::to_string(r.level), std::to_string(r.nodes),
         significant(r.load * 1e3, 3), ms(r.predicted_dt), ms(r.power_dt), found,
         r.found_dt && r.predicted_dt ? significant(*r.found_dt / *r.predicted_dt, 4) : "–"});
  }
  doc.table(t);
}

void hard_cases(Document& doc, const StabilityFile& s) {
  if (s.hard_cases.empty()) return;
  doc.heading(3, "Hard cases");
  std::string about =
      "Each case lists what every model did: finished (returned a result), "
      "converged (static or linear solve), bounded (dynamic run), and what it "
      "reported. Displacements in mm, loads in mN.";
  if (s.hard_cases_at_a_time > 1) {
    about += " The cases ran " + std::to_string(s.hard_cases_at_a_time) +
             " at a time, so the time after each case's set-up is its wall time on a shared "
             "machine; the long run, whose steps are timed, ran alone.";
  }
  doc.paragraph(about);
  for (const auto& hc : s.hard_cases) {
    doc.heading(4, hc.title);
    doc.paragraph(hc.setup + " (" + significant(hc.seconds, 3) + " s)");
    Table t;
    t.header = {"model", "finished", "converged", "bounded", "reported"};
    for (const auto& o : hc.outcomes) {
      t.rows.push_back({o.model, o.finished ? "yes" : "**no**", yes_no(o.converged),
                        yes_no(o.bounded), o.reported});
    }
    doc.table(t);
  }
}

}  // namespace

void stability_section(Document& doc, const StabilityFile& s) {
  doc.heading(2, "Numerical stability");
  doc.paragraph(
      "How large a time step each explicit integrator of the mass-spring models takes before it "
      "blows up — predicted from the largest eigenvalue of M⁻¹K at rest (Lanczos) and found by "
      "running (bisection on dt, " +
      std::to_string(s.steps_per_trial) +
      " steps per trial from a small random velocity, unstable when the energy exceeds 1000× its "
      "start or turns non-finite) — and what every model does on hard cases. Produced by `" +
      s.command + "`" + (s.quick ? " (quick mode)" : "") + " in " +
      significant(s.total_seconds, 3) + " s (`" + s.path.filename().string() + "`).");
  if (!s.timing_provenance.empty()) {
    doc.paragraph("Timings (per level and model's rows, per hard case): " + s.timing_provenance +
                  ".");
  }
  doc.heading(3, "Predicted vs found stable step");
  doc.paragraph(
      "Straight tube, unstructured levels; surface models on the inner wall (triangle topology), "
      "E = 14.24 kPa, consistent masses, inlet and outlet fixed. Damped rows: point damping "
      "c = 2ζ·ω_max·(mean nodal mass), seed 000 eq. (3.3). Predicted: symplectic Euler "
      "4/(γ + √(γ² + 4ω²)), Verlet the root of its amplification matrix's Jury condition (2/ω "
      "undamped), explicit Euler γ/ω² (= 2ζ/ω) or its overdamped lowest-mode bound, with γ the "
      "damping rate of the top (and lowest) mode. Undamped, the prediction is exact. **Damped, it "
      "is an estimate that may be unsafe**: point damping with non-uniform (consistent) masses "
      "does not decouple into modes, γ is only a Rayleigh quotient, and the found step can be "
      "well below it (found / predicted < 1). The *guaranteed* column is a proven bound instead: "
      "every eigenvalue of the damped system solves λ² + γλ + ω² = 0 for some ω ∈ [ω_min, ω_max] "
      "and γ between the extreme eigenvalues of M⁻¹C (here c/m_max and c/m_min), so the smallest "
      "critical step over that rectangle is safe for explicit and symplectic Euler "
      "(`msm/solvers/critical_step.hpp`; none is proven for damped Verlet). Use it, not the "
      "prediction, as a safe damped step. Steps in µs.");
  doc.table(critical_step_table(s));
  doc.paragraph(
      "Explicit Euler without damping is not in the table: it is unstable at every step "
      "(|1 + ihω| > 1; the energy grows by a factor 1 + h²ω² per step in each mode), "
      "asserted by the test suite.");
  doc.heading(3, "Step against refinement");
  doc.paragraph(
      "Least-squares exponent p of dt ∝ h^p over the levels (h the nominal element "
      "size, halved per level; p = 1 expected for springs whose k scales like E·h and "
      "masses like ρh³).");
  doc.table(refinement_table(s));
  tet_steps(doc, s);
  rod_steps(doc, s);
  hard_cases(doc, s);
}

namespace {

std::string load_text(const RecommendFile& r, double magnitude) {
  if (r.load_unit == "N") return significant(magnitude * 1e3, 3) + " mN";
  if (r.load_unit.empty()) return significant(magnitude, 3) + " (the scene's load unit)";
  return significant(magnitude, 3) + " " + r.load_unit;
}

std::string budget_text(const RecommendFile& r) {
  std::string t = "the " + r.quantity;
  if (r.radius_mm) t += " (within " + significant(*r.radius_mm, 3) + " mm)";
  t += " error ≤ " + significant(r.tolerance, 3) + " " + r.unit + ", and ≤ " +
       ms(r.seconds_per_update) + " of computation per update";
  if (r.rate_hz) t += " (" + hz(*r.rate_hz) + ")";
  for (const auto& l : r.loads) {
    t += "; at ν = " + significant(l.poisson_ratio, 6) + " the load is " +
         load_text(r, l.magnitude) + " (reference " +
         (l.reference_element.empty() ? "" : l.reference_element + ", ") + "level " +
         std::to_string(r.reference_level) + ")";
  }
  return t;
}

const CandidateEntry* candidate_named(const RecommendFile& r, const std::optional<std::string>& n) {
  if (!n) return nullptr;
  for (const auto& c : r.candidates) {
    if (c.name == *n) return &c;
  }
  return nullptr;
}

std::string error_text(const CandidateEntry& c, const std::string& unit) {
  return c.error ? significant(*c.error, 3) + " " + unit : "not computable";
}

/// The reason every candidate gives, if they all give the same one (e.g. a reference that judges
/// none of them); empty otherwise.
std::string shared_reason(const RecommendFile& r) {
  if (r.candidates.empty()) return "";
  const std::string& first = r.candidates.front().reason;
  for (const auto& c : r.candidates) {
    if (c.reason != first) return "";
  }
  return first;
}

void answer(Document& doc, const RecommendFile& r) {
  if (const CandidateEntry* best = candidate_named(r, r.recommended)) {
    doc.paragraph("**Recommended: `" + best->name + "`** (" + best->detail + "): error " +
                  error_text(*best, r.unit) + ", " + ms(best->update_seconds.value_or(0.0)) +
                  " per update, " + std::to_string(best->unknowns) + " unknowns." +
                  (best->setup_seconds ? " Set-up " + ms(*best->setup_seconds) + ", once." : "") +
                  (best->roi_radius_mm ? "" : " The whole vessel (no region of interest)."));
  } else if (const CandidateEntry* near = candidate_named(r, r.closest)) {
    doc.paragraph("**No candidate meets the budget.** The closest is `" + near->name + "` (" +
                  near->detail + "): error " + error_text(*near, r.unit) + ", " +
                  ms(near->update_seconds.value_or(0.0)) + " per update; " + near->reason + ".");
  } else if (const std::string why = shared_reason(r); !why.empty()) {
    doc.paragraph("**No candidate meets the budget**, and none finished; every one " + why + ".");
  } else {
    doc.paragraph("**No candidate meets the budget**, and none finished.");
  }
  const CandidateEntry* whole = candidate_named(r, r.whole_vessel);
  if (whole && r.whole_vessel != r.recommended) {
    doc.paragraph("Whole vessel (no region of interest): `" + whole->name + "` (" + whole->detail +
                  ") meets the budget too: error " + error_text(*whole, r.unit) + ", " +
                  ms(whole->update_seconds.value_or(0.0)) + " per update, " +
                  std::to_string(whole->unknowns) + " unknowns.");
  } else if (!whole && r.whole_vessel_reported) {
    doc.paragraph("No whole-vessel candidate (without a region of interest) meets the budget.");
  }
  // A tolerance at or above the reference's own contact displacement is met by a model that does
  // not move at all: the answer then says nothing about accuracy.
  if (r.unit == "mm" && r.reference_contact_point_mm > 0.0 &&
      r.tolerance >= r.reference_contact_point_mm) {
    doc.paragraph(
        "⚠ **The tolerance does not discriminate**: at this load the reference's "
        "contact point moves " +
        significant(r.reference_contact_point_mm, 3) + " mm, no more than the " +
        significant(r.tolerance, 3) +
        " mm tolerance, so a model that does not move at all would meet it. State a "
        "tighter tolerance or a larger load (`magnitude`) for an answer about accuracy.");
  }
}

/// Winners first (recommended, then meeting the budget), then by time per update; failures last.
std::vector<const CandidateEntry*> evidence_order(const RecommendFile& r) {
  std::vector<const CandidateEntry*> order;
  for (const auto& c : r.candidates) order.push_back(&c);
  const auto rank = [](const CandidateEntry* c) {
    if (c->verdict == "failed") return 3;
    if (c->verdict == "recommended") return 0;
    return c->verdict.starts_with("meets") ? 1 : 2;
  };
  std::stable_sort(order.begin(), order.end(), [&](const auto* a, const auto* b) {
    if (rank(a) != rank(b)) return rank(a) < rank(b);
    return a->update_seconds.value_or(0.0) < b->update_seconds.value_or(0.0);
  });
  return order;
}

Table evidence_table(const RecommendFile& r) {
  Table t;
  t.header = {"candidate",
              "unknowns",
              "error (" + r.unit + ")",
              "time per update (ms)",
              "set-up (ms)",
              "Pareto",
              "verdict",
              "why"};
  for (const CandidateEntry* c : evidence_order(r)) {
    t.rows.push_back({"`" + c->name + "`", std::to_string(c->unknowns),
                      c->ok && c->error ? significant(*c->error, 3) : "–",
                      c->ok && c->update_seconds ? significant(*c->update_seconds * 1e3, 3) : "–",
                      c->ok && c->setup_seconds ? significant(*c->setup_seconds * 1e3, 3) : "–",
                      c->pareto ? "★" : "", c->verdict, c->reason});
  }
  return t;
}

/// A guidewire scene's wire candidates: each rod model against the continuum wire.
void wire_candidates(Document& doc, const RecommendFile& r) {
  if (!r.wire) return;
  const WireEntry& w = *r.wire;
  doc.heading(3, "The guidewire's rod model");
  if (w.reference.empty()) {
    doc.paragraph("No rod model judged: " + w.no_reference + ".");
    return;
  }
  doc.paragraph(
      "The wire against the rigid lumen, each rod model of msm/rods (Discrete Elastic Rods, "
      "seed 002's CORDE, the XPBD rod's steady state) at a few segment counts, against the "
      "continuum wire (" +
      w.reference + ", F = " + significant(w.reference_force_N * 1e3, 4) + " mN), judged on the " +
      (r.unit == "mN" ? "contact force's error" : "contact point's error") +
      " and its time per "
      "update, set-up apart (median of 10): for DER and CORDE the wire moved by one update's "
      "travel at 10 mm/s and solved again from its last equilibrium, for XPBD one step of the "
      "update period (its error is its steady state's, reached once the wire is at rest). "
      "**Recommended: " +
      (w.recommended ? "`" + *w.recommended + "`" : std::string("none")) + "**.");
  Table t;
  t.header = {"candidate",
              "force error (mN)",
              "contact point error (mm)",
              "time per update (ms)",
              "set-up (ms)",
              "verdict",
              "why"};
  for (const WireCandidateEntry& c : w.candidates) {
    if (!c.ok) {
      t.rows.push_back({"`" + c.name + "`", "–", "–", "–", "–", c.verdict, c.failure});
      continue;
    }
    t.rows.push_back({"`" + c.name + "`", significant(c.force_error_mN, 3),
                      significant(c.contact_error_mm, 3), significant(c.update_seconds * 1e3, 3),
                      significant(c.setup_seconds * 1e3, 3), c.verdict, c.reason});
  }
  doc.table(t);
}

/// A guidewire scene's wire–vessel pairs: the recommended (or closest) pair and the Pareto front.
void pair_candidates(Document& doc, const RecommendFile& r) {
  if (!r.pairs) return;
  const PairsEntry& p = *r.pairs;
  doc.heading(3, "The wire and the vessel together");
  std::string answer =
      "**Recommended: " + (p.recommended ? "`" + *p.recommended + "`" : std::string("none")) + "**";
  if (!p.recommended && p.closest) answer += "; closest: `" + *p.closest + "`";
  doc.paragraph(
      "A simulator runs a rod model and a vessel model together: every finished wire candidate "
      "with every finished vessel candidate (" +
      std::to_string(p.pairs.size()) +
      " pairs), judged against the same budget. A pair's error is the sum of the two errors "
      "above, each against its own reference (the wire's against the continuum wire in the rigid "
      "lumen, the vessel's against the FEM reference under the wire's load): a bound on the "
      "pair's error as long as the wire's error does not change with the wall's compliance, an "
      "estimate rather than a solve of the pair. Its time per update is the sum of the two; the "
      "exchange of the contact force between them is not timed. " +
      answer + ". The table lists the Pareto front (no other pair both faster and more accurate)" +
      (p.recommended ? " and the recommended pair." : "."));
  Table t;
  t.header = {"pair", "error (" + r.unit + ")", "time per update (ms)", "set-up (ms)", "verdict",
              "why"};
  std::vector<const PairCandidateEntry*> shown;
  for (const PairCandidateEntry& c : p.pairs) {
    if (c.pareto || (p.recommended && c.name == *p.recommended)) shown.push_back(&c);
  }
  std::stable_sort(shown.begin(), shown.end(), [](const auto* a, const auto* b) {
    return a->update_seconds < b->update_seconds;
  });
  for (const PairCandidateEntry* c : shown) {
    t.rows.push_back({"`" + c->name + "`", c->error ? significant(*c->error, 3) : "–",
                      significant(c->update_seconds * 1e3, 3),
                      significant(c->setup_seconds * 1e3, 3), c->verdict, c->reason});
  }
  doc.table(t);
}

}  // namespace

void recommendation_section(Document& doc, const RecommendFile& r) {
  // Headings differ per rate, so one report can hold the visual and the haptic answers.
  doc.heading(2, "Model recommendation: " + r.scene +
                     (r.rate_hz ? " at " + hz(*r.rate_hz)
                                : ", " + ms(r.seconds_per_update) + " per update"));
  std::string levels;
  for (const int l : r.model_levels) {
    levels += ' ';
    levels += std::to_string(l);
  }
  doc.paragraph("Budget: " + budget_text(r) + ". " + std::to_string(r.candidates.size()) +
                " candidates (generated from the mass-spring library's stiffness rules and "
                "solvers, surface and volume, mesh levels" +
                levels +
                ", regions of interest; FEM P1 for comparison) were run against the FEM "
                "reference by");
  doc.code(r.command);
  answer(doc, r);
  doc.paragraph(std::string(kTimePerUpdateText) +
                " Errors are the worst over the scene's Poisson's ratios, "
                "against the P2 reference at each model node; region-of-interest models (R) hold "
                "every node farther than R from the contact and are compared on the whole vessel. "
                "★ marks the Pareto front (no other candidate is both faster and more accurate). "
                "From `" +
                r.path.filename().string() + "`.");
  doc.table(evidence_table(r));
  if (!r.timing_provenance.empty()) doc.paragraph("Timings: " + r.timing_provenance + ".");
  wire_candidates(doc, r);
  pair_candidates(doc, r);
}

namespace {

/// A load in the report's unit: contact forces in mN, others in the scene's unit.
std::string load_text(double load, const std::string& unit) {
  if (unit == "N") return significant(load * 1e3, 3) + " mN";
  return significant(load, 3) + " " + unit;
}

std::string percent(double x) { return significant(100.0 * x, 3) + " %"; }

std::string crossing_text(const ValidityCrossingEntry& c, const std::string& unit) {
  if (c.status == "not_reached") return "not reached up to " + load_text(c.lower, unit);
  if (c.status == "below_ladder") return "at or below " + load_text(c.upper, unit);
  return load_text(*c.load, unit) + " (between " + load_text(c.lower, unit) + " and " +
         load_text(c.upper, unit) + ")";
}

void validity_scene(Document& doc, const ValiditySceneEntry& v) {
  doc.heading(3, v.scene + " (" + v.load_kind + ", ν = " + significant(v.poisson_ratio, 3) + ")");
  std::string p = "References: " + v.element + " on level " + std::to_string(v.reference_level) +
                  " (" + std::to_string(v.dofs) + " DoFs); models on level " +
                  std::to_string(v.model_level) + ". Finite-strain continuation: ";
  if (v.completed) {
    p += "equilibrium at every load of the ladder, up to " +
         load_text(v.largest_load, v.load_unit) + ". ";
  } else if (v.self_contact) {
    p += "**stopped where the wall would touch itself: the largest load reached without the wall "
         "passing through itself is " +
         load_text(v.largest_load, v.load_unit) +
         "**; beyond it the vessel has no equilibrium this reference can represent (it models no "
         "self-contact). Details: " +
         v.stop_reason + ". The rows end at the last ladder load reached. ";
  } else {
    p += "**stopped: the largest load reached is " + load_text(v.largest_load, v.load_unit) +
         "** (" + v.stop_reason + "); the rows end at the last ladder load reached. ";
  }
  p += "Cost: " + std::to_string(v.load_steps) + " load steps (" +
       std::to_string(v.rejected_steps) + " rejected), " + std::to_string(v.newton_iterations) +
       " Newton iterations, " + significant(v.solve_seconds, 3) + " s of assembly and solves" +
       (v.from_cache ? " (read from the FEM solution cache this run; the original solve's time)"
                     : "") +
       ".";
  doc.paragraph(p);
  Table limits;
  limits.header = {"references part by", "at the QoI (contact point)",
                   "over the mesh (relative L2)"};
  for (std::size_t k = 0; k < v.qoi_limits.size() && k < v.l2_limits.size(); ++k) {
    limits.rows.push_back({percent(v.qoi_limits[k].threshold),
                           crossing_text(v.qoi_limits[k], v.load_unit),
                           crossing_text(v.l2_limits[k], v.load_unit)});
  }
  doc.table(limits);
  Table rows;
  rows.header = {"load",          "u finite strain (mm)", "u linear (mm)",  "QoI difference",
                 "L2 difference", "linear strain",        "lumen gap (mm)", "Newton its (cum.)"};
  for (const std::string& m : v.models) rows.header.push_back(m + ": rel. L2 / QoI error (mm)");
  for (const ValidityRowEntry& r : v.rows) {
    std::vector<std::string> row = {load_text(r.magnitude, v.load_unit),
                                    significant(r.finite_qoi_mm, 3),
                                    significant(r.linear_qoi_mm, 3),
                                    percent(r.qoi_difference),
                                    percent(r.l2_difference),
                                    percent(r.linear_strain),
                                    r.wall_gap_mm ? significant(*r.wall_gap_mm, 3) : "–",
                                    std::to_string(r.newton_iterations)};
    for (const ValidityModelEntry& e : r.models) {
      row.push_back(e.ok ? significant(e.relative_l2, 3) + " / " + significant(e.qoi_error_mm, 3)
                         : "failed: " + e.failure);
    }
    rows.rows.push_back(std::move(row));
  }
  doc.table(rows);
  doc.slot(validity_view_slot(v.scene));  // report.html: the models against it in 3D
}

}  // namespace

void validity_section(Document& doc, const ValidityFile& v) {
  doc.heading(2, "Limit of the linear reference, and the models at finite strain");
  doc.paragraph(
      "The linear FEM reference scaled to each load against the finite-strain one (compressible "
      "neo-Hookean with the same E and ν, same mesh, elements, supports and dead loads; one load "
      "continuation through the ladder, docs/physics/finite_strain.md). *QoI difference* is "
      "|u_lin − u_fs| / |u_fs| at the scene's QoI point, *L2 difference* the same over the "
      "reference mesh's nodes. The loads where they part by 1, 5 and 10 % are interpolated "
      "between the two ladder loads that bracket the threshold, ln F linear in ln d (exact for a "
      "power law; at small loads d grows like F since the references differ by O(F²)). The "
      "models' columns are their relative L2 error over their nodes and the displacement error "
      "at their QoI node against the finite-strain reference. *linear strain* is the linear "
      "reference's largest principal strain (the run flags results beyond 5 %). *lumen gap* is "
      "how close the finite-strain wall comes to touching itself: the smallest distance between "
      "inner-wall nodes at least the inner radius apart at rest (so about the inner radius at "
      "rest, and 0 where the wall touches itself; node to node, up to an element size above the "
      "surfaces' gap). The continuation "
      "stops where a wall node would enter the wall elsewhere, which this reference cannot "
      "represent (it models no self-contact). Made by " +
      std::string("`") + v.command + "`" + (v.full ? " (full)" : "") + " in " +
      significant(v.total_seconds, 3) + " s.");
  for (const ValiditySceneEntry& s : v.scenes) validity_scene(doc, s);
}

namespace {

std::string fixed3(double v) { return decimals(v, 3); }

std::string case_load(const CalibrationCaseEntry& c) {
  return significant(c.magnitude, 6) + " " + c.load_unit;
}

Table calibration_case_table(const CalibrateFile& c, bool training) {
  Table t;
  t.header = {"scene",
              "level",
              "case",
              "holds out",
              "load",
              "P1",
              "base",
              "calibrated",
              "calibrated / P1",
              "base s/update",
              "calibrated s/update",
              "P1 solve s",
              "reference max strain"};
  const auto or_dash = [](const std::optional<double>& x, auto&& show) {
    return x ? show(*x) : std::string("—");
  };
  const auto s3 = [](double x) { return significant(x, 3); };
  for (const CalibrationCaseEntry& e : c.cases) {
    if (e.training != training) continue;
    t.rows.push_back(
        {e.scene, std::to_string(e.level), e.name, e.holds_out, case_load(e),
         decimals(e.p1_relative_l2, 3), or_dash(e.base_relative_l2, fixed3),
         or_dash(e.calibrated_relative_l2, fixed3),
         or_dash(e.calibrated_relative_l2, [&](double x) { return decimals(x / e.p1_relative_l2, 3); }),
         or_dash(e.base_update_seconds, s3), or_dash(e.calibrated_update_seconds, s3),
         s3(e.p1_solve_seconds), significant(100.0 * e.max_strain_reference, 2) + " %"});
  }
  return t;
}

}  // namespace

void calibration_section(Document& doc, const CalibrateFile& c) {
  doc.heading(1, "Calibration of " + c.model + " (" + c.scene + ", " + c.granularity + ")");
  doc.code(c.command);
  doc.paragraph("Model: " + c.model_detail + ", ν = " + significant(c.poisson_ratio, 6) + ", " +
                c.vessel + " (mesh " + c.mesh_hash + ", " + std::to_string(c.nodes) + " nodes, " +
                std::to_string(c.springs) + " springs). Fit: " + c.method + ". " +
                std::to_string(c.parameter_count) + " parameters, " + std::to_string(c.iterations) +
                " iterations (" + c.stop_reason + "), " + decimals(c.fit_seconds, 3) + " s; objective " +
                significant(c.objective_before, 6) + " → " + significant(c.objective_after, 6) +
                ". Written to `" + c.calibration_file + "`.");
  if (!c.parameters.empty()) {
    Table t;
    t.header = {"parameter", "factor"};
    for (const auto& p : c.parameters) t.rows.push_back({p.name, decimals(p.factor, 3)});
    doc.table(t);
  } else {
    doc.paragraph(std::string(c.granularity == "per_spring" ? "Per-spring" : "Per-section-spring") +
                  " factors (kappa included): min " + decimals(c.factor_min, 3) + ", median " +
                  decimals(c.factor_median, 3) + ", max " + decimals(c.factor_max, 3) + ".");
  }
  doc.paragraph(
      "Relative L2 errors against the P2 reference at the model's nodes (P1 at its "
      "mesh's nodes), each model solved as the scene solves it; *s/update*: the median "
      "time per update of a warm-started load ramp (set-up apart).");
  doc.heading(2, "Training loads");
  doc.table(calibration_case_table(c, true));
  doc.heading(2, "Held-out loads");
  doc.table(calibration_case_table(c, false));
  std::string last_failure;
  for (const CalibrationCaseEntry& e : c.cases) {
    if (!e.failure.empty() && e.failure != last_failure) {  // a transfer's refusal once
      doc.paragraph(e.scene + " " + e.name + " (" + case_load(e) +
                    "): calibrated model not evaluated: " + e.failure);
      last_failure = e.failure;
    }
    if (!e.base_failure.empty()) {
      doc.paragraph(e.scene + " " + e.name + " (" + case_load(e) +
                    "): uncalibrated model not evaluated: " + e.base_failure);
    }
  }
}

namespace {

template <class File, class Section>
std::string section_markdown(const File& file, Section&& section) {
  Document doc;
  section(doc, file);
  return doc.markdown_text(".");
}

}  // namespace

std::string stability_markdown(const StabilityFile& stability) {
  return section_markdown(stability, stability_section);
}

std::string recommendation_markdown(const RecommendFile& recommendation) {
  return section_markdown(recommendation, recommendation_section);
}

std::string calibration_markdown(const CalibrateFile& calibration) {
  return section_markdown(calibration, calibration_section);
}

}  // namespace vessel::reports
