#include "reports/best_model.hpp"

#include <iomanip>
#include <set>
#include <sstream>
#include <utility>

#include "reports/report.hpp"

namespace vessel::reports {

namespace {

/// P1 FEM: a FEM model whose element (the head of its detail, "P1, direct ...") is P1.
bool is_p1(const OutcomeRow& o) { return o.kind == "fem" && o.detail.rfind("P1", 0) == 0; }

/// The edge-pair model (its topology, at the head of its detail, names the edge pairs;
/// msm/model/build_network.cpp).
bool is_edge_pair(const OutcomeRow& o) {
  return o.kind == "volume_msm" && o.detail.find("tetrahedron-sharing edge pairs") != std::string::npos;
}

/// Whether `o` beats `best` (lower error; ties: faster).
bool better(const OutcomeRow& o, const OutcomeRow* best) {
  return !best || o.relative_l2 < best->relative_l2 ||
         (o.relative_l2 == best->relative_l2 && o.solve_seconds < best->solve_seconds);
}

std::string load_text(double magnitude, const std::string& unit) {
  return unit == "N" ? significant(magnitude * 1e3) + " mN" : significant(magnitude) + " " + unit;
}

}  // namespace

std::vector<BestModelRow> best_model_rows(const ResultsFile& results) {
  std::vector<BestModelRow> rows;
  for (const SceneRows& s : results.scenes) {
    const double load = representative_load(s);
    std::set<std::pair<double, int>> cases;  // (ν, level), ascending
    for (const OutcomeRow& o : s.outcomes) {
      if (o.magnitude == load) cases.emplace(o.poisson_ratio, o.level);
    }
    for (const auto& [nu, level] : cases) {
      BestModelRow row;
      row.scene = s.name;
      row.poisson_ratio = nu;
      row.level = level;
      row.magnitude = load;
      row.load_unit = s.load_unit;
      const OutcomeRow* best = nullptr;
      const OutcomeRow* edge_pair = nullptr;
      const OutcomeRow* p1 = nullptr;
      for (const OutcomeRow& o : s.outcomes) {
        if (o.magnitude != load || o.poisson_ratio != nu || o.level != level || !o.ok) continue;
        if (is_p1(o) && !p1) p1 = &o;
        // The suite's own mass-spring models only: a model outside it (external, displacements)
        // may be anything, so it is not named the best mass-spring model; nor are the P1 tet
        // models (corotational_fem, xpbd_fem), which are FEM.
        if (o.kind == "fem" || o.kind == "external" || o.kind == "displacements" ||
            o.kind == "corotational_fem" || o.kind == "xpbd_fem") {
          continue;
        }
        if (is_edge_pair(o)) {
          if (better(o, edge_pair)) edge_pair = &o;
        } else if (better(o, best)) {
          best = &o;
        }
      }
      if (best) {
        row.best_model = best->model;
        row.best_relative_l2 = best->relative_l2;
        row.best_solve_seconds = best->solve_seconds;
      }
      if (p1) {
        row.p1_model = p1->model;
        row.p1_relative_l2 = p1->relative_l2;
        row.p1_solve_seconds = p1->solve_seconds;
      }
      if (best && p1) {
        if (p1->relative_l2 > 0.0) row.error_ratio = best->relative_l2 / p1->relative_l2;
        if (p1->solve_seconds > 0.0) row.time_ratio = best->solve_seconds / p1->solve_seconds;
      }
      if (edge_pair) row.edge_pair_model = edge_pair->model;
      if (edge_pair && p1) {
        if (p1->relative_l2 > 0.0) {
          row.edge_pair_error_ratio = edge_pair->relative_l2 / p1->relative_l2;
        }
        if (p1->solve_seconds > 0.0) {
          row.edge_pair_time_ratio = edge_pair->solve_seconds / p1->solve_seconds;
        }
      }
      rows.push_back(row);
    }
  }
  return rows;
}

Table best_model_table(const std::vector<BestModelRow>& rows) {
  Table t;
  t.header = {"scene",        "ν",        "level",           "load",
              "best mass-spring model",   "its rel. L2",     "P1 rel. L2",
              "error / P1",   "its solve s", "P1 solve s",   "time / P1",
              "edge pairs: error / P1", "edge pairs: time / P1"};
  for (const BestModelRow& r : rows) {
    const auto ratio = [](const std::optional<double>& v) { return v ? significant(*v) : "–"; };
    t.rows.push_back(
        {r.scene, significant(r.poisson_ratio), std::to_string(r.level), load_text(r.magnitude, r.load_unit),
         r.best_model.empty() ? "none finished" : r.best_model,
         r.best_model.empty() ? "–" : significant(r.best_relative_l2),
         r.p1_model ? significant(r.p1_relative_l2) : "no P1", ratio(r.error_ratio),
         r.best_model.empty() ? "–" : significant(r.best_solve_seconds),
         r.p1_model ? significant(r.p1_solve_seconds) : "–", ratio(r.time_ratio),
         ratio(r.edge_pair_error_ratio), ratio(r.edge_pair_time_ratio)});
  }
  return t;
}

void best_model_section(Document& doc, const ResultsFile& results) {
  const std::vector<BestModelRow> rows = best_model_rows(results);
  if (rows.empty()) return;
  doc.heading(2, "Best mass-spring model against P1");
  doc.paragraph(
      "Per scene, Poisson's ratio and mesh level, at the scene's representative load: the "
      "mass-spring model with the lowest relative L2 error, that error over P1 FEM's on the same "
      "mesh level (*error / P1* ≤ 1: as accurate as P1), and its solve time over P1's (*time / "
      "P1* < 1: faster). A mass-spring model's solve time is its time per update after set-up "
      "(static and linear models: the median warm-started update of the load ramp; integrators: "
      "the run's steps); P1's is its median update of the same ramp, prepared as the linear "
      "mass-spring models are (factorised once at set-up, a contact patch's responses "
      "precomputed). "
      "*no P1*: the scene runs no P1 model, or "
      "P1 failed there (ν = 0.5). *Edge pairs*: the springs of each tet coupled in its "
      "tetrahedron-sharing edge pairs (Kikuuwe et al. 2009), which is P1 FEM's StVK tetrahedron "
      "written on the edges: not a candidate for the best mass-spring model but the bound one "
      "reaches, so its error over P1's shows what a spring network lacks and its time what the "
      "coupling costs.");
  doc.table(best_model_table(rows));
}

}  // namespace vessel::reports
