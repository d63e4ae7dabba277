#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fem_reference/convergence.hpp"

using namespace vessel::fem;

TEST(ObservedOrder, RecoversThePowerOfAPowerLaw) {
  // e = C h^p with h halved: e_coarse / e_fine = 2^p.
  EXPECT_NEAR(observed_order(3.0 * std::pow(0.2, 2.0), 3.0 * std::pow(0.1, 2.0)), 2.0, 1e-12);
  EXPECT_NEAR(observed_order(std::pow(0.3, 3.0), std::pow(0.1, 3.0), 3.0), 3.0, 1e-12);
  EXPECT_THROW(observed_order(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(observed_order(1.0, 0.5, 1.0), std::invalid_argument);
}

TEST(ObservedOrder, FromThreeSolutions) {
  // f(h) = 5 + 0.7 h² on h = 0.4, 0.2, 0.1.
  auto f = [](double h) { return 5.0 + 0.7 * h * h; };
  EXPECT_NEAR(observed_order_three(f(0.4), f(0.2), f(0.1)), 2.0, 1e-10);
  EXPECT_THROW(observed_order_three(1.0, 2.0, 1.5), std::domain_error);  // oscillating
}

TEST(Richardson, ExtrapolatesAPowerLawExactly) {
  auto f = [](double h) { return 2.5 - 0.3 * h * h * h; };
  const auto e = richardson(f(0.2), f(0.1), 3.0);
  EXPECT_NEAR(e.extrapolated, 2.5, 1e-12);
  EXPECT_NEAR(e.error_fine, 0.3e-3, 1e-12);
  // Hand-computed GCI: 1.25 · |(f2 − f1)/f1| / (2³ − 1), f2 − f1 = −0.3(0.008 − 0.001) = −0.0021.
  EXPECT_NEAR(e.gci_fine, 1.25 * (0.0021 / f(0.1)) / 7.0, 1e-14);
}

TEST(RichardsonField, RecoversThePointwiseErrorOfAPowerLaw) {
  // u_h(x) = u(x) + c(x) h²: the fine level's error is c(x) h_fine² exactly.
  using vessel::Vec3;
  const std::vector<Vec3> exact{{1e-3, 0, 0}, {0, 2e-3, 1e-3}};
  const std::vector<Vec3> c{{0.5, -1, 0}, {0, 0, 2}};
  auto level = [&](double h) {
    std::vector<Vec3> u;
    for (std::size_t i = 0; i < exact.size(); ++i) u.push_back(exact[i] + c[i] * h * h);
    return u;
  };
  const double h = 1e-2;
  const auto est = richardson_field(level(2 * h), level(h), 2.0);
  ASSERT_EQ(est.error_fine.size(), 2u);
  EXPECT_NEAR(est.error_fine[0], c[0].norm() * h * h, 1e-15);
  EXPECT_NEAR(est.error_fine[1], c[1].norm() * h * h, 1e-15);
  EXPECT_NEAR(est.max_error, 2 * h * h, 1e-15);
  EXPECT_THROW(richardson_field(level(h), {}, 2.0), std::invalid_argument);
}

TEST(GciOrder, ObservedFromThreeLevelsOfAPowerLaw) {
  // f(h) = 1 + 0.1 h^1.5 at h = 1, 1/2, 1/4: p = ln((f3 − f2)/(f2 − f1))/ln 2 = 1.5 by hand
  // ((f3 − f2)/(f2 − f1) = (1 − 2^-1.5)/(2^-1.5 − 4^-1.5) = 2^1.5), with Roache's Fs = 1.25.
  auto f = [](double h) { return 1.0 + 0.1 * std::pow(h, 1.5); };
  const GciOrder g = gci_order(std::vector<double>{f(1.0), f(0.5), f(0.25)}, 1.0);
  EXPECT_EQ(g.source, "observed");
  EXPECT_NEAR(g.order, 1.5, 1e-12);
  EXPECT_EQ(g.safety_factor, 1.25);
  // With that order Richardson recovers f(0) = 1 exactly.
  EXPECT_NEAR(richardson(f(0.5), f(0.25), g.order).extrapolated, 1.0, 1e-14);
}

TEST(GciOrder, ClampsAnImplausibleOrderAndFallsBackWhenOscillatory) {
  // p = 5 observed (differences 32:1) is clamped to the range's top, 3.
  const GciOrder high = gci_order(std::vector<double>{1.0 + 33e-3, 1.0 + 1e-3, 1.0}, 1.0);
  EXPECT_EQ(high.source, "observed");
  EXPECT_DOUBLE_EQ(high.order, 3.0);
  EXPECT_NE(high.note.find("clamped"), std::string::npos) << high.note;
  // Differences of opposite sign: the stated order, Fs 3.
  const GciOrder osc = gci_order(std::vector<double>{1.0, 1.2, 1.1}, 1.0);
  EXPECT_EQ(osc.source, "assumed");
  EXPECT_EQ(osc.order, 1.0);
  EXPECT_EQ(osc.safety_factor, 3.0);
  EXPECT_NE(osc.note.find("oscillatorily"), std::string::npos) << osc.note;
  // Two levels only.
  const GciOrder two = gci_order(std::nullopt, 2.0);
  EXPECT_EQ(two.source, "assumed");
  EXPECT_EQ(two.order, 2.0);
  EXPECT_THROW((void)gci_order(std::nullopt, 5.0), std::invalid_argument);
}
