// The guidewire's critical step (verification/studies/stability/rod_steps.hpp): the closed forms
// against values worked by hand, the step found by running the integrator against the closed
// form (axial for the metal wire; bending when the wire is made axially and torsionally soft),
// and the implicit integrators bounded at every step tried.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "../../schema_check.hpp"
#include "../../test_helpers.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rod_layout.hpp"
#include "msm/stability/stability_search.hpp"
#include "reports/study_files.hpp"
#include "reports/study_sections.hpp"
#include "verification/studies/stability/rod_steps.hpp"

using namespace vessel;
using namespace vessel::stability_study;
namespace rods = vessel::msm::rods;

namespace {

/// The study's default wire (60 GPa, 0.356 mm, 6450 kg/m³, 0.1 m) at N segments.
rods::RodLayout wire_layout(int n) {
  const RodWire w;
  return rods::make_layout(
      rods::uniform_rod({w.young, w.shear, w.density}, w.length, w.diameter, n));
}

}  // namespace

TEST(RodSteps, ClosedFormsEqualTheValuesWorkedByHand) {
  // E = 60 GPa, ρ = 6450 kg/m³: c = √(E/ρ) = 3049.971 m/s; h = 0.1 m / 50 = 2 mm:
  //   axial   h/c = 6.557439e-7 s;
  //   twist   h/√(G/ρ), G = E/2.66: 1.069486e-6 s;
  //   bending h²/(2√(EI/ρA)) = h²/(2·c·d/4) (√(I/A) = d/4): 4e-6/(2·3049.971·8.9e-5) = 7.367908e-6 s.
  const RodWire w;
  const RodStepClosedForm cf =
      rod_step_closed_form(rods::solid_section({w.young, w.shear, w.density}, w.diameter), 2e-3);
  EXPECT_NEAR(cf.axial_dt / 6.557439e-7, 1.0, 1e-6);
  EXPECT_NEAR(cf.twist_dt / 1.069486e-6, 1.0, 1e-6);
  EXPECT_NEAR(cf.bending_dt / 7.367908e-6, 1.0, 1e-6);
  EXPECT_EQ(cf.dt, cf.axial_dt);  // the slender wire: axial binds
}

TEST(RodSteps, SymplecticEulerAndVerletRunToTheAxialClosedForm) {
  const rods::RodLayout layout = wire_layout(50);
  for (const msm::Integrator i : {msm::Integrator::symplectic_euler, msm::Integrator::verlet}) {
    const RodStepRow r = der_explicit_row(layout, i, 500);
    std::printf("ROD-STEP N 50 %s: closed form %.6e s, Lanczos 2/omega %.6e s, found %.6e s, "
                "unstable %.6e s\n",
                r.integrator.c_str(), r.closed_form_dt, r.predicted_dt, r.found_dt, r.unstable_dt);
    EXPECT_NEAR(r.closed_form_dt / 6.557439e-7, 1.0, 1e-6);
    // The finite clamped chain's top axial mode lies just below the infinite chain's 2c/h.
    EXPECT_NEAR(r.found_dt / r.closed_form_dt, 1.0, 0.02) << r.integrator;
    EXPECT_GT(r.unstable_dt, r.found_dt);
    EXPECT_LT(r.unstable_dt / r.closed_form_dt, 1.03) << r.integrator;
    EXPECT_NEAR(r.predicted_dt / r.closed_form_dt, 1.0, 0.02);
  }
}

TEST(RodSteps, BendingClosedFormBindsAWireMadeAxiallyAndTorsionallySoft) {
  // EA and GJ divided by 10⁴ (masses kept): their steps grow 100×, bending's (7.37 µs) binds.
  rods::RodLayout layout = wire_layout(50);
  for (auto& s : layout.section) {
    s.EA *= 1e-4;
    s.GJ *= 1e-4;
  }
  const RodStepRow r = der_explicit_row(layout, msm::Integrator::symplectic_euler, 500);
  std::printf("ROD-STEP bending N 50: closed form %.6e s, found %.6e s\n", r.closed_form_dt,
              r.found_dt);
  EXPECT_NEAR(r.closed_form_dt / 7.367908e-6, 1.0, 1e-6);
  EXPECT_EQ(r.closed_form_dt, r.bending_dt);
  EXPECT_NEAR(r.found_dt / r.bending_dt, 1.0, 0.03);
}

TEST(RodSteps, ImplicitIntegratorsAndXpbdStayBoundedFarBeyondTheExplicitStep) {
  const rods::RodLayout layout = wire_layout(50);
  // From 1.5× the explicit limit (where symplectic Euler diverges) to a 30 Hz frame.
  const std::vector<double> dts{1e-6, 1e-4, 1e-2, 1.0 / 30.0};
  // The control: symplectic Euler on the same rod diverges at 1e-6 s (1.5× its limit).
  const rods::DerRod rod(layout);
  msm::Problem p;
  p.form = &rod;
  p.rest = rod.rest_state();
  p.external_force = Eigen::VectorXd::Zero(rod.num_dofs());
  p.mass = rod.lumped_mass();
  p.fixed = rod.clamp_fixed();
  EXPECT_FALSE(msm::is_stable(p, msm::Integrator::symplectic_euler, 1e-6, 200,
                              msm::random_velocity(p, 1e-3, 1)));
  rods::DerRod der(layout);
  rods::CordeRod corde(layout);
  for (const RodStepRow& r :
       {implicit_row(der, WireModel::der, dts, 50), implicit_row(corde, WireModel::corde, dts, 50),
        xpbd_row(layout, dts, 50)}) {
    ASSERT_EQ(r.bounded.size(), dts.size());
    for (std::size_t k = 0; k < dts.size(); ++k) {
      EXPECT_TRUE(r.bounded[k]) << r.model << " " << r.integrator << " at " << dts[k] << " s: "
                                << r.failure;
    }
  }
}

TEST(RodSteps, JsonMeetsItsSchemaAndTheReportRendersTheRows) {
  StabilityReport rep;
  rep.command_line = "vesselverify stability --quick";
  rep.trial_steps = 500;
  RodStepRow found;
  found.model = "der";
  found.integrator = "symplectic-euler";
  found.segments = 50;
  found.h = 2e-3;
  found.axial_dt = found.closed_form_dt = 6.557e-7;
  found.twist_dt = 1.069e-6;
  found.bending_dt = 7.368e-6;
  found.omega_max = 3.05e6;
  found.predicted_dt = 6.55e-7;
  found.found_dt = 6.54e-7;
  found.unstable_dt = 6.57e-7;
  RodStepRow ladder = found;
  ladder.model = "corde";
  ladder.integrator = "implicit-euler";
  ladder.omega_max = ladder.predicted_dt = ladder.found_dt = ladder.unstable_dt = NAN;
  ladder.steps_tried = {1e-6, 1e-2};
  ladder.bounded = {true, true};
  RodStepRow broken = ladder;
  broken.model = "xpbd";
  broken.integrator = "xpbd";
  broken.bounded = {true, false};
  rep.rod_rows = {found, ladder, broken};
  const std::string text = stability_json(rep);
  const auto schema = nlohmann::json::parse(test::read_text(VESSEL_STABILITY_SCHEMA));
  const auto problems = test::schema_problems(nlohmann::json::parse(text), schema);
  EXPECT_TRUE(problems.empty()) << test::joined(problems);
  const reports::StabilityFile file = reports::parse_stability(text, "stability.json");
  ASSERT_EQ(file.rod_steps.size(), 3u);
  EXPECT_FALSE(file.rod_steps[1].found_dt.has_value());
  const std::string md = reports::stability_markdown(file);
  EXPECT_NE(md.find("### The guidewire's critical step"), std::string::npos) << md;
  EXPECT_NE(md.find("| der | symplectic-euler | 50 | 2 | 0.6557 | 1.069 | 7.368 | 0.6557 | 0.655 | "
                    "0.654 | 0.9974 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("bounded at every step tried, 1 µs to 10 ms"), std::string::npos) << md;
  EXPECT_NE(md.find("**unbounded at "), std::string::npos) << md;
}
