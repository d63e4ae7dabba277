// contact::solve_signorini and press_rigid_indenter against hand-solved cases and a second solver
// (projected Gauss–Seidel run to convergence) on random symmetric positive definite compliances.
#include <gtest/gtest.h>

#include <random>

#include "verification/contact/signorini.hpp"

using namespace vessel::contact;

namespace {

/// Projected Gauss–Seidel on the same conditions (SOFA's LCP solver), iterated to round-off.
Eigen::VectorXd projected_gauss_seidel(const Eigen::MatrixXd& W, const Eigen::VectorXd& g0) {
  Eigen::VectorXd l = Eigen::VectorXd::Zero(g0.size());
  for (int sweep = 0; sweep < 200000; ++sweep) {
    double change = 0.0;
    for (Eigen::Index i = 0; i < g0.size(); ++i) {
      const double gi = g0[i] + W.row(i).dot(l);
      const double next = std::max(0.0, l[i] - gi / W(i, i));
      change = std::max(change, std::abs(next - l[i]));
      l[i] = next;
    }
    if (change < 1e-15 * (1.0 + l.cwiseAbs().maxCoeff())) break;
  }
  return l;
}

Eigen::MatrixXd random_spd(int m, std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::MatrixXd A(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) A(i, j) = n(rng);
  return A * A.transpose() / m + 0.1 * Eigen::MatrixXd::Identity(m, m);
}

}  // namespace

TEST(Signorini, HandSolvedTwoCandidates) {
  Eigen::MatrixXd W(2, 2);
  W << 2, 1, 1, 2;
  // One pressed: λ0 = 1/2 closes its gap; the other's gap opens to 0.5 + 0.5 = 1.
  SignoriniSolution s = solve_signorini(W, Eigen::Vector2d(-1, 0.5), 1e-14);
  EXPECT_NEAR(s.force[0], 0.5, 1e-15);
  EXPECT_EQ(s.force[1], 0.0);
  EXPECT_NEAR(s.gap[1], 1.0, 1e-15);
  // Both pressed: λ = W⁻¹ (1, 1) = (1/3, 1/3).
  s = solve_signorini(W, Eigen::Vector2d(-1, -1), 1e-14);
  EXPECT_NEAR(s.force[0], 1.0 / 3, 1e-15);
  EXPECT_NEAR(s.force[1], 1.0 / 3, 1e-15);
  // Nothing pressed: no force.
  s = solve_signorini(W, Eigen::Vector2d(0.1, 0.2), 1e-14);
  EXPECT_EQ(s.force.norm(), 0.0);
}

TEST(Signorini, MatchesProjectedGaussSeidelAndMeetsTheConditions) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n;
  for (const int m : {5, 20, 60}) {
    const Eigen::MatrixXd W = random_spd(m, rng);
    Eigen::VectorXd g0(m);
    for (int i = 0; i < m; ++i) g0[i] = n(rng);
    const SignoriniSolution s = solve_signorini(W, g0, 1e-13);
    const Eigen::VectorXd pgs = projected_gauss_seidel(W, g0);
    EXPECT_LT((s.force - pgs).norm(), 1e-9 * pgs.norm()) << "m = " << m;
    EXPECT_GE(s.force.minCoeff(), 0.0);
    EXPECT_GE(s.gap.minCoeff(), -1e-12);
    EXPECT_LT(std::abs(s.force.dot(s.gap)), 1e-12 * s.force.norm());
    int active = 0;
    for (const char a : s.active) active += a;
    EXPECT_GT(active, 0);
    EXPECT_LT(active, m);  // a mixed case: some pressed, some open
  }
}

TEST(Signorini, RigidPressReachesTheForceAndAgreesWithBisection) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int m = 30;
  const Eigen::MatrixXd W = random_spd(m, rng);
  Eigen::VectorXd h(m);
  for (int i = 0; i < m; ++i) h[i] = u(rng);
  const double F = 2.0;
  const RigidPress p = press_rigid_indenter(W, h, F, 1e-14);
  EXPECT_NEAR(p.contact.force.sum(), F, 1e-12 * F);
  // The same approach by bisection on δ (each probe an independent solve).
  double lo = h.minCoeff(), hi = lo + 1.0;
  const auto total = [&](double d) {
    return solve_signorini(W, h - d * Eigen::VectorXd::Ones(m), 1e-14).force.sum();
  };
  while (total(hi) < F) hi += 1.0;
  for (int k = 0; k < 100; ++k) (total(0.5 * (lo + hi)) < F ? lo : hi) = 0.5 * (lo + hi);
  EXPECT_NEAR(p.approach, 0.5 * (lo + hi), 1e-12);
  EXPECT_THROW(press_rigid_indenter(W, h, 0.0, 1e-14), std::invalid_argument);
}
