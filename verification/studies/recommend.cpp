#include "verification/studies/recommend.hpp"

#include "verification/harness/results.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "reports/study_sections.hpp"
#include "reports/svg_plot.hpp"

namespace vessel {

using reports::significant;

namespace {

std::string ms(double seconds) { return significant(seconds * 1e3) + " ms"; }

/// "30 Hz", "1000 Hz" (significant's 3 digits would print 1e+03).
std::string hz(double rate) { return significant(rate, 6) + " Hz"; }

bool is_integrator(const ModelSpec& m) { return m.solver.kind == msm::SolverKind::integrator; }

bool is_explicit(msm::Integrator i) { return i != msm::Integrator::implicit_euler; }

bool meets(const Candidate& c, double tolerance, double budget) {
  return c.ok && std::isfinite(c.error) && c.error <= tolerance && c.update_seconds <= budget;
}

}  // namespace

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::recommended:
      return "recommended";
    case Verdict::meets_budget:
      return "meets the budget, costlier";
    case Verdict::too_slow:
      return "too slow";
    case Verdict::too_inaccurate:
      return "too inaccurate";
    case Verdict::too_slow_and_inaccurate:
      return "too slow and too inaccurate";
    case Verdict::failed:
      return "failed";
  }
  return "?";
}

Selection select_model(const std::vector<Candidate>& c, double tolerance, double budget,
                       const std::string& unit) {
  Selection sel;
  const std::size_t n = c.size();
  sel.verdicts.resize(n);
  sel.reasons.resize(n);
  const auto usable = [&](std::size_t i) { return c[i].ok && std::isfinite(c[i].error); };
  // Cheapest meeting both: least time per update; times within kTimingTie of the least are a tie
  // (wall-clock timings of one run differ by a few per cent), won by the least error, then by
  // the earlier candidate.
  const auto cheapest = [&](const auto& eligible) {
    std::optional<std::size_t> best;
    double fastest = HUGE_VAL;
    for (std::size_t i = 0; i < n; ++i) {
      if (eligible(i) && meets(c[i], tolerance, budget)) {
        fastest = std::min(fastest, c[i].update_seconds);
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!eligible(i) || !meets(c[i], tolerance, budget) ||
          c[i].update_seconds > fastest * (1.0 + kTimingTie)) {
        continue;
      }
      if (!best || c[i].error < c[*best].error) best = i;
    }
    return std::make_pair(best, fastest);
  };
  const auto [recommended, fastest] = cheapest([](std::size_t) { return true; });
  sel.recommended = recommended;
  sel.whole_vessel = cheapest([&](std::size_t i) { return c[i].roi_radius <= 0.0; }).first;
  if (!sel.recommended) {
    // Closest: the least factor by which the budget would have to grow for it to pass.
    double best_factor = HUGE_VAL;
    for (std::size_t i = 0; i < n; ++i) {
      if (!usable(i)) continue;
      const double factor = std::max(c[i].error / tolerance, c[i].update_seconds / budget);
      if (!sel.closest || factor < best_factor ||
          (factor == best_factor && c[i].update_seconds < c[*sel.closest].update_seconds)) {
        sel.closest = i;
        best_factor = factor;
      }
    }
  }
  const std::string tol_text = significant(tolerance) + " " + unit;
  for (std::size_t i = 0; i < n; ++i) {
    if (!c[i].ok) {
      sel.verdicts[i] = Verdict::failed;
      sel.reasons[i] = "failed: " + c[i].failure;
      continue;
    }
    if (!std::isfinite(c[i].error)) {
      sel.verdicts[i] = Verdict::failed;
      sel.reasons[i] =
          "failed: its error on the budget's quantity is not finite (the model does "
          "not move the contact)";
      continue;
    }
    const bool accurate = c[i].error <= tolerance;
    const bool fast = c[i].update_seconds <= budget;
    const std::string err = significant(c[i].error) + " " + unit;
    const std::string time = ms(c[i].update_seconds);
    if (sel.recommended == i) {
      sel.verdicts[i] = Verdict::recommended;
      sel.reasons[i] = "the cheapest that meets both: " + err + " ≤ " + tol_text + ", " + time +
                       " ≤ " + ms(budget) + " per update";
    } else if (accurate && fast) {
      sel.verdicts[i] = Verdict::meets_budget;
      const Candidate& best = c[*sel.recommended];
      const bool tied = c[i].update_seconds <= fastest * (1.0 + kTimingTie);
      sel.reasons[i] =
          "meets both, but " + time + " per update against " + ms(best.update_seconds) +
          (tied ? " (a tie within " + significant(kTimingTie * 100) + " %) with a larger error" : "");
    } else if (!accurate && !fast) {
      sel.verdicts[i] = Verdict::too_slow_and_inaccurate;
      sel.reasons[i] = err + " > " + tol_text + " and " + time + " > " + ms(budget) + " per update";
    } else if (!accurate) {
      sel.verdicts[i] = Verdict::too_inaccurate;
      sel.reasons[i] = err + " > " + tol_text;
    } else {
      sel.verdicts[i] = Verdict::too_slow;
      sel.reasons[i] = time + " > " + ms(budget) + " per update";
    }
    if (sel.closest == i) {
      sel.reasons[i] += "; the closest: the budget would have to grow " +
                        significant(std::max(c[i].error / tolerance, c[i].update_seconds / budget)) + "×";
    }
  }
  std::vector<std::size_t> finished;
  std::vector<double> xs, ys;
  for (std::size_t i = 0; i < n; ++i) {
    if (!usable(i)) continue;
    finished.push_back(i);
    xs.push_back(c[i].update_seconds);
    ys.push_back(c[i].error);
  }
  for (const std::size_t k : reports::pareto_front(xs, ys)) sel.pareto.push_back(finished[k]);
  return sel;
}

namespace {

/// One spring model of a kind: its stiffness rule, and the term it adds to its springs.
struct SpringChoice {
  msm::StiffnessRule rule = msm::StiffnessRule::seed000;
  bool volume_term = false;
  msm::Bending bending = msm::Bending::none;
  msm::VolumeModuli volume_moduli = msm::VolumeModuli::golec;  ///< with volume_term
  bool edge_pairs = false;  ///< the springs coupled in edge pairs (msm/terms/edge_pair_term.hpp)
  [[nodiscard]] bool plain() const {
    return !volume_term && !edge_pairs && bending == msm::Bending::none;
  }
};

/// The spring models of a kind: every stiffness rule; for volume networks also the hybrid volume
/// model (van-gelder springs + volume term, msm/model/model.hpp) and the edge-pair model
/// (P1 on the tets' edges, msm/terms/edge_pair_term.hpp); for surface networks also the Discrete
/// Shells model (van-gelder membrane + hinge energy, msm/terms/bending_term.hpp).
std::vector<SpringChoice> spring_rules(ModelKind kind) {
  std::vector<SpringChoice> out;
  for (const msm::StiffnessRule rule : msm::kAllStiffnessRules) out.push_back({rule});
  if (kind == ModelKind::volume_msm) {
    out.push_back({msm::StiffnessRule::van_gelder, true});
    // The homogenised rule's (E_s, κ) (msm/terms/volume_term_homogenised.hpp).
    out.push_back(
        {msm::StiffnessRule::van_gelder, true, msm::Bending::none, msm::VolumeModuli::homogenised});
    out.push_back({msm::StiffnessRule::seed001, false, msm::Bending::none,
                   msm::VolumeModuli::golec, true});
  }
  if (kind == ModelKind::surface_msm) {
    out.push_back({msm::StiffnessRule::van_gelder, false, msm::Bending::discrete_shells});
  }
  return out;
}

std::string rule_label(const SpringChoice& c) {
  if (c.edge_pairs) return "edge-pairs";
  if (c.volume_term) {
    return c.volume_moduli == msm::VolumeModuli::homogenised ? "hybrid-volume-homogenised"
                                                             : "hybrid-volume";
  }
  if (c.bending != msm::Bending::none) return msm::to_string(c.bending);
  return msm::to_string(c.rule);
}

}  // namespace

std::vector<ModelSpec> candidate_models(const Scene& s, const std::vector<double>& roi_radii) {
  std::vector<ModelSpec> out;
  const bool dynamic = std::any_of(s.models.begin(), s.models.end(),
                                   [](const ModelSpec& m) { return m.solver.is_dynamic(); });
  const std::vector<std::pair<ModelKind, std::string>> kinds{{ModelKind::surface_msm, "surface"},
                                                             {ModelKind::volume_msm, "volume"}};
  if (!dynamic) {
    ModelSpec fem;
    fem.name = "fem_p1";
    fem.kind = ModelKind::fem;
    fem.degree = 1;
    out.push_back(fem);
    for (const auto& [kind, kind_name] : kinds) {
      for (const SpringChoice& choice : spring_rules(kind)) {
        ModelSpec m;
        m.kind = kind;
        m.surface = msm::WallSurface::mid;
        m.stiffness = choice.rule;
        m.volume_term = choice.volume_term;
        m.volume_moduli = choice.volume_moduli;
        m.bending = choice.bending;
        m.edge_pairs = choice.edge_pairs;
        m.mass = msm::MassRule::consistent;  // irrelevant to a static answer
        const std::string rule_name = rule_label(choice);
        for (const std::string solver : {"static", "linear"}) {
          m.solver = msm::parse_solver(solver);
          m.name = kind_name + "/" + rule_name + "/" + solver;
          out.push_back(m);
        }
        if (s.load.kind != LoadKind::contact) continue;
        for (const double r : roi_radii) {
          m.solver = msm::parse_solver("static");
          m.roi_radius = r;
          m.name = kind_name + "/" + rule_name + "/static/R=" + significant(r * 1e3) + "mm";
          out.push_back(m);
        }
      }
    }
    // The scene's calibrated mass-spring models (`calibration = "file.json"`, vesselverify
    // calibrate), with the same calibration, under both static solvers.
    for (const ModelSpec& scene_model : s.models) {
      if (scene_model.kind == ModelKind::fem || scene_model.calibration.empty()) continue;
      ModelSpec m = scene_model;
      m.roi_radius = 0.0;
      for (const std::string solver : {"static", "linear"}) {
        m.solver = msm::parse_solver(solver);
        m.name = std::string(m.kind == ModelKind::volume_msm ? "volume" : "surface") +
                 "/calibrated-" + scene_model.calibration.stem().string() + "/" + solver;
        out.push_back(m);
      }
    }
    return out;
  }
  // Dynamic: the scene's time steps per integrator family, its longest simulated time, its damping.
  std::set<double> explicit_dts, implicit_dts;
  double duration = 0.0;
  double damping = 0.0;
  for (const ModelSpec& m : s.models) {
    if (!is_integrator(m)) continue;
    (is_explicit(m.solver.integrator) ? explicit_dts : implicit_dts).insert(m.solver.dt);
    duration = std::max(duration, m.solver.dt * static_cast<double>(m.solver.steps));
    damping = std::max(damping, m.damping);
  }
  std::set<double> all = explicit_dts;
  all.insert(implicit_dts.begin(), implicit_dts.end());
  for (const auto& [kind, kind_name] : kinds) {
    for (const SpringChoice& choice : spring_rules(kind)) {
      for (const msm::Integrator integrator : msm::kAllIntegrators) {
        const std::set<double>& family = is_explicit(integrator) ? explicit_dts : implicit_dts;
        for (const double dt : family.empty() ? all : family) {
          ModelSpec m;
          m.kind = kind;
          m.surface = msm::WallSurface::mid;
          m.stiffness = choice.rule;
          m.volume_term = choice.volume_term;
          m.volume_moduli = choice.volume_moduli;
          m.bending = choice.bending;
          m.edge_pairs = choice.edge_pairs;
          m.mass = msm::MassRule::consistent;  // the FEM transient's mass
          m.solver.kind = msm::SolverKind::integrator;
          m.solver.integrator = integrator;
          m.solver.dt = dt;
          m.solver.steps = std::max(1L, std::lround(duration / dt));
          m.damping = damping;
          m.name = kind_name + "/" + rule_label(choice) + "/" + msm::to_string(integrator) +
                   "/dt=" + significant(dt);
          out.push_back(m);
        }
      }
      // The real-time solver (Liu et al. 2013), implicit Euler with its default iterations per
      // step, at the implicit family's steps: plain spring networks only (no volume or bending
      // term).
      if (!choice.plain()) continue;
      for (const double dt : implicit_dts.empty() ? all : implicit_dts) {
        ModelSpec m;
        m.kind = kind;
        m.surface = msm::WallSurface::mid;
        m.stiffness = choice.rule;
        m.mass = msm::MassRule::consistent;
        m.solver = msm::parse_solver("local-global-euler");
        m.solver.dt = dt;
        m.solver.steps = std::max(1L, std::lround(duration / dt));
        m.damping = damping;
        m.name = kind_name + "/" + rule_label(choice) + "/local-global-euler/dt=" + significant(dt);
        out.push_back(m);
      }
    }
  }
  return out;
}

std::vector<Candidate> collect_candidates(const SceneResult& r) {
  std::vector<Candidate> out;
  std::map<std::pair<std::string, int>, std::size_t> index;
  for (const ModelOutcome& o : r.outcomes) {
    const auto key = std::make_pair(o.model, o.level);
    auto it = index.find(key);
    if (it == index.end()) {
      Candidate c;
      c.name = o.model + " @ L" + std::to_string(o.level);
      c.model = o.model;
      c.detail = o.detail;
      c.level = o.level;
      c.roi_radius = o.roi_radius;
      c.ok = true;
      it = index.emplace(key, out.size()).first;
      out.push_back(c);
    }
    Candidate& c = out[it->second];
    c.unknowns = std::max(c.unknowns, o.unknowns);
    if (!o.ok) {  // worst case over ν: one failure fails the candidate
      if (c.ok) c.failure = o.failure;
      c.ok = false;
      continue;
    }
    // NaN (not computable) wins over any number: std::max would drop it.
    c.error =
        std::isnan(c.error) || std::isnan(o.budget_error) ? NAN : std::max(c.error, o.budget_error);
    c.update_seconds = std::max(c.update_seconds, o.update_seconds);
    c.setup_seconds = std::max(c.setup_seconds, o.setup_seconds);
  }
  return out;
}

Recommendation recommend(const Scene& scene, const RecommendOptions& o,
                         const std::filesystem::path& output_dir, const std::string& command) {
  if (!scene.budget.stated || scene.budget.seconds_per_update() <= 0.0) {
    throw InputError(scene.source.string() +
                     ": recommend needs a budget: expected a [budget] table with rate_hz or "
                     "time_budget_s, or --rate / --time-budget");
  }
  Recommendation rec;
  rec.scene = scene;
  Scene& s = rec.scene;
  s.modes.count = 0;  // the budget asks for accuracy and speed: no natural frequencies ([modes])
  if (o.quick) {
    const std::vector<double> magnitudes = s.load.magnitudes;
    s = quick_variant(std::move(s));
    s.load.magnitudes = magnitudes;  // the budget picks its own load
  }
  s.model_levels =
      o.levels.empty() ? (o.quick ? std::vector<int>{0} : std::vector<int>{0, 1}) : o.levels;
  std::sort(s.model_levels.begin(), s.model_levels.end());
  s.vessel.level = s.model_levels.front();
  if (o.reference_level >= 0) s.reference_level = o.reference_level;
  s.reference_level = std::max(s.reference_level, s.model_levels.back());
  std::vector<double> radii = o.roi_radii;
  if (radii.empty()) {
    radii =
        o.quick ? std::vector<double>{4e-3, 8e-3} : std::vector<double>{2e-3, 4e-3, 8e-3, 16e-3};
  }
  s.models = candidate_models(s, radii);
  HarnessOptions h = o.harness;
  h.budget_load_only = true;
  if (h.log) {
    *h.log << "recommend " << s.name << ": " << s.models.size() << " candidate models at level(s)";
    for (const int l : s.model_levels) *h.log << " " << l;
    *h.log << ", reference level " << s.reference_level << "\n";
  }
  rec.result = run_and_write({s}, h, output_dir, command).front();
  rec.results_dir = output_dir;
  rec.candidates = collect_candidates(rec.result);
  rec.selection = select_model(rec.candidates, s.budget.tolerance, s.budget.seconds_per_update(),
                               budget_unit(s.budget.quantity));
  write_recommendation(rec, output_dir, command);
  return rec;
}

bool rate_independent(const Recommendation& rec) {
  return std::none_of(rec.scene.models.begin(), rec.scene.models.end(),
                      [](const ModelSpec& m) { return is_integrator(m); });
}

Recommendation rejudged(const Recommendation& rec, double rate_hz) {
  if (!rate_independent(rec)) {
    throw std::logic_error("rejudged: " + rec.scene.name +
                           " has integrator candidates, whose time per update depends on the rate");
  }
  Recommendation out = rec;
  out.scene.budget.rate_hz = rate_hz;
  out.scene.budget.time_budget_s = 0.0;
  const Budget& b = out.scene.budget;
  out.selection =
      select_model(out.candidates, b.tolerance, b.seconds_per_update(), budget_unit(b.quantity));
  return out;
}

void write_recommendation(const Recommendation& rec, const std::filesystem::path& output_dir,
                          const std::string& command) {
  write_file_atomically(output_dir / "recommend.md",
                        [&](std::ostream& out) { out << recommendation_markdown(rec, command); });
  write_file_atomically(output_dir / "recommend.json",
                        [&](std::ostream& out) { out << recommendation_json(rec, command, output_dir); });
}

namespace {

std::string budget_text(const Scene& s, const SceneResult& r) {
  const Budget& b = s.budget;
  std::ostringstream t;
  t << "the " << to_string(b.quantity);
  if (b.quantity == BudgetQuantity::patch) t << " (within " << significant(b.radius * 1e3) << " mm)";
  t << " error ≤ " << significant(b.tolerance) << " " << budget_unit(b.quantity) << ", and ≤ "
    << ms(b.seconds_per_update()) << " of computation per update";
  if (b.rate_hz > 0.0) t << " (" << hz(b.rate_hz) << ")";
  const char* unit =
      s.load.kind == LoadKind::contact ? "N" : (s.load.kind == LoadKind::pressure ? "Pa" : "g");
  for (const ReferenceInfo& ref : r.references) {
    t << "; at ν = " << ref.poisson_ratio << " the load is ";
    if (s.load.kind == LoadKind::contact) {
      t << significant(ref.budget_magnitude * 1e3) << " mN";
    } else {
      t << significant(ref.budget_magnitude) << " " << unit;
    }
    t << " (reference " << ref.element << ", level " << ref.level << ")";
  }
  return t.str();
}

}  // namespace

std::string recommendation_markdown(const Recommendation& rec, const std::string& command) {
  const Scene& s = rec.scene;
  const Selection& sel = rec.selection;
  const auto& c = rec.candidates;
  const char* unit = budget_unit(s.budget.quantity);
  std::ostringstream md;
  md << "## Model recommendation: " << s.name;
  // Headings differ per rate, so one report can embed the visual and the haptic answers.
  if (s.budget.rate_hz > 0.0)
    md << " at " << hz(s.budget.rate_hz);
  else
    md << ", " << ms(s.budget.time_budget_s) << " per update";
  md << "\n\n";
  md << "Budget: " << budget_text(s, rec.result) << ". " << c.size()
     << " candidates (generated from the mass-spring library's stiffness rules and solvers, "
        "surface and volume, mesh levels";
  for (const int l : s.model_levels) md << " " << l;
  md << ", regions of interest; FEM P1 for comparison) were run against the FEM reference by\n\n"
     << "    " << command << "\n\n";
  if (sel.recommended) {
    const Candidate& best = c[*sel.recommended];
    md << "**Recommended: `" << best.name << "`** (" << best.detail << "): error "
       << significant(best.error) << " " << unit << ", " << ms(best.update_seconds) << " per update ("
       << ms(best.setup_seconds) << " set-up, once), " << best.unknowns << " unknowns"
       << (best.roi_radius > 0.0 ? "" : ", the whole vessel") << ".\n\n";
  } else if (sel.closest) {
    const Candidate& near = c[*sel.closest];
    md << "**No candidate meets the budget.** The closest is `" << near.name << "` (" << near.detail
       << "): error " << significant(near.error) << " " << unit << ", " << ms(near.update_seconds)
       << " per update; " << sel.reasons[*sel.closest] << ".\n\n";
  } else {
    md << "**No candidate meets the budget**, and none finished.\n\n";
  }
  if (sel.whole_vessel && sel.whole_vessel != sel.recommended) {
    const Candidate& w = c[*sel.whole_vessel];
    md << "Whole vessel (no region of interest): `" << w.name << "` (" << w.detail << ") meets "
       << "the budget too: error " << significant(w.error) << " " << unit << ", "
       << ms(w.update_seconds) << " per update, " << w.unknowns << " unknowns.\n\n";
  } else if (!sel.whole_vessel) {
    md << "No whole-vessel candidate (without a region of interest) meets the budget.\n\n";
  }
  // A tolerance at or above the reference's own contact displacement is met by a model that does
  // not move at all: say so, the answer then says nothing about accuracy.
  double reference_qoi_mm = 0.0;
  for (const ModelOutcome& o : rec.result.outcomes) {
    if (o.ok) reference_qoi_mm = std::max(reference_qoi_mm, o.qoi_reference_mm);
  }
  if (s.budget.quantity != BudgetQuantity::reaction && reference_qoi_mm > 0.0 &&
      s.budget.tolerance >= reference_qoi_mm) {
    md << "⚠ **The tolerance does not discriminate**: at this load the reference's contact point "
          "moves "
       << significant(reference_qoi_mm) << " mm, no more than the " << significant(s.budget.tolerance)
       << " mm tolerance, so a model that does not move at all would meet it. State a tighter "
          "tolerance or a larger load (`magnitude`) for an answer about accuracy.\n\n";
  }
  md << reports::kTimePerUpdateText
     << " Errors are the worst over the scene's Poisson's ratios, against the P2 reference at "
        "each model node; region-of-interest models (R) hold every node farther than R from the "
        "contact and are compared on the whole vessel. ★ marks the Pareto front (no other "
        "candidate is both faster and more accurate).\n\n";
  md << "| candidate | unknowns | error (" << unit
     << ") | time per update (ms) | set-up (ms) | Pareto | verdict | "
        "why |\n|---|---|---|---|---|---|---|---|\n";
  // Winners first, then by time per update; failures last.
  std::vector<std::size_t> order(c.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto rank = [&](std::size_t i) {
      return static_cast<int>(sel.verdicts[i]) > 1 ? 2 : static_cast<int>(sel.verdicts[i]);
    };
    const bool fa = sel.verdicts[a] == Verdict::failed, fb = sel.verdicts[b] == Verdict::failed;
    if (fa != fb) return fb;
    if (rank(a) != rank(b)) return rank(a) < rank(b);
    return c[a].update_seconds < c[b].update_seconds;
  });
  for (const std::size_t i : order) {
    const bool front = std::find(sel.pareto.begin(), sel.pareto.end(), i) != sel.pareto.end();
    md << "| `" << c[i].name << "` | " << c[i].unknowns << " | "
       << (c[i].ok && std::isfinite(c[i].error) ? significant(c[i].error) : "–") << " | "
       << (c[i].ok ? significant(c[i].update_seconds * 1e3) : "–") << " | "
       << (c[i].ok ? significant(c[i].setup_seconds * 1e3) : "–") << " | " << (front ? "★" : "") << " | "
       << to_string(sel.verdicts[i]) << " | " << sel.reasons[i] << " |\n";
  }
  md << "\n";
  return md.str();
}

std::string recommendation_json(const Recommendation& rec, const std::string& command,
                                const std::filesystem::path& output_dir) {
  const Scene& s = rec.scene;
  const Selection& sel = rec.selection;
  nlohmann::json candidates = nlohmann::json::array();
  for (std::size_t i = 0; i < rec.candidates.size(); ++i) {
    const Candidate& c = rec.candidates[i];
    nlohmann::json j{
        {"name", c.name},
        {"model", c.model},
        {"detail", c.detail},
        {"level", c.level},
        {"unknowns", c.unknowns},
        {"ok", c.ok},
        {"pareto", std::find(sel.pareto.begin(), sel.pareto.end(), i) != sel.pareto.end()},
        {"verdict", to_string(sel.verdicts[i])},
        {"reason", sel.reasons[i]}};
    if (c.roi_radius > 0.0) j["roi_radius_mm"] = c.roi_radius * 1e3;
    if (c.ok) {
      j["error"] = std::isfinite(c.error) ? nlohmann::json(c.error) : nlohmann::json(nullptr);
      j["update_seconds"] = c.update_seconds;
      j["setup_seconds"] = c.setup_seconds;
    } else {
      j["failure"] = c.failure;
    }
    candidates.push_back(j);
  }
  const auto name_of = [&](const std::optional<std::size_t>& i) {
    return i ? nlohmann::json(rec.candidates[*i].name) : nlohmann::json(nullptr);
  };
  nlohmann::json budget{{"quantity", to_string(s.budget.quantity)},
                        {"unit", budget_unit(s.budget.quantity)},
                        {"tolerance", s.budget.tolerance},
                        {"seconds_per_update", s.budget.seconds_per_update()},
                        {"update_period_s", s.budget.update_period()}};
  if (s.budget.rate_hz > 0.0) budget["rate_hz"] = s.budget.rate_hz;
  if (s.budget.quantity == BudgetQuantity::patch) budget["radius_mm"] = s.budget.radius * 1e3;
  nlohmann::json loads = nlohmann::json::array();
  for (const ReferenceInfo& ref : rec.result.references) {
    loads.push_back({{"poisson_ratio", ref.poisson_ratio}, {"magnitude", ref.budget_magnitude}});
  }
  double reference_qoi_mm = 0.0;
  for (const ModelOutcome& o : rec.result.outcomes) {
    if (o.ok) reference_qoi_mm = std::max(reference_qoi_mm, o.qoi_reference_mm);
  }
  nlohmann::json j{{"schema", "vesselverify.recommend"},
                         {"reference_contact_point_mm", reference_qoi_mm},
                         {"schema_version", 1},
                         {"command", command},
                         {"scene", s.name},
                         {"source", s.source.string()},
                         {"model_levels", s.model_levels},
                         {"reference_level", s.reference_level},
                         {"budget", budget},
                         {"loads", loads},
                         {"recommended", name_of(sel.recommended)},
                         {"closest", name_of(sel.closest)},
                         {"whole_vessel", name_of(sel.whole_vessel)},
                         {"candidates", candidates}};
  if (!rec.results_dir.empty()) {
    // The candidates' results.json, relative to recommend.json's folder.
    j["results"] =
        (rec.results_dir / "results.json").lexically_proximate(output_dir).generic_string();
  }
  return j.dump(2) + "\n";
}

}  // namespace vessel
