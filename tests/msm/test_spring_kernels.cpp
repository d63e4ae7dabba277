// Spring kernels against finite differences of their own energy and hand-derived values.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "finite_differences.hpp"
#include "msm/kernels/spring_kernels.hpp"

using namespace vessel::msm;
using vessel::msm::test::check_derivatives;

namespace {

Eigen::VectorXd random_state(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd x(6);
  for (int i = 0; i < 6; ++i) x[i] = scale * u(rng);
  return x;
}

void check_law(const SpringLaw& law, double rest, const Eigen::VectorXd& x) {
  auto E = [&](const Eigen::VectorXd& y) {
    return spring_energy(y.head<3>(), y.tail<3>(), rest, law);
  };
  auto G = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    return spring_gradient(y.head<3>(), y.tail<3>(), rest, law);
  };
  auto H = [&](const Eigen::VectorXd& y) -> Eigen::MatrixXd {
    return spring_hessian(y.head<3>(), y.tail<3>(), rest, law);
  };
  const auto c = check_derivatives(E, G, H, x, 1e-7 * rest);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-5);
  EXPECT_LT(c.hessian_asymmetry, 1e-14);
}

}  // namespace

TEST(SpringKernels, HookeEnergyGradientHessianMatchFiniteDifferencesAtRandomStates) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::VectorXd x = random_state(rng, 1e-3);
    check_law({41.106, 41.106}, 0.8e-3, x);  // stretched and compressed states both occur
  }
}

TEST(SpringKernels, BilinearSpringMatchesFiniteDifferencesOnBothBranches) {
  std::mt19937 rng(2);
  SpringLaw law{10.0, 40.0, 0.1e-3};
  int above = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const Eigen::VectorXd x = random_state(rng, 1e-3);
    const double L = (x.head<3>() - x.tail<3>()).norm();
    const double rest = 0.7e-3;
    if (std::abs(L - rest - law.threshold) < 1e-6) continue;  // stay off the kink for FD
    above += L - rest > law.threshold;
    check_law(law, rest, x);
  }
  EXPECT_GT(above, 10);
}

TEST(SpringKernels, HookeForceIsSeed000Eq32ByHand) {
  // xa = (2,0,0) mm, xb = 0, l = 1 mm, k = 5 N/m: f_a = −k (xa−xb)/|…| (|…| − l) = (−5e-3, 0, 0) N.
  const SpringLaw law{5.0, 5.0};
  const Vec6 g = spring_gradient(Vec3(2e-3, 0, 0), Vec3::Zero(), 1e-3, law);
  EXPECT_NEAR(-g[0], -5e-3, 1e-18);
  EXPECT_NEAR(-g[3], 5e-3, 1e-18);
  EXPECT_NEAR(spring_energy(Vec3(2e-3, 0, 0), Vec3::Zero(), 1e-3, law), 0.5 * 5.0 * 1e-6, 1e-20);
}

TEST(SpringKernels, BilinearForceIsSeed001Eq1ByHand) {
  // k1 = 10, k2 = 30 N/m, Δx_c = 0.1 mm, elongation 0.3 mm: |F| = k1·Δx_c + k2·(0.3 − 0.1) mm.
  const SpringLaw law{10.0, 30.0, 0.1e-3};
  const Vec6 g = spring_gradient(Vec3(1.3e-3, 0, 0), Vec3::Zero(), 1e-3, law);
  EXPECT_NEAR(g[0], 10.0 * 0.1e-3 + 30.0 * 0.2e-3, 1e-15);
  // Below the threshold it is Hooke's k1.
  const Vec6 g2 = spring_gradient(Vec3(1.05e-3, 0, 0), Vec3::Zero(), 1e-3, law);
  EXPECT_NEAR(g2[0], 10.0 * 0.05e-3, 1e-15);
}

TEST(SpringKernels, ProjectedHessianIsPsdAndEqualsTheUnprojectedOneInTension) {
  const SpringLaw law{20.0, 20.0};
  // Compressed spring: the transverse eigenvalue k(L−l)/L is negative.
  Mat6 H = spring_hessian(Vec3(0.5e-3, 0.1e-3, 0), Vec3::Zero(), 1e-3, law, false);
  Eigen::SelfAdjointEigenSolver<Mat6> es(H);
  EXPECT_LT(es.eigenvalues().minCoeff(), -1.0);
  Mat6 Hp = spring_hessian(Vec3(0.5e-3, 0.1e-3, 0), Vec3::Zero(), 1e-3, law, true);
  Eigen::SelfAdjointEigenSolver<Mat6> esp(Hp);
  EXPECT_GT(esp.eigenvalues().minCoeff(), -1e-12);
  // Projection keeps the positive part: H − Hp is negative semi-definite, of rank 2.
  Eigen::SelfAdjointEigenSolver<Mat6> diff(H - Hp);
  EXPECT_LT(diff.eigenvalues().maxCoeff(), 1e-12);
  // Stretched: nothing to project.
  const Mat6 Ht = spring_hessian(Vec3(1.5e-3, 0.2e-3, 0), Vec3::Zero(), 1e-3, law, false);
  const Mat6 Htp = spring_hessian(Vec3(1.5e-3, 0.2e-3, 0), Vec3::Zero(), 1e-3, law, true);
  EXPECT_LT((Ht - Htp).norm(), 1e-12);
}

TEST(SpringKernels, AxialDampingIsSeed000Eq34AndDissipates) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 xa(u(rng), u(rng), u(rng)), xb(u(rng), u(rng), u(rng));
    const Vec3 va(u(rng), u(rng), u(rng)), vb(u(rng), u(rng), u(rng));
    const double kd = 0.3;
    const Vec6 f = axial_damping_force(xa, xb, va, vb, kd);
    // Along the axis, equal and opposite, dissipative.
    const Vec3 d = (xa - xb).normalized();
    EXPECT_LT((f.head<3>() - f.head<3>().dot(d) * d).norm(), 1e-14);
    EXPECT_LT((f.head<3>() + f.tail<3>()).norm(), 1e-14);
    const double power = f.head<3>().dot(va) + f.tail<3>().dot(vb);
    EXPECT_NEAR(power, -kd * std::pow((va - vb).dot(d), 2), 1e-12);
    EXPECT_LE(power, 1e-15);
    // Jacobian −∂f/∂v against finite differences (f is linear in v: exact).
    Eigen::Matrix<double, 6, 1> v;
    v << va, vb;
    const Mat6 J = axial_damping_jacobian(xa, xb, kd);
    EXPECT_LT((f + J * v).norm(), 1e-13);
  }
  EXPECT_LT((point_damping_force(Vec3(1, 2, 3), 0.5) - Vec3(-0.5, -1, -1.5)).norm(), 1e-15);
}

TEST(SpringKernels, ZeroRestLengthSpringAtCoincidentEndsHasHessianKTimesIdentityBlocks) {
  // ½k|xa − xb|² has Hessian k[I −I; −I I] everywhere, including where xa = xb.
  SpringLaw law;
  law.k1 = 7.0;
  const Vec3 x(0.1, -0.2, 0.3);
  const Mat6 H = spring_hessian(x, x, 0.0, law, false);
  Mat6 expected;
  const Eigen::Matrix3d K = 7.0 * Eigen::Matrix3d::Identity();
  expected << K, -K, -K, K;
  EXPECT_LT((H - expected).norm(), 1e-12);
  // Away from coincidence the general formula gives the same (transverse dψ/L = k).
  const Mat6 H1 = spring_hessian(x, x + Vec3(1e-3, 2e-3, -1e-3), 0.0, law, false);
  EXPECT_LT((H1 - expected).norm(), 1e-9);
}
