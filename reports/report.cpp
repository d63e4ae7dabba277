#include "reports/report.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/mesh_quality.hpp"
#include "reports/best_model.hpp"
#include "reports/guidewire_section.hpp"
#include "reports/insertion_section.hpp"
#include "reports/modal_section.hpp"
#include "reports/representative_load.hpp"
#include "reports/scene_card.hpp"
#include "reports/series_style.hpp"
#include "reports/study_sections.hpp"
#include "reports/svg_plot.hpp"
#include "reports/web_page.hpp"

namespace vessel::reports {

namespace {

std::string file_safe(const std::string& name) {
  std::string out;
  for (const char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

/// A model variant as plotted: its name, plus the level when the scene sweeps levels.
std::string variant(const OutcomeRow& o, const SceneRows& s) {
  return s.model_levels.size() > 1 ? o.model + " (L" + std::to_string(o.level) + ")" : o.model;
}

double first_nu(const SceneRows& s) {
  return s.references.empty() ? (s.outcomes.empty() ? 0.0 : s.outcomes.front().poisson_ratio)
                              : s.references.front().poisson_ratio;
}

int finest_level(const SceneRows& s) {
  return s.model_levels.empty() ? 0 : s.model_levels.back();
}

/// Outcomes selected by a predicate, in file order.
template <class Pred>
std::vector<const OutcomeRow*> select(const SceneRows& s, Pred&& pred) {
  std::vector<const OutcomeRow*> out;
  for (const auto& o : s.outcomes) {
    if (pred(o)) out.push_back(&o);
  }
  return out;
}

/// Model names in order of first appearance.
std::vector<std::string> model_names(const SceneRows& s) {
  std::vector<std::string> names;
  for (const auto& o : s.outcomes) {
    if (std::find(names.begin(), names.end(), o.model) == names.end()) names.push_back(o.model);
  }
  return names;
}

std::string load_text(double magnitude, const SceneRows& s) {
  if (s.load_unit == "N") return significant(magnitude * 1e3) + " mN";
  return significant(magnitude) + " " + s.load_unit;
}

/// A solve time, marked for models outside the suite with whose time it is: the simulator's own
/// (its timing.json) or its whole process's wall time (start-up and file I/O included).
std::string solve_time_text(const OutcomeRow& o) {
  std::string t = significant(o.solve_seconds);
  if (o.timing_source == "simulator") t += " (simulator's own)";
  if (o.timing_source == "process") t += " (process wall time)";
  if (o.timing_source == "none") t += " (not timed)";
  return t;
}

std::string reference_uncertainty_text(const OutcomeRow& o) {
  return o.reference_uncertainty_max_mm ? significant(*o.reference_uncertainty_max_mm) : "–";
}

Series series(std::string label, bool lines, bool markers = true) {
  Series s;
  s.label = std::move(label);
  s.lines = lines;
  s.markers = markers;
  return s;
}

/// The reference (or the Pareto front): a thick black line.
Series black_line(std::string label, std::vector<double> x = {}, std::vector<double> y = {}) {
  Series s = series(std::move(label), true, false);
  s.x = std::move(x);
  s.y = std::move(y);
  s.emphasis = true;
  s.colour = kReferenceColour;
  return s;
}

/// A guide (tolerance, uncertainty, seed 000's line): dashed grey.
Series grey_dashed(std::string label, bool markers = false) {
  Series s = series(std::move(label), true, markers);
  s.dashed = true;
  s.colour = "#888888";
  return s;
}

struct FigureContext {
  Document& doc;
  const SceneRows& scene;
  double magnitude;
  double nu;
  SeriesStyles& styles;

  /// A model's series in its own colour and marker.
  [[nodiscard]] Series model_series(const std::string& model, std::string label, bool lines,
                                    bool markers = true) const {
    Series s = series(std::move(label), lines, markers);
    styles.apply(s, model);
    return s;
  }
};

void speed_error_figure(const FigureContext& c) {
  const auto rows = select(c.scene, [&](const OutcomeRow& o) {
    return o.ok && o.magnitude == c.magnitude;
  });
  if (rows.empty()) return;
  Plot plot;
  plot.title = c.scene.name + ": speed against error at " + load_text(c.magnitude, c.scene);
  plot.x = {"solve time after set-up (s; static and linear: per update)", Scale::log};
  plot.y = {"max nodal error (mm)", Scale::log};
  std::map<std::string, std::size_t> series_of;
  std::vector<double> xs, ys;
  std::vector<std::string> labels;
  for (const OutcomeRow* o : rows) {
    const std::string label = variant(*o, c.scene);
    if (!series_of.count(label)) {
      series_of[label] = plot.series.size();
      plot.series.push_back(c.model_series(o->model, label, false));
    }
    Series& s = plot.series[series_of[label]];
    s.x.push_back(std::max(o->solve_seconds, 1e-6));
    s.y.push_back(o->max_mm);
    s.point_labels.push_back(o->model + ", ν = " + significant(o->poisson_ratio) + ", level " +
                             std::to_string(o->level) + ", load " +
                             load_text(o->magnitude, c.scene));
    s.point_views.push_back(c.scene.name + "|" + o->model + "|" + std::to_string(o->level));
    xs.push_back(std::max(o->solve_seconds, 1e-6));
    ys.push_back(o->max_mm);
    labels.push_back(label + (c.scene.references.size() > 1 ? " ν=" + significant(o->poisson_ratio) : ""));
  }
  const auto front = pareto_front(xs, ys);
  Series pareto = black_line("Pareto front");
  pareto.colour = kParetoColour;
  std::string names;
  for (const std::size_t i : front) {
    pareto.x.push_back(xs[i]);
    pareto.y.push_back(ys[i]);
    names += (names.empty() ? "" : ", ") + labels[i];
  }
  plot.series.push_back(pareto);
  const auto [xmin, xmax] = std::minmax_element(xs.begin(), xs.end());
  Series tolerance = grey_dashed("tolerance " + significant(c.scene.tolerance_mm) + " mm");
  tolerance.x = {*xmin, *xmax};
  tolerance.y = {c.scene.tolerance_mm, c.scene.tolerance_mm};
  plot.series.push_back(tolerance);
  // A simulator's budgets per update: 30 Hz (visual) and 1 kHz (haptic).
  const auto [ymin, ymax] = std::minmax_element(ys.begin(), ys.end());
  for (const auto& [rate, label] : {std::pair{30.0, "30 Hz (visual): 33 ms per update"},
                                    std::pair{1000.0, "1 kHz (haptic): 1 ms per update"}}) {
    Series line = grey_dashed(label);
    line.colour = rate < 100 ? "#b07aa1" : "#9c755f";
    line.x = {1.0 / rate, 1.0 / rate};
    line.y = {std::min(*ymin, c.scene.tolerance_mm) * 0.8, std::max(*ymax, c.scene.tolerance_mm) * 1.25};
    plot.series.push_back(line);
  }
  c.doc.figure(file_safe(c.scene.name) + "_speed_error.svg", plot,
               "Speed against error, " + c.scene.name + ", load " +
                   load_text(c.magnitude, c.scene) +
                   ": one point per model, Poisson's ratio and level. The purple line joins the "
                   "Pareto front (no other point is both faster and more accurate): " + names +
                   ". Dashed: the scene's tolerance, and the time per update at 30 Hz (visual) and 1 kHz "
                   "(haptic).");
}

void error_vs_nu_figure(const FigureContext& c) {
  if (c.scene.references.size() < 2) return;
  Plot plot;
  plot.title = c.scene.name + ": error against Poisson's ratio";
  plot.x = {"Poisson's ratio ν", Scale::linear};
  plot.y = {"relative L2 error", Scale::log};
  for (const auto& name : model_names(c.scene)) {
    Series s = c.model_series(name, name, true);
    for (const OutcomeRow* o : select(c.scene, [&](const OutcomeRow& r) {
           return r.ok && r.model == name && r.magnitude == c.magnitude &&
                  r.level == finest_level(c.scene);
         })) {
      s.x.push_back(o->poisson_ratio);
      s.y.push_back(o->relative_l2);
    }
    plot.series.push_back(s);
  }
  c.doc.figure(file_safe(c.scene.name) + "_error_vs_nu.svg", plot,
               "Relative L2 error of the nodal displacement against ν, load " +
                   load_text(c.magnitude, c.scene) + ", level " +
                   std::to_string(finest_level(c.scene)) +
                   ". Spring networks obey the Cauchy relations (an isotropic one has ν = 1/4 "
                   "whatever is asked), and P1 locks as ν → 0.5: both show here.");
}

void error_vs_level_figure(const FigureContext& c) {
  if (c.scene.model_levels.size() < 2) return;
  Plot plot;
  plot.title = c.scene.name + ": error against mesh level";
  plot.x = {"mesh level (cell size halves per level)", Scale::linear};
  plot.y = {"max nodal error (mm)", Scale::log};
  Series unc = grey_dashed("reference uncertainty (max)", true);
  for (const auto& name : model_names(c.scene)) {
    Series s = c.model_series(name, name, true);
    for (const OutcomeRow* o : select(c.scene, [&](const OutcomeRow& r) {
           return r.ok && r.model == name && r.magnitude == c.magnitude &&
                  r.poisson_ratio == c.nu;
         })) {
      s.x.push_back(o->level);
      s.y.push_back(o->max_mm);
      if (o->reference_uncertainty_max_mm && name == model_names(c.scene).front()) {
        unc.x.push_back(o->level);
        unc.y.push_back(*o->reference_uncertainty_max_mm);
      }
    }
    plot.series.push_back(s);
  }
  if (!unc.x.empty()) plot.series.push_back(unc);
  c.doc.figure(file_safe(c.scene.name) + "_error_vs_level.svg", plot,
               "Convergence: max nodal error against mesh level, ν = " + significant(c.nu) + ", load " +
                   load_text(c.magnitude, c.scene) +
                   ". FEM errors fall with refinement; a mass-spring error that does not fall is "
                   "the model's own, not the mesh's. Grey: the reference's own uncertainty, "
                   "below which no error is resolved.");
}

void load_displacement_figure(const FigureContext& c) {
  Plot plot;
  plot.title = c.scene.name + ": load against QoI displacement";
  plot.x = {"load (" + std::string(c.scene.load_unit == "N" ? "mN" : c.scene.load_unit) + ")",
            Scale::log};
  plot.y = {"displacement at the QoI point (mm)", Scale::log};
  const double unit = c.scene.load_unit == "N" ? 1e3 : 1.0;
  Series reference = black_line("FEM reference");
  std::set<double> magnitudes;
  for (const auto& name : model_names(c.scene)) {
    Series s = c.model_series(name, name, true);
    for (const OutcomeRow* o : select(c.scene, [&](const OutcomeRow& r) {
           return r.ok && r.model == name && r.poisson_ratio == c.nu &&
                  r.level == finest_level(c.scene);
         })) {
      s.x.push_back(o->magnitude * unit);
      s.y.push_back(o->qoi_mm);
      if (magnitudes.insert(o->magnitude).second) {
        reference.x.push_back(o->magnitude * unit);
        reference.y.push_back(o->qoi_reference_mm);
      }
    }
    plot.series.push_back(s);
  }
  if (magnitudes.size() < 2) return;  // one load: nothing to draw a line through
  std::vector<std::size_t> order(reference.x.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return reference.x[a] < reference.x[b]; });
  Series sorted = reference;
  for (std::size_t i = 0; i < order.size(); ++i) {
    sorted.x[i] = reference.x[order[i]];
    sorted.y[i] = reference.y[order[i]];
  }
  plot.series.insert(plot.series.begin(), sorted);
  std::string caption = "Load against the displacement at the QoI point (" + c.scene.name +
                        ", ν = " + significant(c.nu) + ", level " + std::to_string(finest_level(c.scene)) +
                        "). The FEM reference is linear, so it is only valid up to about 5 % strain.";
  if (c.scene.load_unit == "N") {
    Series hooke = grey_dashed("seed 000 Hooke line, F/k, k = 41.106 N/m");
    for (const double m : magnitudes) {
      hooke.x.push_back(m * 1e3);
      hooke.y.push_back(m / kSeed000HookeStiffness * 1e3);
    }
    plot.series.push_back(hooke);
    caption += " Dashed grey: the line seed 000 compared its model against (x = F/k with its "
               "k = E·A/h₀ = 41.106 N/m, eq. 4.2), which is not the vessel's contact stiffness.";
  }
  c.doc.figure(file_safe(c.scene.name) + "_load_displacement.svg", plot, caption);
}

void wall_profile_figure(const FigureContext& c) {
  const auto rows = select(c.scene, [&](const OutcomeRow& r) {
    return r.ok && r.magnitude == c.magnitude && r.poisson_ratio == c.nu &&
           r.level == finest_level(c.scene) && !r.profile_s_mm.empty();
  });
  if (rows.empty()) return;
  Plot plot;
  plot.title = c.scene.name + ": radial displacement along the wall";
  plot.x = {"arc length along the centreline s (mm)", Scale::linear};
  plot.y = {"radial displacement u·e_ρ (mm)", Scale::linear};
  const OutcomeRow* densest = *std::max_element(rows.begin(), rows.end(), [](auto a, auto b) {
    return a->profile_s_mm.size() < b->profile_s_mm.size();
  });
  plot.series.push_back(
      black_line("FEM reference", densest->profile_s_mm, densest->profile_reference_mm));
  std::set<std::string> seen;
  for (const OutcomeRow* o : rows) {
    if (!seen.insert(o->model).second) continue;
    Series m = c.model_series(o->model, o->model, true);
    m.x = o->profile_s_mm;
    m.y = o->profile_model_mm;
    plot.series.push_back(m);
  }
  c.doc.figure(file_safe(c.scene.name) + "_wall_profile.svg", plot,
               "Radial displacement along the wall line through the QoI point (each model's "
               "nodes at its angle around the centreline), load " +
                   load_text(c.magnitude, c.scene) + ", ν = " + significant(c.nu) +
                   ". Where the curves part is where each model's error lives.");
}

void history_figure(const FigureContext& c) {
  const auto rows = select(c.scene, [&](const OutcomeRow& r) {
    return r.ok && !r.history_time_s.empty() && r.poisson_ratio == c.nu &&
           r.level == finest_level(c.scene);
  });
  if (rows.empty()) return;
  Plot plot;
  plot.title = c.scene.name + ": QoI displacement over time";
  plot.x = {"time (s)", Scale::linear};
  plot.y = {"displacement at the QoI point (mm)", Scale::linear};
  bool reference_drawn = false;
  std::string reference_mesh;  // ", P2 on level N" when the results say which
  for (const OutcomeRow* o : rows) {
    if (o->magnitude != rows.front()->magnitude) continue;
    if (!reference_drawn && o->history_reference_mm.size() == o->history_time_s.size()) {
      if (o->history_reference_level) {
        reference_mesh = ", P2 on level " + std::to_string(*o->history_reference_level);
      }
      plot.series.insert(plot.series.begin(),
                         black_line("FEM transient (Newmark)", o->history_time_s,
                                    o->history_reference_mm));
      reference_drawn = true;
    }
    Series m = c.model_series(o->model, o->model, true, false);
    m.x = o->history_time_s;
    m.y = o->history_model_mm;
    plot.series.push_back(m);
  }
  Table t;
  t.header = {"model", "load", "steps", "simulated s", "solve s", "steps/s", "real-time factor",
              "max error over time mm", "final max error mm", "FEM damping α 1/s"};
  for (const OutcomeRow* o : rows) {
    t.rows.push_back({o->model, load_text(o->magnitude, c.scene), std::to_string(o->steps),
                      significant(o->simulated_s), significant(o->solve_seconds),
                      significant(static_cast<double>(o->steps) / o->solve_seconds),
                      significant(o->simulated_s / o->solve_seconds),
                      reference_drawn ? significant(o->history_max_error_mm) : "–", significant(o->max_mm),
                      significant(o->mass_damping_per_s)});
  }
  c.doc.figure(file_safe(c.scene.name) + "_history.svg", plot,
               "The contact force applied as a step at t = 0: displacement of the QoI point over "
               "time for each integrator" +
                   (reference_drawn ? ", against the FEM transient (Newmark, average "
                                      "acceleration" + reference_mesh + ")."
                                    : std::string(" (no FEM transient in these results).")) +
                   " Real-time factor: simulated time over wall-clock time (≥ 1 runs in real "
                   "time). The final error is against the static reference.");
  c.doc.table(t);
}

/// timing_provenance_line over a scene's outcomes.
std::string scene_timing_provenance(const SceneRows& s) {
  std::size_t timed = 0;
  std::vector<std::string> cached_at;
  for (const OutcomeRow& o : s.outcomes) {
    if (o.timing_measured_at.empty()) continue;
    ++timed;
    if (o.timing_cached) cached_at.push_back(o.timing_measured_at);
  }
  return timing_provenance_line(timed, cached_at);
}

Table statistics_table(const SceneRows& s) {
  Table t;
  t.header = {"model", "ν", "level", "load", "max mm", "mean mm", "std mm", "RMS mm", "rel. L2",
              "ref. unc. mm", "QoI model / ref. mm", "max strain", "solve s", "set-up s",
              "memory MiB", "unknowns"};
  for (const auto& o : s.outcomes) {
    std::vector<std::string> row{o.model, significant(o.poisson_ratio), std::to_string(o.level),
                                 load_text(o.magnitude, s) + (o.beyond_linear_regime ? " ⚠" : "")};
    if (!o.ok) {
      row.push_back("**failed**: " + first_sentence(o.failure));
      row.resize(t.header.size());
      row[12] = significant(o.solve_seconds);
      row[13] = significant(o.setup_seconds);
      t.rows.push_back(row);
      continue;
    }
    for (const std::string& v :
         {significant(o.max_mm), significant(o.mean_mm), significant(o.stddev_mm), significant(o.rms_mm), significant(o.relative_l2),
          reference_uncertainty_text(o), significant(o.qoi_mm) + " / " + significant(o.qoi_reference_mm),
          significant(o.max_strain, 2), solve_time_text(o), significant(o.setup_seconds), significant(o.memory_mib, 3),
          std::to_string(o.unknowns)}) {
      row.push_back(v);
    }
    t.rows.push_back(row);
  }
  return t;
}

std::string point_mm(const std::vector<double>& p) {
  return "(" + significant(p[0], 4) + ", " + significant(p[1], 4) + ", " + significant(p[2], 4) +
         ") mm";
}

/// The lumen's ends and the meshes' dihedral angles; a warning where a mesh has slivers, whose
/// error the models' errors there include.
void mesh_paragraph(Document& doc, const SceneRows& s) {
  std::string text;
  if (!s.lumen_ends.empty()) {
    text += "Ends of the lumen:";
    for (const auto& e : s.lumen_ends) {
      text += " " + e.group + " at " + point_mm(e.centre_mm) + ", radius " +
              significant(e.radius_mm, 3) + " mm;";
    }
    text.back() = '.';
  }
  if (!s.mesh_quality.empty()) {
    double lo = 180.0, hi = 0.0;
    for (const auto& m : s.mesh_quality) {
      lo = std::min(lo, m.min_dihedral_deg);
      hi = std::max(hi, m.max_dihedral_deg);
    }
    text += (text.empty() ? "" : " ") + std::string("Dihedral angles of its meshes: ") +
            significant(lo, 3) + "° to " + significant(hi, 4) + "°.";
  }
  for (const auto& m : s.mesh_quality) {
    if (m.sliver_count == 0) continue;
    text += " **The level-" + std::to_string(m.level) + " mesh has " +
            std::to_string(m.sliver_count) + " sliver tets** (a dihedral angle below " +
            significant(kSliverMinDihedralDeg) + "° or above " +
            significant(kSliverMaxDihedralDeg) + "°), the worst at " +
            point_mm(m.worst_centroid_mm) + " (" + significant(m.worst_min_dihedral_deg, 3) +
            "° to " + significant(m.worst_max_dihedral_deg, 4) +
            "°): the models' errors on this mesh include the mesh's.";
  }
  if (!text.empty()) doc.paragraph(text);
}

void scene_section(Document& doc, const SceneRows& s, SeriesStyles& styles) {
  doc.heading(2, "Scene `" + s.name + "`");
  doc.paragraph(s.description + (s.description.empty() ? "" : ". ") + s.vessel + ". Load: " +
                s.load + ". Models at level(s) " + [&] {
                  std::string l;
                  for (const int v : s.model_levels) l += (l.empty() ? "" : ", ") + std::to_string(v);
                  return l;
                }() + "; " + significant(s.seconds, 3) + " s for the whole scene.");
  mesh_paragraph(doc, s);
  Table refs;
  refs.header = {"ν", "reference element", "level", "DoFs", "solve s", "max strain per unit load",
                 "GCI order: linear", "GCI order: finite strain"};
  for (const auto& r : s.references) {
    refs.rows.push_back({significant(r.poisson_ratio), r.element, std::to_string(r.level),
                         std::to_string(r.dofs), significant(r.solve_seconds),
                         significant(r.max_abs_strain_at_unit_load),
                         r.gci_linear.empty() ? "–" : r.gci_linear,
                         r.gci_finite.empty() ? "–" : r.gci_finite});
  }
  doc.table(refs);
  doc.slot("view:" + s.name);
  guidewire_section(doc, s);
  const FigureContext c{doc, s, representative_load(s), first_nu(s), styles};
  speed_error_figure(c);
  error_vs_nu_figure(c);
  error_vs_level_figure(c);
  load_displacement_figure(c);
  wall_profile_figure(c);
  history_figure(c);
  natural_frequency_section(doc, s, styles);
  doc.paragraph("Seed 000's statistics of the nodal displacement error for every model, Poisson's "
                "ratio, level and load (⚠: the reference strains beyond 5 % there). Set-up is "
                "done once (model build; for static and linear mass-spring models also assembly "
                "and factorisation at rest); solve s is the time after it: per update for static "
                "and linear mass-spring models (the median over a load ramp of warm-started "
                "updates ending at the row's load, as a simulator runs them), the run's steps for "
                "integrators, and for FEM the same ramp's median update, prepared as the linear "
                "mass-spring models are (factorised once at set-up):");
  doc.table(statistics_table(s));
  // Each failure's whole message once, folded, below the table that gives its first sentence.
  std::set<std::string> messages;
  for (const OutcomeRow& o : s.outcomes) {
    if (o.ok || !messages.insert(o.model + "\n" + o.failure).second) continue;
    doc.details("Failed: " + o.model + " (level " + std::to_string(o.level) + ", ν = " +
                    significant(o.poisson_ratio) + "): " + first_sentence(o.failure),
                o.failure);
  }
  const std::string provenance = scene_timing_provenance(s);
  if (!provenance.empty()) doc.paragraph("Timings: " + provenance + ".");
}

/// One row per (scene, model, level) at the scene's representative load and first ν.
Table summary_table(const ResultsFile& r) {
  Table t;
  t.header = {"scene", "model", "level", "load", "max mm", "RMS mm", "rel. L2", "ref. unc. mm",
              "within tol.", "solve s", "set-up s", "memory MiB"};
  for (const auto& s : r.scenes) {
    const double mag = representative_load(s);
    const double nu = first_nu(s);
    for (const auto& o : s.outcomes) {
      if (o.magnitude != mag || o.poisson_ratio != nu) continue;
      if (!o.ok) {
        t.rows.push_back({s.name, o.model, std::to_string(o.level), load_text(mag, s),
                          "**failed**", "", "", "", "no", "", significant(o.setup_seconds), ""});
        continue;
      }
      t.rows.push_back({s.name, o.model, std::to_string(o.level),
                        load_text(mag, s) + (o.beyond_linear_regime ? " ⚠" : ""), significant(o.max_mm),
                        significant(o.rms_mm), significant(o.relative_l2), reference_uncertainty_text(o),
                        o.max_mm <= s.tolerance_mm ? "yes" : "no", solve_time_text(o),
                        significant(o.setup_seconds), significant(o.memory_mib, 3)});
    }
  }
  return t;
}

}  // namespace

double representative_load(const SceneRows& s) {
  std::vector<double> magnitudes;
  for (const auto& o : s.outcomes) {
    if (std::find(magnitudes.begin(), magnitudes.end(), o.magnitude) == magnitudes.end()) {
      magnitudes.push_back(o.magnitude);
    }
  }
  // The budget's load is drawn only where the run has it (a --quick run keeps only the smallest
  // and largest load); the file's own value is used, so the outcomes' filters match it exactly.
  std::optional<double> budget;
  if (s.budget_magnitude) {
    for (const double m : magnitudes) {
      if (std::abs(m - *s.budget_magnitude) <= 1e-12 * std::abs(m)) budget = m;
    }
  }
  const double strain_at_unit_load =
      s.references.empty() ? 0.0 : s.references.front().max_abs_strain_at_unit_load;
  return vessel::representative_load(magnitudes, strain_at_unit_load, budget);
}

Document build_report(const ResultsFile& r, const std::optional<StabilityFile>& stability,
                      const std::string& command, const std::vector<RecommendFile>& recommendations,
                      const std::optional<ValidityFile>& validity,
                      const std::optional<InsertionFile>& insertion) {
  Document doc;
  doc.heading(1, "vesselverify report");
  doc.paragraph("How wrong, and how fast, is each mass-spring vessel model against linear-elastic "
                "FEM? Per scene, at its representative load and first Poisson's ratio: the "
                "recommended model (the fastest that meets the scene's [budget], else its max-error "
                "tolerance) and the most accurate mass-spring model on the finest level, with their "
                "max nodal error (× P1: relative L2 error over P1 FEM's), time per update and "
                "verdict; then each model that failed, with the reason.");
  doc.slot("cards");
  doc.table(scene_card_table(scene_cards(r)));
  doc.text_only();
  doc.heading(2, "How these results were made");
  doc.paragraph("Results `" + r.path.filename().string() + "` were produced " + r.date +
                " on `" + r.host + "` (" + std::to_string(r.hardware_threads) +
                " hardware threads), built with " + r.compiler + ", by");
  doc.code(r.command);
  doc.paragraph("This report was generated " + now_utc() + " by");
  doc.code(command);
  doc.paragraph("Errors are the model's nodal displacement minus the FEM reference's (P2, or "
                "Taylor–Hood P2–P1 for ν ≥ 0.49) evaluated at each model node's rest position, in "
                "mm, with seed 000's statistics (max, mean, standard deviation, RMS). *ref. unc.* "
                "is the reference's own estimated error there (Richardson between its two finest "
                "levels, with the order each scene's reference table gives: observed on three "
                "levels, else assumed): an error below it is not resolved. ⚠ marks loads that strain the "
                "reference beyond 5 %, outside linear elasticity's validity. Times are wall-clock "
                "seconds of a Release build (median of the repeats); memory is the peak resident "
                "memory a model's set-up and solve added.");
  doc.heading(2, "Summary");
  doc.paragraph("Each scene at its representative load (the load its [budget] applies at, when "
                "it names one, else the largest within the linear regime) and its first Poisson's "
                "ratio; *within tol.* compares the max error with the "
                "scene's tolerance (seed 000's visual threshold, 0.1 mm, unless the scene says "
                "otherwise).");
  doc.table(summary_table(r));
  best_model_section(doc, r);
  SeriesStyles styles(r);
  for (const auto& s : r.scenes) scene_section(doc, s, styles);
  if (insertion) insertion_section(doc, *insertion);
  for (const auto& recommendation : recommendations) recommendation_section(doc, recommendation);
  if (validity) validity_section(doc, *validity);
  if (stability) {
    stability_section(doc, *stability);
  } else {
    doc.heading(2, "Numerical stability");
    doc.paragraph("Not part of these results: `vesselverify stability` writes `stability.json`, "
                  "which `vesselverify report --stability` draws here.");
  }
  return doc;
}

void attach_run(RecommendFile& recommendation, const ResultsFile& run) {
  for (const SceneRows& scene : run.scenes) {
    if (scene.name != recommendation.scene) continue;
    recommendation.load_unit = scene.load_unit;
    recommendation.timing_provenance = scene_timing_provenance(scene);
    for (BudgetLoadEntry& load : recommendation.loads) {
      for (const ReferenceRow& ref : scene.references) {
        if (ref.poisson_ratio == load.poisson_ratio) load.reference_element = ref.element;
      }
    }
  }
}

void write_report(const ReportOptions& o) {
  const ResultsFile results = read_results(o.results);
  std::optional<StabilityFile> stability;
  if (!o.stability.empty()) stability = read_stability(o.stability);
  std::vector<RecommendFile> recommendations;
  for (const auto& f : o.recommend) {
    RecommendFile r = read_recommend(f);
    if (std::filesystem::exists(r.results)) attach_run(r, read_results(r.results));
    recommendations.push_back(std::move(r));
  }
  std::optional<ValidityFile> validity;
  if (!o.validity.empty()) validity = read_validity(o.validity);
  std::optional<InsertionFile> insertion;
  if (!o.insertion.empty()) insertion = read_insertion(o.insertion);
  const Document doc =
      build_report(results, stability, o.command, recommendations, validity, insertion);
  std::error_code ec;
  std::filesystem::create_directories(o.output_dir / "figures", ec);
  if (ec) {
    throw InputError((o.output_dir / "figures").string() + ": cannot create the output "
                     "directory (" + ec.message() + ")");
  }
  for (const Block& b : doc.blocks()) {
    if (b.kind != Block::Kind::figure) continue;
    write_file_atomically(o.output_dir / "figures" / b.file_name,
                          [&](std::ostream& out) { out << b.svg; });
  }
  write_file_atomically(o.output_dir / "report.md",
                        [&](std::ostream& out) { out << doc.markdown_text("figures"); });
  // report.html: the run's fields (the VTUs results.json names) drawn in 3D per scene.
  std::vector<SceneViews> views;
  for (const SceneRows& s : results.scenes) {
    views.push_back(read_scene_views(s, o.results.parent_path()));
  }
  for (std::size_t i = 0; validity && i < validity->scenes.size(); ++i) {
    const ValiditySceneEntry& s = validity->scenes[i];
    double tolerance_mm = 0.1;  // seed 000's visual threshold, unless the run states the scene's
    for (const SceneRows& r : results.scenes) {
      if (r.name == s.scene) tolerance_mm = r.tolerance_mm;
    }
    views.push_back(validity_scene_views(s, o.validity.parent_path(), tolerance_mm));
  }
  if (insertion) {
    for (SceneViews& v : insertion_views(*insertion)) views.push_back(std::move(v));
  }
  const WebLibraries libraries = load_web_libraries(default_javascript_dir());
  write_file_atomically(o.output_dir / "report.html", [&](std::ostream& out) {
    out << interactive_html(doc, scene_cards(results), views, libraries, "vesselverify report");
  });
}

}  // namespace vessel::reports
