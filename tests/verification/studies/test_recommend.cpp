// Model recommendation against hand-made candidate tables (cheapest meeting both; none meets →
// the closest named; ties), the budget quantities against hand-computed values, time per update,
// the budget's load, and the generated candidate list.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "msm/solvers/integrators.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "verification/harness/budget.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/studies/recommend/recommend.hpp"

using namespace vessel;

namespace {

Candidate candidate(const std::string& name, double error, double seconds, bool ok = true) {
  Candidate c;
  c.name = name;
  c.ok = ok;
  c.error = error;
  c.update_seconds = seconds;
  if (!ok) c.failure = "diverged at step 3";
  return c;
}

}  // namespace

TEST(Selection, TheCheapestMeetingBothWinsAndEveryOtherSaysWhy) {
  // Tolerance 0.1 mm, 10 ms per update.
  const std::vector<Candidate> c{
      candidate("accurate_slow", 0.01, 0.050),  // too slow
      candidate("fast_wrong", 0.50, 0.001),     // too inaccurate
      candidate("good", 0.08, 0.004),           // meets both, cheapest of those
      candidate("good_costlier", 0.02, 0.008),  // meets both, costs more
      candidate("bad_both", 0.3, 0.02),         // both
      candidate("broken", 0.0, 0.0, false),     // failed
  };
  const Selection s = select_model(c, 0.1, 0.010);
  ASSERT_TRUE(s.recommended.has_value());
  EXPECT_EQ(*s.recommended, 2u);
  EXPECT_FALSE(s.closest.has_value());
  EXPECT_EQ(s.verdicts[0], Verdict::too_slow);
  EXPECT_EQ(s.verdicts[1], Verdict::too_inaccurate);
  EXPECT_EQ(s.verdicts[2], Verdict::recommended);
  EXPECT_EQ(s.verdicts[3], Verdict::meets_budget);
  EXPECT_EQ(s.verdicts[4], Verdict::too_slow_and_inaccurate);
  EXPECT_EQ(s.verdicts[5], Verdict::failed);
  EXPECT_NE(s.reasons[0].find("50 ms > 10 ms"), std::string::npos) << s.reasons[0];
  EXPECT_NE(s.reasons[1].find("0.5 mm > 0.1 mm"), std::string::npos) << s.reasons[1];
  EXPECT_NE(s.reasons[3].find("8 ms per update against 4 ms"), std::string::npos) << s.reasons[3];
  EXPECT_NE(s.reasons[5].find("diverged at step 3"), std::string::npos) << s.reasons[5];
  // Pareto front (time, error) among finished candidates: fast_wrong, good, good_costlier,
  // accurate_slow; bad_both is dominated by good.
  EXPECT_EQ(std::set<std::size_t>(s.pareto.begin(), s.pareto.end()),
            (std::set<std::size_t>{0, 1, 2, 3}));
}

TEST(Selection, TheCheapestWholeVesselCandidateIsNamedBesideARegionOfInterest) {
  // Tolerance 0.1 mm, 1 ms: a region-of-interest model wins; the whole-vessel one meeting both
  // is named apart; a whole-vessel one too slow or too inaccurate is not.
  std::vector<Candidate> c{candidate("roi", 0.05, 0.0002), candidate("whole_slow", 0.01, 0.002),
                           candidate("whole_ok", 0.08, 0.0005),
                           candidate("whole_wrong", 0.2, 0.0001)};
  c[0].roi_radius = 4e-3;
  Selection s = select_model(c, 0.1, 0.001);
  ASSERT_TRUE(s.recommended && s.whole_vessel);
  EXPECT_EQ(*s.recommended, 0u);
  EXPECT_EQ(*s.whole_vessel, 2u);
  // None of the whole-vessel candidates meets both: none named.
  c[2].error = 0.15;
  s = select_model(c, 0.1, 0.001);
  EXPECT_EQ(*s.recommended, 0u);
  EXPECT_FALSE(s.whole_vessel.has_value());
}

TEST(Selection, ExactlyOnTheBudgetMeetsIt) {
  const Selection s = select_model({candidate("edge", 0.1, 0.01)}, 0.1, 0.01);
  ASSERT_TRUE(s.recommended.has_value());
  EXPECT_EQ(*s.recommended, 0u);
}

TEST(Selection, NoneMeetsTheBudgetNamesTheClosest) {
  // Tolerance 0.1 mm, 1 ms. Factors max(e/tol, t/budget): a 3, b 1.5 (time), c 2 (error).
  const std::vector<Candidate> c{candidate("a", 0.3, 0.0005), candidate("b", 0.05, 0.0015),
                                 candidate("c", 0.2, 0.0002), candidate("x", 0.0, 0.0, false)};
  const Selection s = select_model(c, 0.1, 0.001);
  EXPECT_FALSE(s.recommended.has_value());
  ASSERT_TRUE(s.closest.has_value());
  EXPECT_EQ(*s.closest, 1u);
  EXPECT_NE(s.reasons[1].find("the closest: the budget would have to grow 1.5×"), std::string::npos)
      << s.reasons[1];
  EXPECT_EQ(s.verdicts[1], Verdict::too_slow);
}

TEST(Selection, TiesGoToTheSmallerErrorThenTheEarlierCandidate) {
  const Selection by_error =
      select_model({candidate("first", 0.05, 0.002), candidate("second", 0.01, 0.002)}, 0.1, 0.01);
  EXPECT_EQ(*by_error.recommended, 1u);
  EXPECT_NE(by_error.reasons[0].find("larger error"), std::string::npos) << by_error.reasons[0];
  const Selection exact =
      select_model({candidate("first", 0.05, 0.002), candidate("second", 0.05, 0.002)}, 0.1, 0.01);
  EXPECT_EQ(*exact.recommended, 0u);
  // Times within 5 % of the fastest are a tie; beyond, the faster wins whatever its error.
  const Selection near = select_model(
      {candidate("fastest", 0.08, 0.00200), candidate("within", 0.01, 0.00209)}, 0.1, 0.01);
  EXPECT_EQ(*near.recommended, 1u);
  const Selection apart = select_model(
      {candidate("fastest", 0.08, 0.00200), candidate("beyond", 0.01, 0.00211)}, 0.1, 0.01);
  EXPECT_EQ(*apart.recommended, 0u);
  // Closest ties (same factor) go to the faster.
  const Selection closest =
      select_model({candidate("slow", 0.2, 0.0019), candidate("fast", 0.2, 0.0001)}, 0.1, 0.001);
  EXPECT_EQ(*closest.closest, 1u);
}

TEST(Selection, NothingFinishedNamesNothing) {
  const Selection s =
      select_model({candidate("x", 0, 0, false), candidate("nan", NAN, 0.001)}, 0.1, 0.01);
  EXPECT_FALSE(s.recommended.has_value());
  EXPECT_FALSE(s.closest.has_value());
  EXPECT_EQ(s.verdicts[1], Verdict::failed);
  EXPECT_TRUE(s.pareto.empty());
}

TEST(TimePerUpdate, StaticSolvesAndIntegratorSteps) {
  // Static: solve_seconds is already the time per update (the ramp's median), whatever the rate.
  EXPECT_EQ(time_per_update(0.02, 0, 0.0, 1.0 / 30.0), std::make_pair(0.02, 0L));
  // 20 000 steps of 1e-5 s in 2 s: 1e-4 s per step; at 1 kHz 100 steps per update → 10 ms.
  const auto [haptic, steps] = time_per_update(2.0, 20000, 1e-5, 1e-3);
  EXPECT_EQ(steps, 100);
  EXPECT_NEAR(haptic, 0.01, 1e-15);
  // At 30 Hz: ⌈(1/30)/1e-5⌉ = 3334 steps.
  EXPECT_EQ(time_per_update(2.0, 20000, 1e-5, 1.0 / 30.0).second, 3334);
  // A step longer than the period: one step per update.
  const auto [one, one_step] = time_per_update(0.2, 200, 1e-2, 1e-3);
  EXPECT_EQ(one_step, 1);
  EXPECT_NEAR(one, 1e-3, 1e-15);
  // No rate: not computed.
  EXPECT_EQ(time_per_update(0.2, 200, 1e-2, 0.0).first, 0.0);
}

TEST(BudgetMagnitude, ExplicitElseLargestWithinTheLinearRegimeElseSmallest) {
  Scene s;
  s.load.magnitudes = {1e-5, 1e-4, 1e-3};
  // Strain 400 per N: 1e-4 N strains 4 %, 1e-3 N 40 %.
  EXPECT_DOUBLE_EQ(budget_magnitude(s, 400.0), 1e-4);
  EXPECT_DOUBLE_EQ(budget_magnitude(s, 1e6), 1e-5);  // none within: the smallest
  s.budget.magnitude = 1e-3;
  EXPECT_DOUBLE_EQ(budget_magnitude(s, 400.0), 1e-3);
}

TEST(Quantities, HandComputedValues) {
  // Four nodes; the QoI node is 0 at the origin; loads on nodes 0 and 1 along +x.
  const std::vector<Vec3> nodes{{0, 0, 0}, {1e-3, 0, 0}, {3e-3, 0, 0}, {0, 5e-3, 0}};
  const std::vector<Vec3> u_ref{{2e-4, 0, 0}, {1e-4, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  const std::vector<Vec3> u_model{{1.5e-4, 0, 0}, {1e-4, 0, 3e-5}, {0, 4e-5, 0}, {0, 0, -2e-4}};
  const std::vector<Vec3> loads{{3e-3, 0, 0}, {1e-3, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  Budget b;
  b.quantity = BudgetQuantity::patch;
  b.radius = 3.5e-3;
  const QuantityErrors q = quantity_errors(b, nodes, u_model, u_ref, 0, Vec3::Zero(), loads, {});
  EXPECT_NEAR(q.contact_point_mm, 0.05, 1e-12);  // |1.5e-4 − 2e-4| m
  EXPECT_NEAR(q.field_mm, 0.2, 1e-12);           // node 3
  ASSERT_TRUE(q.patch_mm.has_value());
  EXPECT_NEAR(*q.patch_mm, 0.05, 1e-12);  // nodes 0..2 (node 3 is 5 mm away): max(0.05, 0.03, 0.04)
  // Indentation Σ f·u / |Σ f|: model (3e-3·1.5e-4 + 1e-3·1e-4)/4e-3 = 1.375e-4 m,
  // reference (3e-3·2e-4 + 1e-3·1e-4)/4e-3 = 1.75e-4 m.
  EXPECT_NEAR(*q.indentation_mm, 0.1375, 1e-12);
  EXPECT_NEAR(*q.indentation_reference_mm, 0.175, 1e-12);
  // Force felt at the reference's indentation: F·d_ref/d_model − F = 4 mN·(1.75/1.375 − 1).
  EXPECT_NEAR(*q.reaction_mN, 4.0 * (0.175 / 0.1375 - 1.0), 1e-9);
  EXPECT_NEAR(budget_quantity_error(q, BudgetQuantity::patch), 0.05, 1e-12);
  EXPECT_NEAR(budget_quantity_error(q, BudgetQuantity::field), 0.2, 1e-12);
  EXPECT_NEAR(budget_quantity_error(q, BudgetQuantity::reaction), *q.reaction_mN, 0.0);

  // No contact loads: no reaction; another quantity: no patch. A dynamic history's larger error
  // counts for the contact point.
  History h;
  h.time_s = {0.0, 1.0};
  h.max_error_mm = 0.3;
  const QuantityErrors r = quantity_errors(Budget{}, nodes, u_model, u_ref, 0, Vec3::Zero(), {}, h);
  EXPECT_FALSE(r.patch_mm.has_value());
  EXPECT_FALSE(r.reaction_mN.has_value());
  EXPECT_TRUE(std::isnan(budget_quantity_error(r, BudgetQuantity::reaction)));
  EXPECT_NEAR(r.contact_point_mm, 0.3, 1e-12);
  // A model that does not indent feels an infinite force error.
  const std::vector<Vec3> still(4, Vec3::Zero());
  const QuantityErrors s =
      quantity_errors(Budget{}, nodes, still, u_ref, 0, Vec3::Zero(), loads, {});
  EXPECT_TRUE(std::isinf(*s.reaction_mN));
}

TEST(Candidates, GeneratedFromTheLibrarysLists) {
  Scene s;
  s.load.kind = LoadKind::contact;
  ModelSpec m;
  m.kind = ModelKind::volume_msm;
  m.stiffness = msm::StiffnessRule::seed001;
  s.models = {m};
  const std::vector<ModelSpec> c = candidate_models(s, {4e-3, 8e-3});
  // FEM P1, corotational P1, XPBD FEM + (2 kinds × every rule + the hybrid volume model under both
  // rules for its moduli + the edge-pair volume model + the discrete-shells surface model) ×
  // (static, linear, 2 radii).
  const std::size_t spring_models = 2 * msm::kAllStiffnessRules.size() + 4;
  ASSERT_EQ(c.size(), 3 + spring_models * 4);
  std::set<std::string> names, rules;
  for (const auto& x : c) {
    names.insert(x.name);
    if (x.kind == ModelKind::surface_msm || x.kind == ModelKind::volume_msm)
      rules.insert(msm::to_string(x.stiffness));
  }
  EXPECT_EQ(names.size(), c.size());  // unique
  EXPECT_EQ(rules.size(), msm::kAllStiffnessRules.size());
  EXPECT_TRUE(names.count("volume/lloyd/static/R=4mm"));
  EXPECT_TRUE(names.count("volume/hybrid-volume/static"));
  EXPECT_TRUE(names.count("volume/hybrid-volume-homogenised/static"));
  EXPECT_TRUE(names.count("surface/discrete-shells/static/R=8mm"));
  EXPECT_TRUE(names.count("volume/edge-pairs/linear"));
  EXPECT_TRUE(names.count("fem/corotational-p1/static"));
  EXPECT_EQ(std::count_if(c.begin(), c.end(),
                          [](const ModelSpec& x) {
                            return x.kind == ModelKind::xpbd_fem &&
                                   x.name.starts_with("fem/xpbd-neo-hookean/dt=");
                          }),
            1);
  for (const auto& x : c) {
    EXPECT_EQ(x.edge_pairs, x.name.starts_with("volume/edge-pairs/")) << x.name;
    if (x.name.starts_with("surface/discrete-shells/")) {
      EXPECT_EQ(x.bending, msm::Bending::discrete_shells) << x.name;
      EXPECT_EQ(x.stiffness, msm::StiffnessRule::van_gelder) << x.name;
    } else {
      EXPECT_EQ(x.bending, msm::Bending::none) << x.name;
    }
  }
  EXPECT_TRUE(names.count("volume/least-squares-fit/linear"));
  EXPECT_TRUE(names.count("surface/seed000/linear"));
  // Pressure: no regions of interest.
  s.load.kind = LoadKind::pressure;
  EXPECT_EQ(candidate_models(s, {4e-3}).size(), 3 + spring_models * 2);

  // Dynamic: every integrator at its family's time steps, over the scene's longest run.
  s.load.kind = LoadKind::contact;
  ModelSpec e = m;
  e.solver = msm::parse_solver("verlet");
  e.solver.dt = 1e-5;
  e.solver.steps = 20000;
  e.damping = 1e-4;
  ModelSpec i = m;
  i.solver = msm::parse_solver("implicit-euler");
  i.solver.dt = 1e-3;
  i.solver.steps = 100;
  s.models = {e, i};
  const std::vector<ModelSpec> d = candidate_models(s, {4e-3});
  // Every integrator on every spring model, plus local-global-euler on the plain spring networks
  // (all but the two hybrid volume, the edge-pair and the discrete-shells models), at the
  // implicit step.
  ASSERT_EQ(d.size(), spring_models * msm::kAllIntegrators.size() + spring_models - 4);
  for (const auto& x : d) {
    if (x.solver.kind == msm::SolverKind::local_global_euler) {
      EXPECT_FALSE(x.volume_term) << x.name;
      EXPECT_FALSE(x.edge_pairs) << x.name;
      EXPECT_EQ(x.bending, msm::Bending::none) << x.name;
      EXPECT_DOUBLE_EQ(x.solver.dt, 1e-3) << x.name;
      EXPECT_EQ(x.solver.steps, 200) << x.name;
      continue;
    }
    const bool implicit = x.solver.integrator == msm::Integrator::implicit_euler;
    EXPECT_EQ(x.solver.kind, msm::SolverKind::integrator) << x.name;
    EXPECT_DOUBLE_EQ(x.solver.dt, implicit ? 1e-3 : 1e-5) << x.name;
    EXPECT_EQ(x.solver.steps, implicit ? 200 : 20000) << x.name;  // 0.2 s simulated
    EXPECT_DOUBLE_EQ(x.damping, 1e-4);
  }
}

TEST(Candidates, IncludeTheScenesCalibratedModels) {
  Scene s;
  s.load.kind = LoadKind::contact;
  ModelSpec m;
  m.kind = ModelKind::volume_msm;
  m.stiffness = msm::StiffnessRule::van_gelder;
  m.volume_term = true;
  m.calibration = "/x/hybrid_groups.json";
  m.calibration_transfer = true;
  s.models = {m};
  const std::vector<ModelSpec> c = candidate_models(s, {4e-3});
  const std::size_t spring_models = 2 * msm::kAllStiffnessRules.size() + 4;  // as above
  ASSERT_EQ(c.size(), 3 + spring_models * 3 + 2);
  int calibrated = 0;
  for (const auto& x : c) {
    if (x.calibration.empty()) continue;
    ++calibrated;
    EXPECT_TRUE(x.volume_term);
    EXPECT_TRUE(x.calibration_transfer);
    EXPECT_TRUE(x.name == "volume/calibrated-hybrid_groups/static" ||
                x.name == "volume/calibrated-hybrid_groups/linear")
        << x.name;
  }
  EXPECT_EQ(calibrated, 2);
}

TEST(Rejudged, TheSameCandidatesAtAnotherRateWithoutRunningThemAgain) {
  // Judged at 30 Hz (33 ms) the accurate 20 ms model wins; at 1 kHz (1 ms) only the 0.5 ms one
  // is fast enough, and it is too inaccurate: none meets, the closest is named.
  Recommendation rec;
  rec.scene.budget.stated = true;
  rec.scene.budget.tolerance = 0.1;
  rec.scene.budget.rate_hz = 30.0;
  ModelSpec linear;
  linear.kind = ModelKind::volume_msm;
  linear.solver = msm::parse_solver("linear");
  rec.scene.models = {linear};
  rec.candidates = {candidate("accurate", 0.05, 0.020), candidate("fast", 0.3, 0.0005)};
  rec.selection = select_model(rec.candidates, 0.1, rec.scene.budget.seconds_per_update());
  ASSERT_TRUE(rec.selection.recommended.has_value());
  EXPECT_EQ(*rec.selection.recommended, 0u);
  ASSERT_TRUE(rate_independent(rec));

  const Recommendation at_1khz = rejudged(rec, 1000.0);
  EXPECT_EQ(at_1khz.scene.budget.rate_hz, 1000.0);
  EXPECT_DOUBLE_EQ(at_1khz.scene.budget.seconds_per_update(), 1e-3);
  EXPECT_FALSE(at_1khz.selection.recommended.has_value());
  EXPECT_EQ(at_1khz.selection.verdicts[0], Verdict::too_slow);
  EXPECT_EQ(at_1khz.selection.verdicts[1], Verdict::too_inaccurate);
  EXPECT_EQ(at_1khz.candidates.size(), rec.candidates.size());  // the same evidence

  // An integrator's update is ⌈period/dt⌉ steps: its time depends on the rate, so no re-judging.
  ModelSpec integrator = linear;
  integrator.solver = msm::parse_solver("verlet");
  rec.scene.models.push_back(integrator);
  EXPECT_FALSE(rate_independent(rec));
  EXPECT_THROW((void)rejudged(rec, 1000.0), std::logic_error);
}
