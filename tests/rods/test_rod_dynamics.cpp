// rod_implicit_euler_step, the one implicit Euler of every rod model, against the closed form of
// backward Euler on a cantilever's first bending mode (Euler–Bernoulli frequency).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "fem_reference/rod_theory/elastica.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rod_dynamics.hpp"
#include "msm/rods/rod_statics.hpp"
#include "rod_cases.hpp"

namespace vessel::msm::rods::test {
namespace {

std::unique_ptr<Rod> cantilever_rod(const std::string& model, int segments) {
  RodLayout layout = make_layout(uniform_rod(test_material(), kLength, kDiameter, segments));
  if (model == "DER") return std::make_unique<DerRod>(std::move(layout));
  return std::make_unique<CordeRod>(std::move(layout));
}

/// The static shape under a tip force α·EI/L² along y: the release state.
VectorXd bent_shape(Rod& rod, double alpha) {
  RodStaticLoad load;
  load.force = VectorXd::Zero(rod.num_dofs());
  load.force[3 * rod.layout().tip_node + 1] = alpha * test_EI() / (kLength * kLength);
  load.steps = static_cast<int>(std::ceil(alpha));
  return solve_rod_static(rod, load).x;
}

/// The cantilever's first bending frequency, rad/s: ω₁ = β₁² √(EI/(ρA L⁴)).
double first_mode_omega() {
  const double beta = rod_theory::cantilever_beta(1);
  return beta * beta * std::sqrt(test_EI() / test_rhoA()) / (kLength * kLength);
}

class RodImplicitEuler : public ::testing::TestWithParam<std::string> {};

TEST_P(RodImplicitEuler, DissipatesAndSwingsThroughTheAxisFromALargeBend) {
  const auto rod = cantilever_rod(GetParam(), 16);
  VectorXd x = bent_shape(*rod, 0.3);
  VectorXd v = VectorXd::Zero(rod->num_dofs());
  const double dt = 2.0 * M_PI / first_mode_omega() / 40.0;
  const VectorXd mass = rod->lumped_mass();
  const auto total = [&] { return rod->energy(x) + 0.5 * v.dot(mass.cwiseProduct(v)); };
  double energy = total();
  const int tip = rod->layout().tip_node;
  const double y0 = x[3 * tip + 1];
  double lowest = y0;
  for (int step = 0; step < 30; ++step) {
    RodStep next = rod_implicit_euler_step(*rod, x, v, VectorXd(), dt);
    x = std::move(next.x);
    v = std::move(next.v);
    if (const EqualityConstraints* c = rod->constraints()) {
      VectorXd values;
      c->evaluate(x, values);
      EXPECT_LE(values.cwiseAbs().maxCoeff(), 1e-10 * kLength * kLength) << step;
    }
    const double e = total();
    EXPECT_LE(e, energy * (1.0 + 1e-9)) << step;  // backward Euler dissipates
    energy = e;
    lowest = std::min(lowest, x[3 * tip + 1]);
  }
  EXPECT_LT(lowest, 0.0);  // it swings through the axis within the first period
  EXPECT_GT(lowest, -y0);  // and loses amplitude
}

// Backward Euler on y'' = −ω²y multiplies the mode by g = 1/(1 − iωh) per step, so once the
// higher modes have decayed the tip obeys y_{n+2} = 2 Re(g) y_{n+1} − |g|² y_n with
// Re(g) = |g|² = 1/(1 + (ωh)²). Both coefficients, fitted from the rod's own steps, give back
// the Euler–Bernoulli ω₁: the phase (an energy-conserving rule has |g| = 1) and the damping.
TEST_P(RodImplicitEuler, SmallOscillationFollowsBackwardEulerOnTheFirstMode) {
  const auto rod = cantilever_rod(GetParam(), 32);
  const double omega = first_mode_omega();
  const double h = 2.0 * M_PI / omega / 20.0;  // ωh = 0.314: the scheme damps 4.6 % a step
  VectorXd x = bent_shape(*rod, 1e-3);
  VectorXd v = VectorXd::Zero(rod->num_dofs());
  const int tip = rod->layout().tip_node;
  std::vector<double> y;
  for (int step = 0; step < 40; ++step) {
    RodStep next = rod_implicit_euler_step(*rod, x, v, VectorXd(), h);
    x = std::move(next.x);
    v = std::move(next.v);
    y.push_back(x[3 * tip + 1]);
  }
  // Least squares for (a, b) in y_{n+2} = a y_{n+1} − b y_n over the second period (mode 2 has
  // ω₂h = 1.97 and has decayed by 1e-4 after the first).
  Eigen::MatrixXd A(18, 2);
  Eigen::VectorXd rhs(18);
  for (int r = 0; r < 18; ++r) {
    const int n = 20 + r;
    A(r, 0) = y[n + 1];
    A(r, 1) = -y[n];
    rhs[r] = y[n + 2];
  }
  const Eigen::Vector2d ab = A.colPivHouseholderQr().solve(rhs);
  const double omega_from_phase = std::sqrt(2.0 / ab[0] - 1.0) / h;
  const double omega_from_damping = std::sqrt(1.0 / ab[1] - 1.0) / h;
  std::printf("ROD-IE %s: ω₁ %.6g rad/s; from Re(g) %.6g (%.2e), from |g|² %.6g (%.2e)\n",
              GetParam().c_str(), omega, omega_from_phase, omega_from_phase / omega - 1.0,
              omega_from_damping, omega_from_damping / omega - 1.0);
  EXPECT_NEAR(omega_from_phase / omega, 1.0, 3e-3);
  EXPECT_NEAR(omega_from_damping / omega, 1.0, 3e-3);
}

TEST_P(RodImplicitEuler, RejectsANonPositiveStep) {
  const auto rod = cantilever_rod(GetParam(), 4);
  const VectorXd x = rod->rest_state();
  const VectorXd v = VectorXd::Zero(x.size());
  EXPECT_THROW(rod_implicit_euler_step(*rod, x, v, VectorXd(), 0.0), InputError);
  EXPECT_THROW(rod_implicit_euler_step(*rod, x, v, VectorXd(), -1e-3), InputError);
  EXPECT_THROW(rod_implicit_euler_step(*rod, x, VectorXd::Zero(3), VectorXd(), 1e-3), InputError);
}

INSTANTIATE_TEST_SUITE_P(Models, RodImplicitEuler, ::testing::Values("DER", "CORDE"));

}  // namespace
}  // namespace vessel::msm::rods::test
