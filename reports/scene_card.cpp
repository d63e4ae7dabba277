#include "reports/scene_card.hpp"

#include <algorithm>

#include "reports/best_model.hpp"
#include "reports/report.hpp"

namespace vessel::reports {

namespace {

double time_per_update(const OutcomeRow& o) {
  return o.update_seconds ? *o.update_seconds : o.solve_seconds;
}

std::string load_text(double magnitude, const std::string& unit) {
  return unit == "N" ? significant(magnitude * 1e3) + " mN" : significant(magnitude) + " " + unit;
}

/// P1 FEM on the same level, ν and load (best_model.cpp's is_p1), or nullptr.
const OutcomeRow* p1_beside(const SceneRows& s, const OutcomeRow& o) {
  for (const OutcomeRow& p : s.outcomes) {
    if (p.ok && p.kind == "fem" && p.detail.rfind("P1", 0) == 0 && p.level == o.level &&
        p.poisson_ratio == o.poisson_ratio && p.magnitude == o.magnitude) {
      return &p;
    }
  }
  return nullptr;
}

CardModel card_model(const SceneRows& s, const OutcomeRow& o) {
  CardModel m;
  m.outcome = o;
  m.passes = passes(s, o);
  m.update_seconds = time_per_update(o);
  if (const OutcomeRow* p1 = p1_beside(s, o); p1 && p1->relative_l2 > 0.0) {
    m.ratio_to_p1 = o.relative_l2 / p1->relative_l2;
  }
  return m;
}

std::string model_text(const std::optional<CardModel>& m) {
  if (!m) return "none";
  return m->outcome.model + " (L" + std::to_string(m->outcome.level) + ")";
}

std::string error_text(const std::optional<CardModel>& m) {
  if (!m) return "–";
  std::string t = significant(m->outcome.max_mm) + " mm";
  if (m->ratio_to_p1) t += ", " + significant(*m->ratio_to_p1) + "× P1";
  return t;
}

}  // namespace

bool passes(const SceneRows& s, const OutcomeRow& o) {
  if (!o.ok) return false;
  if (s.budget) {
    return o.budget_error && *o.budget_error <= s.budget->tolerance &&
           time_per_update(o) <= s.budget->seconds_per_update;
  }
  return o.max_mm <= s.tolerance_mm;
}

std::string first_sentence(const std::string& message) {
  std::size_t end = message.size();
  for (const char* stop : {". ", "; ", "\n"}) end = std::min(end, message.find(stop));
  std::string out = message.substr(0, end);
  if (out.size() > 140) {
    out = out.substr(0, 139);
    // Do not cut a UTF-8 sequence in two.
    while (!out.empty() && (static_cast<unsigned char>(out.back()) & 0xC0) == 0x80) out.pop_back();
    if (!out.empty() && (static_cast<unsigned char>(out.back()) & 0x80)) out.pop_back();
    return out + "…";
  }
  return out;
}

std::vector<SceneCard> scene_cards(const ResultsFile& results) {
  const std::vector<BestModelRow> best_rows = best_model_rows(results);
  std::vector<SceneCard> cards;
  for (const SceneRows& s : results.scenes) {
    SceneCard c;
    c.scene = s.name;
    c.description = s.description;
    c.vessel = s.vessel;
    c.load = s.load;
    c.magnitude = representative_load(s);
    c.poisson_ratio = s.references.empty()
                          ? (s.outcomes.empty() ? 0.0 : s.outcomes.front().poisson_ratio)
                          : s.references.front().poisson_ratio;
    c.load_text = load_text(c.magnitude, s.load_unit);
    c.tolerance_mm = s.tolerance_mm;
    c.budget = s.budget;
    const int finest = s.model_levels.empty() ? 0 : s.model_levels.back();
    std::string best_name;
    for (const BestModelRow& r : best_rows) {
      if (r.scene == s.name && r.poisson_ratio == c.poisson_ratio && r.level == finest) {
        best_name = r.best_model;
      }
    }
    for (const OutcomeRow& o : s.outcomes) {
      if (o.magnitude != c.magnitude || o.poisson_ratio != c.poisson_ratio) continue;
      if (!o.ok) {
        const bool seen = std::any_of(c.failures.begin(), c.failures.end(), [&](const auto& f) {
          return f.model == o.model && f.level == o.level;
        });
        if (!seen) c.failures.push_back({o.model, o.level, first_sentence(o.failure), o.failure});
        continue;
      }
      if (o.model == best_name && o.level == finest) c.best_spring = card_model(s, o);
      if (passes(s, o) && (!c.recommended || time_per_update(o) < c.recommended->update_seconds)) {
        c.recommended = card_model(s, o);
      }
    }
    cards.push_back(std::move(c));
  }
  return cards;
}

Table scene_card_table(const std::vector<SceneCard>& cards) {
  Table t;
  t.header = {"scene", "load", "recommended model", "its max error", "its time per update s",
              "best mass-spring model", "its max error", "its time per update s", "passes",
              "failed models"};
  for (const SceneCard& c : cards) {
    std::string failed;
    for (const CardFailure& f : c.failures) failed += (failed.empty() ? "" : ", ") + f.model;
    const auto time = [](const std::optional<CardModel>& m) {
      return m ? significant(m->update_seconds) : std::string("–");
    };
    t.rows.push_back({c.scene, c.load_text, model_text(c.recommended), error_text(c.recommended),
                      time(c.recommended), model_text(c.best_spring), error_text(c.best_spring),
                      time(c.best_spring),
                      c.best_spring ? (c.best_spring->passes ? "yes" : "no") : "–",
                      failed.empty() ? "none" : failed});
  }
  return t;
}

}  // namespace vessel::reports
