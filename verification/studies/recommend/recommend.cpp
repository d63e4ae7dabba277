#include "verification/studies/recommend/recommend.hpp"

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
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "reports/svg_plot.hpp"
#include "verification/harness/guidewire_contact.hpp"
#include "verification/harness/harness.hpp"
#include "verification/harness/results.hpp"
#include "verification/studies/recommend/pair_candidates.hpp"
#include "verification/studies/recommend/wire_candidates.hpp"

namespace vessel {

using reports::significant;

namespace {

std::string ms(double seconds) { return significant(seconds * 1e3) + " ms"; }

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
/// model (van-gelder springs + volume term, msm/model/mass_spring_model.hpp) and the edge-pair model
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

namespace {

const std::vector<std::pair<ModelKind, std::string>> kKinds{{ModelKind::surface_msm, "surface"},
                                                            {ModelKind::volume_msm, "volume"}};

/// A mass-spring model of `kind` on the mid-surface with `choice`'s rule and terms, consistent
/// masses (the FEM transient's; irrelevant to a static answer); solver and name to be set.
ModelSpec spring_model(ModelKind kind, const SpringChoice& choice) {
  ModelSpec m;
  m.kind = kind;
  m.surface = msm::WallSurface::mid;
  m.stiffness = choice.rule;
  m.volume_term = choice.volume_term;
  m.volume_moduli = choice.volume_moduli;
  m.bending = choice.bending;
  m.edge_pairs = choice.edge_pairs;
  m.mass = msm::MassRule::consistent;
  return m;
}

/// Static scenes: FEM P1, corotational P1 and XPBD FEM, every spring model under the static and
/// linear solvers, and with contact loads the static solver on each region-of-interest radius.
void add_static_candidates(const Scene& s, const std::vector<double>& roi_radii,
                           std::vector<ModelSpec>& out) {
  ModelSpec fem;
  fem.name = "fem_p1";
  fem.kind = ModelKind::fem;
  fem.degree = 1;
  out.push_back(fem);
  // The P1 models simulators pick instead of springs (msm/fem), on P1's mesh: corotational P1 by
  // static Newton, and XPBD FEM at its default step (its time per update: that step's cost × the
  // steps an update period holds; its error: its steady state's).
  ModelSpec corotational;
  corotational.name = "fem/corotational-p1/static";
  corotational.kind = ModelKind::corotational_fem;
  out.push_back(corotational);
  ModelSpec xpbd;
  xpbd.kind = ModelKind::xpbd_fem;
  xpbd.name = "fem/xpbd-neo-hookean/dt=" + significant(xpbd.tet_fem.dt);
  out.push_back(xpbd);
  for (const auto& [kind, kind_name] : kKinds) {
    for (const SpringChoice& choice : spring_rules(kind)) {
      ModelSpec m = spring_model(kind, choice);
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
}

/// The scene's calibrated mass-spring models (`calibration = "file.json"`, vesselverify
/// calibrate), with the same calibration, under both static solvers.
void add_calibrated_candidates(const Scene& s, std::vector<ModelSpec>& out) {
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
}

/// The time steps the scene's integrators use, per family, its longest simulated time and its
/// largest point damping.
struct SceneSteps {
  std::set<double> explicit_dts, implicit_dts, all;
  double duration = 0.0, damping = 0.0;
};

SceneSteps scene_steps(const Scene& s) {
  SceneSteps t;
  for (const ModelSpec& m : s.models) {
    if (!is_integrator(m)) continue;
    (is_explicit(m.solver.integrator) ? t.explicit_dts : t.implicit_dts).insert(m.solver.dt);
    t.duration = std::max(t.duration, m.solver.dt * static_cast<double>(m.solver.steps));
    t.damping = std::max(t.damping, m.damping);
  }
  t.all = t.explicit_dts;
  t.all.insert(t.implicit_dts.begin(), t.implicit_dts.end());
  return t;
}

/// Dynamic scenes: every spring model under every integrator at its family's steps, and the
/// local–global implicit Euler on the plain spring networks.
void add_dynamic_candidates(const Scene& s, std::vector<ModelSpec>& out) {
  const SceneSteps t = scene_steps(s);
  const auto timed = [&](ModelSpec m, double dt, const std::string& name) {
    m.solver.dt = dt;
    m.solver.steps = std::max(1L, std::lround(t.duration / dt));
    m.damping = t.damping;
    m.name = name + "/dt=" + significant(dt);
    out.push_back(m);
  };
  for (const auto& [kind, kind_name] : kKinds) {
    for (const SpringChoice& choice : spring_rules(kind)) {
      for (const msm::Integrator integrator : msm::kAllIntegrators) {
        const std::set<double>& family = is_explicit(integrator) ? t.explicit_dts : t.implicit_dts;
        ModelSpec m = spring_model(kind, choice);
        m.solver.kind = msm::SolverKind::integrator;
        m.solver.integrator = integrator;
        for (const double dt : family.empty() ? t.all : family) {
          timed(m, dt, kind_name + "/" + rule_label(choice) + "/" + msm::to_string(integrator));
        }
      }
      // The real-time solver (Liu et al. 2013), implicit Euler with its default iterations per
      // step, at the implicit family's steps: plain spring networks only (no volume or bending
      // term).
      if (!choice.plain()) continue;
      ModelSpec m = spring_model(kind, choice);
      m.solver = msm::parse_solver("local-global-euler");
      for (const double dt : t.implicit_dts.empty() ? t.all : t.implicit_dts) {
        timed(m, dt, kind_name + "/" + rule_label(choice) + "/local-global-euler");
      }
    }
  }
}

}  // namespace

std::vector<ModelSpec> candidate_models(const Scene& s, const std::vector<double>& roi_radii) {
  std::vector<ModelSpec> out;
  const bool dynamic = std::any_of(s.models.begin(), s.models.end(),
                                   [](const ModelSpec& m) { return m.solver.is_dynamic(); });
  if (dynamic) {
    add_dynamic_candidates(s, out);
  } else {
    add_static_candidates(s, roi_radii, out);
    add_calibrated_candidates(s, out);
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

void judge_by_contact_force(const GuidewireContact& contact, std::vector<Candidate>& candidates) {
  for (Candidate& c : candidates) {
    if (!c.ok) continue;
    const std::optional<double> error = worst_contact_force_error_mN(contact, c.model, c.failure);
    c.ok = error.has_value();
    c.error = error.value_or(NAN);
  }
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
  if (s.budget.quantity == BudgetQuantity::contact_force) {
    if (!rec.result.guidewire_contact) {
      throw std::logic_error("recommend: quantity contact_force without the run's contact solve");
    }
    judge_by_contact_force(*rec.result.guidewire_contact, rec.candidates);
  }
  rec.selection = select_model(rec.candidates, s.budget.tolerance, s.budget.seconds_per_update(),
                               budget_unit(s.budget.quantity));
  if (s.load.guidewire) {
    if (h.log) *h.log << "recommend " << s.name << ": the wire's candidates (DER, CORDE)\n";
    rec.wire = std::make_shared<const WireRecommendation>(recommend_wire(s));
    if (rec.wire->reference) {
      rec.pairs = std::make_shared<const PairCandidates>(
          pair_candidates(rec.wire->candidates, rec.candidates, s.budget));
    }
  }
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
  if (out.wire) {
    auto wire = std::make_shared<WireRecommendation>(*out.wire);
    wire->selection = judge_wire(wire->candidates, b);
    out.wire = wire;
  }
  if (out.pairs) {
    out.pairs = std::make_shared<const PairCandidates>(
        pair_candidates(out.wire->candidates, out.candidates, b));
  }
  return out;
}

void write_recommendation(const Recommendation& rec, const std::filesystem::path& output_dir,
                          const std::string& command) {
  const std::string json = recommendation_json(rec, command, output_dir);
  // The Markdown is the report's section drawn from the document just written.
  const std::string md =
      reports::recommendation_markdown(reports::parse_recommend(json, output_dir / "recommend.json"));
  write_file_atomically(output_dir / "recommend.json", [&](std::ostream& out) { out << json; });
  write_file_atomically(output_dir / "recommend.md", [&](std::ostream& out) { out << md; });
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
    loads.push_back({{"poisson_ratio", ref.poisson_ratio},
                     {"magnitude", ref.budget_magnitude},
                     {"reference_element", ref.element}});
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
                         {"load_unit", s.load.kind == LoadKind::contact    ? "N"
                                       : s.load.kind == LoadKind::pressure ? "Pa"
                                                                           : "g"},
                         {"recommended", name_of(sel.recommended)},
                         {"closest", name_of(sel.closest)},
                         {"whole_vessel", name_of(sel.whole_vessel)},
                         {"candidates", candidates}};
  if (rec.wire) j["wire"] = wire_recommendation_json(*rec.wire);
  if (rec.pairs) {
    j["pairs"] = pair_recommendation_json(*rec.pairs, rec.wire->candidates, rec.candidates);
  }
  if (!rec.results_dir.empty()) {
    // The candidates' results.json, relative to recommend.json's folder.
    j["results"] =
        (rec.results_dir / "results.json").lexically_proximate(output_dir).generic_string();
  }
  return j.dump(2) + "\n";
}

}  // namespace vessel
