// Steihaug–Toint truncated CG (msm/solvers/steihaug.hpp) against the Newton step of a dense solve
// and against its iterates worked out by hand on a 2 × 2 indefinite model.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "msm/solvers/steihaug.hpp"

using namespace vessel::msm;

namespace {

struct Model {
  Eigen::MatrixXd H, P;
  Eigen::VectorXd g;
  [[nodiscard]] SteihaugStep step(double radius, double forcing = 1e-12) const {
    const Eigen::LLT<Eigen::MatrixXd> p(P);
    return steihaug_cg([&](const VectorXd& v, VectorXd& out) { out = H * v; },
                       [&](const VectorXd& v, VectorXd& out) { out = P * v; },
                       [&](const VectorXd& r, VectorXd& out) { out = p.solve(r); }, g, radius,
                       forcing, 50);
  }
  [[nodiscard]] double m(const VectorXd& d) const { return g.dot(d) + 0.5 * d.dot(H * d); }
  [[nodiscard]] double p_norm(const VectorXd& d) const { return std::sqrt(d.dot(P * d)); }
};

}  // namespace

TEST(Steihaug, APositiveDefiniteModelInsideTheRegionGivesTheNewtonStep) {
  Model s;
  s.H = Eigen::MatrixXd{{4, 1, 0}, {1, 3, 1}, {0, 1, 2}};
  s.P = Eigen::MatrixXd{{5, 0, 0}, {0, 3, 0}, {0, 0, 2}};
  s.g = Eigen::VectorXd{{1.0, -2.0, 0.5}};
  const SteihaugStep d = s.step(1e3);
  EXPECT_FALSE(d.boundary);
  EXPECT_FALSE(d.negative_curvature);
  EXPECT_LE(d.iterations, 3);  // CG is exact in n steps
  EXPECT_LE((d.d - s.H.llt().solve(-s.g)).norm(), 1e-12);
}

TEST(Steihaug, ATightRegionCutsTheFirstStepOnTheBoundary) {
  // The first CG direction is −P⁻¹g; with Δ below its length the step is it, scaled to ‖d‖_P = Δ.
  Model s;
  s.H = Eigen::MatrixXd{{4, 1}, {1, 3}};
  s.P = Eigen::MatrixXd{{4, 0}, {0, 3}};
  s.g = Eigen::VectorXd{{1.0, 1.0}};
  const Eigen::VectorXd first = -s.P.llt().solve(s.g);
  const double radius = 0.1 * s.p_norm(first);
  const SteihaugStep d = s.step(radius);
  EXPECT_TRUE(d.boundary);
  EXPECT_FALSE(d.negative_curvature);
  EXPECT_NEAR(s.p_norm(d.d), radius, 1e-14);
  EXPECT_LE((d.d - 0.1 * first).norm(), 1e-14);
}

TEST(Steihaug, NegativeCurvatureIsFollowedToTheBoundary) {
  // H = diag(2, −1), P = I, g = (2, 1), Δ = 3, by hand: the first direction p₀ = −g has
  // p₀ᵀHp₀ = 7, α₀ = 5/7, z₁ = (−10/7, −5/7) (inside: ‖z₁‖² = 125/49), r₁ = g + α₀Hp₀ = (−6/7,
  // 12/7), β = ‖r₁‖²/‖g‖² = 36/49, p₁ = −r₁ + βp₀ = (−30/49, −120/49) with p₁ᵀHp₁ = −12600/2401 <
  // 0: the step is z₁ + τp₁ with ‖z₁ + τp₁‖ = 3, τ > 0.
  Model s;
  s.H = Eigen::MatrixXd{{2, 0}, {0, -1}};
  s.P = Eigen::MatrixXd::Identity(2, 2);
  s.g = Eigen::VectorXd{{2.0, 1.0}};
  const SteihaugStep d = s.step(3.0);
  EXPECT_TRUE(d.negative_curvature);
  EXPECT_TRUE(d.boundary);
  EXPECT_EQ(d.iterations, 2);
  const Eigen::Vector2d z1(-10.0 / 7, -5.0 / 7), p1(-30.0 / 49, -120.0 / 49);
  // τ: the positive root of ‖p₁‖²τ² + 2 z₁·p₁ τ + ‖z₁‖² − 9 = 0.
  const double a = p1.squaredNorm(), b = 2 * z1.dot(p1), c = z1.squaredNorm() - 9.0;
  const double tau = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  EXPECT_LE((d.d - (z1 + tau * p1)).norm(), 1e-13);
  EXPECT_NEAR(d.d.norm(), 3.0, 1e-13);
  EXPECT_LT(s.g.dot(d.d), 0.0);
  EXPECT_LT(s.m(d.d), s.m(z1));  // the curvature lowers the model below the PD part's step
}
