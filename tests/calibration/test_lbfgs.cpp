// The L-BFGS minimiser (msm/calibration/lbfgs) on functions whose minimum is known in closed form.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "msm/calibration/lbfgs.hpp"

using namespace vessel::msm;

TEST(Lbfgs, FindsTheMinimumOfAnIllConditionedQuadratic) {
  // f = ½xᵀAx − bᵀx, minimum at x* = A⁻¹b (condition number of A about 1e3).
  const int n = 30;
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Eigen::MatrixXd Q = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return g(rng); });
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(Q);
  const Eigen::MatrixXd O = qr.householderQ();
  Eigen::VectorXd eig(n);
  for (int i = 0; i < n; ++i) eig[i] = std::pow(1e3, static_cast<double>(i) / (n - 1));
  const Eigen::MatrixXd A = O * eig.asDiagonal() * O.transpose();
  const Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(n, [&] { return g(rng); });
  const Eigen::VectorXd x_star = A.ldlt().solve(b);
  const Objective f = [&](const Eigen::VectorXd& x, Eigen::VectorXd& grad) {
    grad = A * x - b;
    return 0.5 * x.dot(A * x) - b.dot(x);
  };
  LbfgsOptions o;
  o.max_iterations = 500;
  o.gradient_tolerance = 1e-7;  // f's round-off stops the Armijo test near 1e-7 here
  o.relative_decrease = 0.0;  // stop on the gradient alone
  const LbfgsResult r = minimize_lbfgs(f, Eigen::VectorXd::Zero(n), o);
  EXPECT_TRUE(r.converged) << r.stop_reason << " after " << r.iterations << ", |g| " << r.gradient_norm;
  // |x − x*|/|x*| ≤ cond(A)·|∇f|/|∇f(x0)|: 1e3 · 1e-7.
  EXPECT_LT((r.x - x_star).norm() / x_star.norm(), 1e-4);
}

TEST(Lbfgs, FindsRosenbrocksMinimumInTwoAndTenDimensions) {
  // Rosenbrock: Σ 100(x_{i+1} − x_i²)² + (1 − x_i)², minimum 0 at (1, ..., 1).
  const Objective f = [](const Eigen::VectorXd& x, Eigen::VectorXd& grad) {
    grad.setZero(x.size());
    double v = 0.0;
    for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
      const double a = x[i + 1] - x[i] * x[i];
      const double c = 1.0 - x[i];
      v += 100.0 * a * a + c * c;
      grad[i] += -400.0 * a * x[i] - 2.0 * c;
      grad[i + 1] += 200.0 * a;
    }
    return v;
  };
  for (const int n : {2, 10}) {
    Eigen::VectorXd x0 = Eigen::VectorXd::Constant(n, -1.2);
    x0[n - 1] = 1.0;
    LbfgsOptions o;
    o.max_iterations = 2000;
    o.gradient_tolerance = 1e-10;
    const LbfgsResult r = minimize_lbfgs(f, x0, o);
    EXPECT_LT((r.x - Eigen::VectorXd::Ones(n)).lpNorm<Eigen::Infinity>(), 1e-5)
        << "n = " << n << ", " << r.stop_reason << " after " << r.iterations;
    EXPECT_LT(r.f, 1e-10);
  }
}

TEST(Lbfgs, RejectsZeroMemory) {
  LbfgsOptions o;
  o.memory = 0;
  const Objective f = [](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    g = x;
    return 0.5 * x.squaredNorm();
  };
  EXPECT_THROW(minimize_lbfgs(f, Eigen::VectorXd::Ones(2), o), std::invalid_argument);
}
