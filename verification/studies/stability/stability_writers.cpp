// stability.json and stability.md: what the stability study writes.
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "meshes/foundation/atomic_file.hpp"
#include "reports/results_file.hpp"
#include "verification/studies/stability/stability.hpp"
#include "verification/studies/stability/study_models.hpp"

namespace vessel {

using stability_study::fmt;

namespace {

std::string yes_no(const std::optional<bool>& b) {
  if (!b) return "–";
  return *b ? "yes" : "**no**";
}


}  // namespace

std::string stability_json(const StabilityReport& r) {
  nlohmann::json j;
  j["schema"] = "vesselverify.stability";
  j["schema_version"] = 1;
  j["command"] = r.command_line;
  j["quick"] = r.quick;
  j["units"] = {{"time", "s"}, {"length", "m"}, {"angular_frequency", "rad/s"},
                {"damping", "N·s/m"}, {"values", "SI unless the key ends in _mm"}};
  j["steps_per_trial"] = r.trial_steps;
  j["critical_steps"] = nlohmann::json::array();
  for (const auto& row : r.rows) {
    j["critical_steps"].push_back({{"model", row.model},
                                   {"integrator", row.integrator},
                                   {"zeta", row.zeta},
                                   {"point_damping", row.point_damping},
                                   {"level", row.level},
                                   {"nodes", row.nodes},
                                   {"springs", row.springs},
                                   {"h_nominal", row.h_nominal},
                                   {"omega_max", row.omega_max},
                                   {"omega_gershgorin", row.omega_gershgorin},
                                   {"omega_min", row.omega_min},
                                   {"gamma_max", row.gamma_max},
                                   {"predicted_dt", row.predicted_dt},
                                   {"found_dt", row.found_dt},
                                   {"unstable_dt", row.unstable_dt},
                                   {"found_over_predicted", row.found_dt / row.predicted_dt},
                                   {"guaranteed_dt", std::isfinite(row.guaranteed_dt)
                                                         ? nlohmann::json(row.guaranteed_dt)
                                                         : nlohmann::json()},
                                   {"found_over_guaranteed",
                                    std::isfinite(row.guaranteed_dt) && row.guaranteed_dt > 0
                                        ? nlohmann::json(row.found_dt / row.guaranteed_dt)
                                        : nlohmann::json()},
                                   {"trials", row.trials},
                                   {"seconds", row.seconds}});
  }
  j["refinement"] = nlohmann::json::array();
  for (const auto& f : r.fits) {
    j["refinement"].push_back({{"model", f.model},
                               {"integrator", f.integrator},
                               {"zeta", f.zeta},
                               {"levels", f.levels},
                               {"found_exponent", f.exponent},
                               {"predicted_exponent", f.predicted_exponent}});
  }
  j["hard_cases"] = nlohmann::json::array();
  for (const auto& hc : r.hard_cases) {
    nlohmann::json c{{"id", hc.id}, {"title", hc.title}, {"setup", hc.setup},
                     {"seconds", hc.seconds}, {"outcomes", nlohmann::json::array()}};
    for (const auto& oc : hc.outcomes) {
      nlohmann::json v = nlohmann::json::object();
      for (const auto& [k, x] : oc.values) v[k] = std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
      c["outcomes"].push_back({{"model", oc.model},
                               {"finished", oc.finished},
                               {"converged", oc.converged ? nlohmann::json(*oc.converged)
                                                          : nlohmann::json()},
                               {"bounded", oc.bounded ? nlohmann::json(*oc.bounded)
                                                      : nlohmann::json()},
                               {"reported", oc.reported},
                               {"values", v}});
    }
    j["hard_cases"].push_back(c);
  }
  j["total_seconds"] = r.seconds;
  j["hard_cases_at_a_time"] = r.hard_cases_at_a_time;
  // Which timings (rows' and cases' seconds) were read from the outcome cache, and when measured.
  j["timing_provenance"] = {{"items", r.timed_items}, {"cached_measured_at", r.cached_at}};
  return j.dump(2) + "\n";
}

std::string stability_markdown(const StabilityReport& r) {
  std::ostringstream md;
  md << "## Numerical stability\n\n"
     << "How large a time step each explicit integrator of the mass-spring models takes before "
        "it blows up — predicted from the largest eigenvalue of M⁻¹K at rest (Lanczos) and found "
        "by running (bisection on dt, " << r.trial_steps
     << " steps per trial from a small random velocity, unstable when the energy exceeds "
        "1000× its start or turns non-finite) — and what every model does on hard cases. "
        "Produced by `" << r.command_line << "`" << (r.quick ? " (quick mode)" : "")
     << " in " << fmt(r.seconds, 3) << " s.";
  const std::string provenance = reports::timing_provenance_line(r.timed_items, r.cached_at);
  if (!provenance.empty()) {
    md << " Timings (per level and model's rows, per hard case): " << provenance << ".";
  }
  md << "\n\n"
     << "### Predicted vs found stable step\n\n"
     << "Straight tube, unstructured levels; surface models on the inner wall (triangle "
        "topology), E = 14.24 kPa, consistent masses, inlet and outlet fixed. Damped rows: point "
        "damping c = 2ζ·ω_max·(mean nodal mass), seed 000 eq. (3.3). Predicted: symplectic "
        "Euler 4/(γ + √(γ² + 4ω²)), Verlet the root of its amplification matrix's Jury "
        "condition (2/ω undamped), explicit Euler γ/ω² (= 2ζ/ω) or its overdamped lowest-mode "
        "bound, with γ the damping rate of the top (and lowest) mode. Undamped, the prediction "
        "is exact. **Damped, it is an estimate that may be unsafe**: point damping with "
        "non-uniform (consistent) masses does not decouple into modes, γ is only a Rayleigh "
        "quotient, and the found step can be well below it (found / predicted < 1). The "
        "*guaranteed* column is a proven bound instead: every eigenvalue of the damped system "
        "solves λ² + γλ + ω² = 0 for some ω ∈ [ω_min, ω_max] and γ between the extreme "
        "eigenvalues of M⁻¹C (here c/m_max and c/m_min), so the smallest critical step over "
        "that rectangle is safe for explicit and symplectic Euler "
        "(`msm/solvers/critical_step.hpp`; none is proven for damped Verlet). Use it, not the "
        "prediction, as a safe damped step. Steps in µs.\n\n"
     << "| model | integrator | ζ | level | nodes | ω_max (rad/s) | Gershgorin bound | predicted "
        "(µs) | guaranteed (µs) | found stable (µs) | found / predicted | found / guaranteed |\n"
     << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& row : r.rows) {
    md << "| " << row.model << " | " << row.integrator << " | " << fmt(row.zeta) << " | "
       << row.level << " | " << row.nodes << " | " << fmt(row.omega_max, 5) << " | "
       << fmt(row.omega_gershgorin, 5) << " | " << fmt(row.predicted_dt * 1e6, 5) << " | "
       << (std::isfinite(row.guaranteed_dt) ? fmt(row.guaranteed_dt * 1e6, 5) : "–") << " | "
       << fmt(row.found_dt * 1e6, 5) << " | " << fmt(row.found_dt / row.predicted_dt, 4)
       << " | "
       << (std::isfinite(row.guaranteed_dt) && row.guaranteed_dt > 0
               ? fmt(row.found_dt / row.guaranteed_dt, 4)
               : "–")
       << " |\n";
  }
  md << "\nExplicit Euler without damping is not in the table: it is unstable at every step "
        "(|1 + ihω| > 1; the energy grows by a factor 1 + h²ω² per step in each mode), asserted "
        "by the test suite.\n\n"
     << "### Step against refinement\n\n"
     << "Least-squares exponent p of dt ∝ h^p over the levels (h the nominal element size, "
        "halved per level; p = 1 expected for springs whose k scales like E·h and masses like "
        "ρh³).\n\n"
     << "| model | integrator | ζ | levels | p (found) | p (predicted) |\n"
     << "| --- | --- | --- | --- | --- | --- |\n";
  for (const auto& f : r.fits) {
    std::string levels;
    for (int l : f.levels) {
      if (!levels.empty()) levels += ",";
      levels += std::to_string(l);
    }
    md << "| " << f.model << " | " << f.integrator << " | " << fmt(f.zeta) << " | " << levels
       << " | " << fmt(f.exponent, 3) << " | " << fmt(f.predicted_exponent, 3) << " |\n";
  }
  if (!r.hard_cases.empty()) {
    md << "\n### Hard cases\n\n"
       << "Each case lists what every model did: finished (returned a result), converged "
          "(static or linear solve), bounded (dynamic run), and what it reported. Displacements "
          "in mm, loads in mN.";
    if (r.hard_cases_at_a_time > 1) {
      md << " The cases ran " << r.hard_cases_at_a_time
         << " at a time, so the time after each case's set-up is its wall time on a shared "
            "machine; the long run, whose steps are timed, ran alone.";
    }
    md << "\n";
    for (const auto& hc : r.hard_cases) {
      md << "\n#### " << hc.title << "\n\n" << hc.setup << " (" << fmt(hc.seconds, 3) << " s)\n\n"
         << "| model | finished | converged | bounded | reported |\n"
         << "| --- | --- | --- | --- | --- |\n";
      for (const auto& oc : hc.outcomes) {
        std::string rep = oc.reported;
        for (std::size_t p = rep.find('|'); p != std::string::npos; p = rep.find('|', p + 2))
          rep.replace(p, 1, "\\|");
        for (char& ch : rep)
          if (ch == '\n') ch = ' ';
        md << "| " << oc.model << " | " << (oc.finished ? "yes" : "**no**") << " | "
           << yes_no(oc.converged) << " | " << yes_no(oc.bounded) << " | " << rep << " |\n";
      }
    }
  }
  return md.str();
}

void write_stability(const std::filesystem::path& dir, const StabilityReport& report) {
  const std::string json = stability_json(report);
  const std::string md = stability_markdown(report);
  write_file_atomically(dir / "stability.json", [&](std::ostream& out) { out << json; });
  write_file_atomically(dir / "stability.md", [&](std::ostream& out) { out << md; });
}

}  // namespace vessel
