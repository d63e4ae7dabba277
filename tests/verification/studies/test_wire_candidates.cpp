// A guidewire scene's wire candidates in `vesselverify recommend` (wire_candidates.hpp): the
// continuum wire against the shooting values of the issue (F·z²/EI = 0.470968 at L/z = 1.012498;
// the arch's quarter-wave F·R²/EI = 1.0648702), the rod models' errors falling with N, the
// cheapest passing one recommended, and recommend.json's "wire" against its schema and in the
// report's section.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>

#include "../../schema_check.hpp"
#include "../../test_helpers.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/harness/guidewire_contact.hpp"
#include "verification/scene_problems.hpp"
#include "verification/studies/recommend/pair_candidates.hpp"
#include "verification/studies/recommend/recommend.hpp"
#include "verification/studies/recommend/wire_candidates.hpp"

using namespace vessel;

namespace {

// Both scenes' wire: E = 5.073e8 Pa on the solid 0.356 mm section, EI = E π d⁴/64 (≈ 4e-7 N·m²).
const double kEI = 5.073e8 * std::numbers::pi * std::pow(0.356e-3, 4) / 64.0;

Scene scene_with_budget(const std::string& file, double tolerance_mm) {
  Scene s = read_scene(std::string(VESSEL_SCENES_DIR) + "/" + file);
  solve_guidewire_load(s);
  s.budget.stated = true;
  s.budget.quantity = BudgetQuantity::contact_point;
  s.budget.tolerance = tolerance_mm;
  s.budget.rate_hz = 1000.0;
  return s;
}

}  // namespace

TEST(WireCandidates, ContinuumWiresAreTheShootingAndElasticaValues) {
  std::string why;
  const Scene straight = scene_with_budget("guidewire_straight.toml", 0.05);
  const auto s = continuum_wire(straight, why);
  ASSERT_TRUE(s.has_value()) << why;
  // The scene's insertion 20.25 mm is L/z = 1.012498 for z = 20 mm: F = 0.470968 EI/z².
  const double z = 20.25e-3 / 1.012498;
  EXPECT_NEAR(s->force / (0.470968 * kEI / (z * z)), 1.0, 2e-5);
  EXPECT_NEAR(s->contact_point.z(), z, 1e-8);
  EXPECT_NEAR(s->contact_point.x(), 3e-3 - 0.178e-3, 1e-15);  // tilted towards +x
  EXPECT_NEAR(s->contact_point.y(), 0.0, 1e-15);

  const Scene arch = scene_with_budget("guidewire_arch.toml", 0.05);
  const auto a = continuum_wire(arch, why);
  ASSERT_TRUE(a.has_value()) << why;
  const double R = 15e-3;
  EXPECT_NEAR(a->force / (1.0648702 * kEI / (R * R)), 1.0, 1e-7);
  EXPECT_NEAR((a->contact_point - Vec3(0.0, 1.188133 * R, 0.0)).norm(), 0.0, 1e-8);

  // A clamp off the axis has no continuum wire, and says why.
  Scene off = straight;
  off.load.guidewire->clamp_point = Vec3(0.5e-3, 0.0, 0.0);
  EXPECT_FALSE(continuum_wire(off, why).has_value());
  EXPECT_NE(why.find("clamped on the axis"), std::string::npos) << why;
}

TEST(WireCandidates, OnFixedTimingsTheRecommendedWireMeetsTheBudgetAndEveryFasterOneMissesIt) {
  // The candidates' errors from their solves; their times per update fixed (N × a per-model
  // cost, XPBD the cheapest), so which candidates are fast enough does not depend on the machine.
  Scene s = scene_with_budget("guidewire_straight.toml", 1e-3);  // mm on the contact point
  WireRecommendation w = recommend_wire(s, {WireModel::der, WireModel::corde, WireModel::xpbd}, {8, 16, 32});
  ASSERT_TRUE(w.reference.has_value()) << w.no_reference;
  ASSERT_EQ(w.candidates.size(), 9u);
  const double per_segment[3] = {1e-5, 2e-5, 1e-6};  // s: DER, CORDE, XPBD
  const int segments[3] = {8, 16, 32};
  for (std::size_t i = 0; i < 9; ++i) {
    ASSERT_TRUE(w.candidates[i].ok) << w.candidates[i].failure;
    w.candidates[i].update_seconds = segments[i % 3] * per_segment[i / 3];
  }
  // At N = 8 every model misses 1e-3 mm (its contact error is ~1.7e-3 mm; second order in N),
  // at N = 16 every one meets it: XPBD at N = 16 is the cheapest meeting both.
  const Selection sel = judge_wire(w.candidates, s.budget);
  ASSERT_TRUE(sel.recommended.has_value());
  const WireCandidate& best = w.candidates[*sel.recommended];
  EXPECT_EQ(best.name, "wire/xpbd @ N16");
  EXPECT_LE(best.error, s.budget.tolerance);
  EXPECT_LE(best.update_seconds, s.budget.seconds_per_update());
  std::size_t faster = 0;
  for (std::size_t i = 0; i < 9; ++i) {
    if (w.candidates[i].update_seconds >= best.update_seconds) continue;
    ++faster;
    EXPECT_GT(w.candidates[i].error, s.budget.tolerance) << w.candidates[i].name;
    EXPECT_EQ(sel.verdicts[i], Verdict::too_inaccurate) << w.candidates[i].name;
  }
  EXPECT_EQ(faster, 1u);  // XPBD at N = 8: the choice was not simply the fastest

  // A time budget only XPBD at N = 8 meets: nothing meets both, and nothing is recommended.
  s.budget.time_budget_s = 1.2e-5;
  const Selection none = judge_wire(w.candidates, s.budget);
  EXPECT_FALSE(none.recommended.has_value());
  ASSERT_TRUE(none.closest.has_value());
}

TEST(WireCandidates, ErrorsFallWithSegmentsAndTheCheapestPassingOneIsRecommended) {
  const Scene s = scene_with_budget("guidewire_straight.toml", 0.02);
  const WireRecommendation w = recommend_wire(s, {WireModel::der, WireModel::corde, WireModel::xpbd}, {8, 16, 32});
  ASSERT_TRUE(w.reference.has_value()) << w.no_reference;
  ASSERT_EQ(w.candidates.size(), 9u);
  for (const WireCandidate& c : w.candidates) {
    std::printf(
        "WIRE-CANDIDATE %s: F %.6e N, force error %.4e mN, contact error %.4e mm, "
        "update %.3e s, set-up %.3e s%s\n",
        c.name.c_str(), c.force, c.force_error_mN, c.contact_error_mm, c.update_seconds,
        c.setup_seconds, c.ok ? "" : (" FAILED: " + c.failure).c_str());
  }
  for (std::size_t m = 0; m < 3; ++m) {
    const WireCandidate& n8 = w.candidates[3 * m];
    const WireCandidate& n32 = w.candidates[3 * m + 2];
    ASSERT_TRUE(n8.ok && n32.ok) << n8.failure << n32.failure;
    // Second order: four doublings of N cut the force error by about 16 (at least 8 here).
    EXPECT_LT(n32.force_error_mN, n8.force_error_mN / 8.0) << n8.name;
    EXPECT_LT(n32.force_error_mN / (w.reference->force * 1e3), 2e-3) << n32.name;
    EXPECT_EQ(n32.error, n32.contact_error_mm);  // a mm budget judges the contact point
    EXPECT_GT(n32.update_seconds, 0.0);
  }
  // XPBD's steady state is CORDE's energy without the inextensibility constraint (strains ~1e-6
  // under 0.5 mN): the same force as CORDE's Newton solve; its update is one step, not a solve.
  for (std::size_t k = 0; k < 3; ++k) {
    const WireCandidate& corde = w.candidates[3 + k];
    const WireCandidate& xpbd = w.candidates[6 + k];
    EXPECT_NEAR(xpbd.force / corde.force, 1.0, 1e-5) << xpbd.name;
    EXPECT_NE(xpbd.update.find("one XPBD step"), std::string::npos) << xpbd.update;
  }
  // The recommendation: the least time per update among those meeting both (ties within 5 %).
  std::optional<std::size_t> cheapest;
  for (std::size_t i = 0; i < w.candidates.size(); ++i) {
    const WireCandidate& c = w.candidates[i];
    if (!c.ok || c.error > 0.02 || c.update_seconds > 1e-3) continue;
    if (!cheapest || c.update_seconds < w.candidates[*cheapest].update_seconds) cheapest = i;
  }
  if (!cheapest) {
    EXPECT_FALSE(w.selection.recommended.has_value());
  } else {
    ASSERT_TRUE(w.selection.recommended.has_value());
    EXPECT_LE(w.candidates[*w.selection.recommended].update_seconds,
              1.05 * w.candidates[*cheapest].update_seconds);
  }

  // recommend.json's "wire" meets the schema, and the report's section lists every candidate.
  Recommendation rec;
  rec.scene = s;
  rec.wire = std::make_shared<const WireRecommendation>(w);
  const std::string text = recommendation_json(rec, "vesselverify recommend", "out");
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_RECOMMEND_SCHEMA));
  const auto problems = test::schema_problems(nlohmann::json::parse(text), schema);
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  const reports::RecommendFile file = reports::parse_recommend(text, "out/recommend.json");
  ASSERT_TRUE(file.wire.has_value());
  const std::string md = reports::recommendation_markdown(file);
  EXPECT_NE(md.find("### The guidewire's rod model"), std::string::npos) << md;
  for (const WireCandidate& c : w.candidates) {
    EXPECT_NE(md.find("`" + c.name + "`"), std::string::npos) << c.name;
  }
}

namespace {

WireCandidate wire_part(const std::string& name, double error, double seconds, bool ok = true) {
  WireCandidate w;
  w.name = name;
  w.model = "der";
  w.ok = ok;
  w.failure = ok ? "" : "did not converge";
  w.error = error;
  w.update_seconds = seconds;
  w.setup_seconds = 1e-3;
  return w;
}

Candidate vessel_part(const std::string& name, double error, double seconds, bool ok = true) {
  Candidate c;
  c.name = name;
  c.model = name;
  c.ok = ok;
  c.failure = ok ? "" : "diverged";
  c.error = error;
  c.update_seconds = seconds;
  c.setup_seconds = 2e-3;
  return c;
}

}  // namespace

TEST(PairCandidates, APairsErrorAndTimeAreItsPartsSumsAndTheCheapestPairMeetingTheBudgetWins) {
  // Hand-written parts (mm, s): the cheapest wire and the cheapest vessel that each meet 0.05 mm
  // on their own (B, X) miss it together (0.03 + 0.03); the pair meeting it is A + X.
  const std::vector<WireCandidate> wires = {
      wire_part("A", 0.01, 1e-3), wire_part("B", 0.03, 0.1e-3), wire_part("C", 0.0, 0.0, false)};
  const std::vector<Candidate> vessels = {
      vessel_part("X", 0.03, 0.5e-3), vessel_part("Y", 0.01, 2e-3),
      vessel_part("Z", 0.0, 0.0, false), vessel_part("W", NAN, 0.01e-3)};
  Budget b;
  b.stated = true;
  b.quantity = BudgetQuantity::contact_point;
  b.tolerance = 0.05;
  b.time_budget_s = 2e-3;
  const PairCandidates p = pair_candidates(wires, vessels, b);
  ASSERT_EQ(p.pairs.size(), 6u);  // the failed wire C and vessel Z make no pair
  const auto find = [&](const std::string& name) {
    for (std::size_t i = 0; i < p.pairs.size(); ++i) {
      if (p.pairs[i].name == name) return i;
    }
    ADD_FAILURE() << name << " missing";
    return std::size_t{0};
  };
  const Candidate& ax = p.pairs[find("A + X")];
  EXPECT_DOUBLE_EQ(ax.error, 0.04);
  EXPECT_DOUBLE_EQ(ax.update_seconds, 1.5e-3);
  EXPECT_DOUBLE_EQ(ax.setup_seconds, 3e-3);
  ASSERT_TRUE(p.selection.recommended.has_value());
  EXPECT_EQ(p.pairs[*p.selection.recommended].name, "A + X");
  EXPECT_EQ(p.selection.verdicts[find("B + X")], Verdict::too_inaccurate);  // 0.06 mm
  EXPECT_EQ(p.selection.verdicts[find("A + Y")], Verdict::too_slow);        // 3 ms
  EXPECT_EQ(p.selection.verdicts[find("B + Y")], Verdict::too_slow);        // 2.1 ms
  EXPECT_TRUE(std::isnan(p.pairs[find("A + W")].error));  // the vessel's is not computable
  EXPECT_EQ(p.selection.verdicts[find("A + W")], Verdict::failed);

  // The same pairs at 1000 Hz (1 ms per update): none meets both; the whole recommendation is
  // judged again without running anything.
  Recommendation rec;
  rec.scene.name = "pairs";
  rec.scene.budget = b;
  rec.candidates = vessels;
  rec.selection = select_model(vessels, b.tolerance, b.seconds_per_update());
  WireRecommendation w;
  w.candidates = wires;
  w.selection = judge_wire(wires, b);
  rec.wire = std::make_shared<const WireRecommendation>(w);
  rec.pairs = std::make_shared<const PairCandidates>(p);
  const Recommendation at_1000 = rejudged(rec, 1000.0);
  ASSERT_TRUE(at_1000.pairs);
  EXPECT_FALSE(at_1000.pairs->selection.recommended.has_value());
  ASSERT_TRUE(at_1000.pairs->selection.closest.has_value());

  // recommend.json's "pairs" meets the schema and names each pair's parts; the report's section
  // shows the recommended pair.
  const std::string text = recommendation_json(rec, "vesselverify recommend", "out");
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_RECOMMEND_SCHEMA));
  const nlohmann::json doc = nlohmann::json::parse(text);
  const auto problems = test::schema_problems(doc, schema);
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  EXPECT_EQ(doc["pairs"]["recommended"], "A + X");
  EXPECT_EQ(doc["pairs"]["pairs"][0]["wire"], "A");
  EXPECT_EQ(doc["pairs"]["pairs"][0]["vessel"], "X");
  const reports::RecommendFile file = reports::parse_recommend(text, "out/recommend.json");
  ASSERT_TRUE(file.pairs.has_value());
  EXPECT_EQ(file.pairs->pairs.size(), 6u);
  const std::string md = reports::recommendation_markdown(file);
  EXPECT_NE(md.find("### The wire and the vessel together"), std::string::npos) << md;
  EXPECT_NE(md.find("**Recommended: `A + X`**"), std::string::npos) << md;
}

TEST(ContactForceBudget, EachCandidateTakesItsWallsWorstContactForceErrorOverTheEIs) {
  // Two EIs, hand-set forces (N): the reference 1 and 3 mN; wall a 1.2 and 2.5 mN (errors 0.2
  // and 0.5 mN), wall b 0.9 and 3.05 mN (0.1 and 0.05 mN), wall c failed at the first EI.
  const auto wall = [](const std::string& name, double force, const std::string& failure = "") {
    contact::ModelContact m;
    m.name = name;
    m.force = force;
    m.failure = failure;
    return m;
  };
  const auto run = [&](double ei, double reference, double strain, double a, double b) {
    contact::ContactModelsRun r;
    r.bending_stiffness = ei;
    r.reference = wall("reference_fem_p2", reference);
    r.reference.strain = strain;
    r.models = {wall("a", a), wall("b", b), wall("c", reference, ei < 1e-6 ? "diverged" : "")};
    return r;
  };
  GuidewireContact contact;
  contact.solve.runs = {run(4e-7, 1e-3, 0.01, 1.2e-3, 0.9e-3),
                        run(4e-6, 3e-3, 0.05, 2.5e-3, 3.05e-3)};
  const auto candidate = [](const std::string& model, int level) {
    Candidate c;
    c.name = model + " @ L" + std::to_string(level);
    c.model = model;
    c.level = level;
    c.ok = true;
    c.error = NAN;  // the model's own run has no contact force
    return c;
  };
  std::vector<Candidate> cs{candidate("a", 0), candidate("a", 1), candidate("b", 0),
                            candidate("c", 0), candidate("network", 0)};
  judge_by_contact_force(contact, cs);
  EXPECT_TRUE(cs[0].ok);
  EXPECT_NEAR(cs[0].error, 0.5, 1e-12);  // mN
  EXPECT_NEAR(cs[1].error, 0.5, 1e-12);  // the contact solve's own mesh: every level alike
  EXPECT_TRUE(cs[2].ok);
  EXPECT_NEAR(cs[2].error, 0.1, 1e-12);
  EXPECT_FALSE(cs[3].ok);
  EXPECT_NE(cs[3].failure.find("its contact solve failed at EI 4e-07"), std::string::npos)
      << cs[3].failure;
  EXPECT_FALSE(cs[4].ok);
  EXPECT_NE(cs[4].failure.find("no wall"), std::string::npos) << cs[4].failure;

  // A third EI whose linear reference is strained past its validity (0.2 > 0.1) judges no one;
  // the finite-strain reference has no such limit.
  contact.solve.runs.push_back(run(4e-5, 6e-3, 0.2, 6e-3, 6e-3));
  std::vector<Candidate> beyond{candidate("b", 0)};
  judge_by_contact_force(contact, beyond);
  EXPECT_FALSE(beyond[0].ok);
  EXPECT_NE(beyond[0].failure.find("beyond its validity at EI 4e-05"), std::string::npos)
      << beyond[0].failure;
  contact.wall = ContactWall::neo_hookean;
  std::vector<Candidate> none{candidate("b", 0)};
  judge_by_contact_force(GuidewireContact{}, none);  // no EI solved: nothing to judge by
  EXPECT_FALSE(none[0].ok);
  std::vector<Candidate> finite{candidate("b", 0)};
  judge_by_contact_force(contact, finite);
  EXPECT_TRUE(finite[0].ok);
  EXPECT_NEAR(finite[0].error, 0.1, 1e-12);
}
