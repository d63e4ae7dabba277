// The continuum references against published figures and against each other (closed form vs
// shooting), so that the rod tests below compare with a checked truth.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fem_reference/rod_theory/elastica.hpp"
#include "fem_reference/rod_theory/tube_contact.hpp"

namespace vessel::rod_theory {
namespace {

// Bisshopp & Drucker (1945) as tabulated by Mattiasson (1981).
struct Published {
  double alpha, deflection, shortening, angle;
};
constexpr Published kTable[] = {{1.0, 0.3017208, 0.0564332, 0.4613519},
                                {3.0, 0.6032534, 0.2544202, 0.9860169},
                                {10.0, 0.8106090, 0.5549956, 1.4302855}};

TEST(RodTheory, BisshoppDruckerMatchesPublishedTable) {
  for (const auto& p : kTable) {
    const ElasticaTip tip = bisshopp_drucker(p.alpha);
    EXPECT_NEAR(tip.deflection, p.deflection, 1e-7) << p.alpha;
    EXPECT_NEAR(tip.shortening, p.shortening, 1e-7) << p.alpha;
    EXPECT_NEAR(tip.tip_angle, p.angle, 1e-7) << p.alpha;
  }
}

TEST(RodTheory, ShootingAgreesWithEllipticClosedForm) {
  for (const auto& p : kTable) {
    const ElasticaTip tip = bisshopp_drucker(p.alpha);
    const PlanarShot shot = shoot_planar_cantilever(0.0, p.alpha, 0.0);
    EXPECT_NEAR(shot.y, tip.deflection, 1e-10) << p.alpha;
    EXPECT_NEAR(1.0 - shot.x, tip.shortening, 1e-10) << p.alpha;
    EXPECT_NEAR(shot.theta, tip.tip_angle, 1e-10) << p.alpha;
  }
}

TEST(RodTheory, EndMomentGivesACircularArc) {
  const double m = 2.0 * std::numbers::pi;
  const PlanarShot shot = shoot_planar_cantilever(0.0, 0.0, m);
  EXPECT_NEAR(shot.x, 0.0, 1e-10);
  EXPECT_NEAR(shot.y, 0.0, 1e-10);
  EXPECT_NEAR(shot.theta, m, 1e-10);
  const PlanarShot half = shoot_planar_cantilever(0.0, 0.0, 1.0);
  EXPECT_NEAR(half.x, std::sin(1.0), 1e-10);
  EXPECT_NEAR(half.y, 1.0 - std::cos(1.0), 1e-10);
}

TEST(RodTheory, EigenvalueRoots) {
  EXPECT_NEAR(greenhill_clamped(), 8.9868, 5e-5);
  EXPECT_NEAR(std::tan(greenhill_clamped() / 2), greenhill_clamped() / 2, 1e-9);
  EXPECT_NEAR(cantilever_beta(1), 1.875104, 1e-6);
  EXPECT_NEAR(cantilever_beta(2), 4.694091, 1e-6);
  EXPECT_NEAR(cantilever_beta(3), 7.854757, 1e-6);
  EXPECT_NEAR(euler_cantilever_load(), 2.4674011, 1e-7);
}

TEST(RodTheory, StraightTubeContactByShooting) {
  const double c = (3.0e-3 - 0.178e-3) / 20e-3;
  const StraightTubeContact s = straight_tube_contact(0.3, c);
  RecordProperty("force", std::to_string(s.force));
  // The values to six decimals: half a unit of the last one (reached 0.4709683, 1.0124983).
  EXPECT_NEAR(s.force, 0.470968, 5e-7);
  EXPECT_NEAR(s.length, 1.012498, 5e-7);
  EXPECT_NEAR(s.tip_angle, 0.0601, 1e-4);
  // The small-deflection estimate F = 3EI(θ L − c)/L³ at the shooting's L is 0.19 % lower
  // (0.470092), not the 4 % the notes state.
  const double small = 3.0 * (0.3 * s.length - c) / std::pow(s.length, 3);
  EXPECT_NEAR(small / s.force, 0.99814, 1e-4);
}

TEST(RodTheory, ArchApexQuarterWaveElastica) {
  // The wall's outer radius over the bend's: (15 + 3 − 0.178) mm / 15 mm, exactly; the values
  // to seven decimals, half a unit of the last one (reached 0.51596275, 1.06487023, 1.64221461).
  // The input rounded to 1.188133 moves them by 1.4e-7, 3.7e-7 and 2.3e-7: beyond these bounds.
  constexpr double kOuterOverBend = 17.822 / 15.0;
  const ArchApexContact a = arch_apex_contact(kOuterOverBend);
  EXPECT_NEAR(a.modulus, 0.5159627, 5e-8);
  EXPECT_NEAR(a.force, 1.0648702, 5e-8);
  EXPECT_NEAR(a.length, 1.6422146, 5e-8);
  // Independent check by integration in units R = 1, EI = 1: clamp at (1, 0) heading +y, the
  // wall's force (0, −F) at the tip; the curvature at the clamp m0 = 2k·√F (the crest), and the tip
  // must land on (0, R_o) with zero moment.
  const double F = a.force;
  const double m0 = 2.0 * a.modulus * std::sqrt(F);
  const auto y = integrate_planar({1.0, 0.0, std::numbers::pi / 2, m0}, 0.0, -F, a.length);
  EXPECT_NEAR(y[0], 0.0, 1e-9);
  EXPECT_NEAR(y[1], kOuterOverBend, 1e-9);
  EXPECT_NEAR(y[3], 0.0, 1e-9);
}

}  // namespace
}  // namespace vessel::rod_theory
