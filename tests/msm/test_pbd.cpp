// Seed 002's position-based constraints: gradients against finite differences of C (the same
// generic helper), the generic XPBD update against the seed's closed-form corrections, and XPBD
// stiffness in physical units (Hooke's law on a chain, whatever the iteration count).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include "finite_differences.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/pbd/constraints.hpp"
#include "msm/solvers/integrators.hpp"

using namespace vessel;
using namespace vessel::msm;
using vessel::msm::test::fd_gradient;

namespace {

void expect_gradient_matches(const Constraint& c, const Eigen::VectorXd& x) {
  const ConstraintValue v = evaluate(c, x);
  ASSERT_TRUE(v.valid);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  for (int k = 0; k < v.count; ++k) g.segment<3>(3 * c.nodes[k]) += v.grad[k];
  const Eigen::VectorXd g_fd =
      fd_gradient([&](const Eigen::VectorXd& y) { return evaluate(c, y).C; }, x, 1e-7);
  EXPECT_LT((g - g_fd).norm(), 1e-6 * g_fd.norm()) << "type " << static_cast<int>(c.type);
}

Problem free_problem(const SpringModel& model, const Eigen::VectorXd& x, double mass) {
  Problem p;
  p.form = &model;
  p.rest = x;
  p.mass = Eigen::VectorXd::Constant(x.size(), mass);
  p.external_force = Eigen::VectorXd::Zero(x.size());
  p.fixed.assign(x.size(), 0);
  return p;
}

}  // namespace

TEST(Pbd, ConstraintGradientsMatchFiniteDifferencesAtRandomStates) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    Eigen::VectorXd x(12);
    for (int i = 0; i < 12; ++i) x[i] = u(rng);
    Constraint s{ConstraintType::stretch, {0, 1, 0, 0}, 0.3, 0.0, Vec3::Zero()};
    Constraint d{ConstraintType::dihedral, {0, 1, 2, 3}, 2.0, 0.0, Vec3::Zero()};
    Constraint a{ConstraintType::angle, {2, 3, 0, 0}, 0.4, 0.0, Vec3(u(rng), u(rng), u(rng))};
    expect_gradient_matches(s, x);
    expect_gradient_matches(d, x);
    expect_gradient_matches(a, x);
  }
}

TEST(Pbd, XpbdUpdateReproducesTheSeedsClosedFormCorrections) {
  // Equal masses, compliance 0, one iteration from rest: the generic update must give seed 002's
  // Δp_i = −Δp_j for the stretching and the simplified angle constraints.
  SpringNetwork empty;
  empty.nodes = {Vec3::Zero(), Vec3::Zero()};
  const SpringModel model(empty);
  const Vec3 pi(1.0, 0.2, -0.1), pj(0.1, -0.3, 0.4);
  Eigen::VectorXd x(6);
  x << pi, pj;
  const Problem p = free_problem(model, x, 0.7);
  PbdOptions o;
  o.steps = 1;
  o.iterations = 1;
  {
    const Constraint c{ConstraintType::stretch, {0, 1, 0, 0}, 0.5, 0.0, Vec3::Zero()};
    const PbdResult r = run_pbd(p, {c}, o);
    const Vec3 expected = seed002_stretch_correction(pi, pj, 0.5);
    EXPECT_LT((Vec3(r.x.head<3>()) - pi - expected).norm(), 1e-14);
    EXPECT_LT((Vec3(r.x.tail<3>()) - pj + expected).norm(), 1e-14);
    EXPECT_NEAR((r.x.head<3>() - r.x.tail<3>()).norm(), 0.5, 1e-14);  // satisfied in one step
  }
  {
    const Vec3 f(0.0, 0.0, -2.0);
    const Constraint c{ConstraintType::angle, {0, 1, 0, 0}, 1.2, 0.0, f};
    const PbdResult r = run_pbd(p, {c}, o);
    const Vec3 expected = seed002_angle_correction(pi, pj, f, 1.2);
    EXPECT_LT((Vec3(r.x.head<3>()) - pi - expected).norm(), 1e-12);
    EXPECT_LT((Vec3(r.x.tail<3>()) - pj + expected).norm(), 1e-12);
  }
}

TEST(Pbd, DihedralConstraintIsZeroAtRestAndRestoresABentPair) {
  // Two triangles hinged on the edge 0-1 at 120°.
  SpringNetwork net;
  net.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -0.5, std::sqrt(3.0) / 2)};
  net.triangles = {{0, 1, 2}, {1, 0, 3}};
  const auto cs = build_pbd_constraints(net, {}, {false, true, false, 0.0, 0.0});
  ASSERT_EQ(cs.size(), 1u);
  const Eigen::VectorXd x0 = flatten(net.nodes);
  EXPECT_NEAR(evaluate(cs[0], x0).C, 0.0, 1e-14);
  // Fold node 3 further, hold the hinge, and project (rigid, compliance 0).
  const SpringModel model(net);
  Problem p = free_problem(model, x0, 1.0);
  Eigen::VectorXd x = x0;
  x.segment<3>(9) = Vec3(0.5, -0.2, 0.98);
  for (int i = 0; i < 6; ++i) p.fixed[i] = 1;
  PbdOptions o;
  o.steps = 1;
  o.iterations = 50;
  const PbdResult r = run_pbd(p, cs, o, x);
  EXPECT_GT(std::abs(evaluate(cs[0], x).C), 0.1);
  EXPECT_NEAR(evaluate(cs[0], r.x).C, 0.0, 1e-8);
}

TEST(Pbd, XpbdStiffnessIsPhysicalAndIndependentOfTheIterationCount) {
  // Chain along x, node 0 fixed, y and z fixed; compliance 1/k_i; end force F; damped to rest:
  // the elongation is Hooke's F·Σ 1/k_i once each step's Gauss–Seidel solve has converged (4 or
  // 20 iterations agree to 1e-4). Measured: one iteration per step is 12 % too soft on this chain,
  // so "independent of the iteration count" holds only for converged iterations.
  const std::vector<double> k{10.0, 41.106, 25.0};
  const double F = 0.05;
  SpringNetwork net;
  for (int i = 0; i < 4; ++i) net.nodes.push_back(Vec3(1e-3 * i, 0, 0));
  const SpringModel model(net);
  Problem p = free_problem(model, flatten(net.nodes), 1e-4);
  for (int i = 0; i < 4; ++i) p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
  p.fixed[0] = 1;
  p.external_force[9] = F;
  std::vector<Constraint> cs;
  for (int i = 0; i < 3; ++i) {
    cs.push_back({ConstraintType::stretch, {i, i + 1, 0, 0}, 1e-3, 1.0 / k[i], Vec3::Zero()});
  }
  const double expected = F * (1 / k[0] + 1 / k[1] + 1 / k[2]);
  for (int iterations : {1, 4, 20}) {
    PbdOptions o;
    o.dt = 1e-3;
    o.steps = 20000;
    o.iterations = iterations;
    o.velocity_damping = 0.02;
    const PbdResult r = run_pbd(p, cs, o);
    const double ratio = (r.x[9] - p.rest[9]) / expected;
    std::printf("XPBD chain, %2d iterations per step: elongation / Hooke = %.6f\n", iterations,
                ratio);
    if (iterations == 1) {
      EXPECT_GT(ratio, 1.05);  // under-converged: softer
    } else {
      EXPECT_NEAR(ratio, 1.0, 1e-4) << iterations << " iterations";
    }
  }
  PbdOptions bad;
  bad.dt = -1;
  EXPECT_THROW((void)run_pbd(p, cs, bad), InputError);
}

TEST(Pbd, NonFiniteStateStopsWithStepAndNode) {
  SpringNetwork net;
  net.nodes = {Vec3::Zero(), Vec3(1e-3, 0, 0)};
  const SpringModel model(net);
  Problem p = free_problem(model, flatten(net.nodes), 1e-4);
  p.external_force[3] = std::numeric_limits<double>::infinity();
  const std::vector<Constraint> cs{
      {ConstraintType::stretch, {0, 1, 0, 0}, 1e-3, 0.1, Vec3::Zero()}};
  PbdOptions o;
  o.steps = 10;
  try {
    (void)run_pbd(p, cs, o);
    FAIL() << "expected DivergenceError";
  } catch (const DivergenceError& e) {
    EXPECT_EQ(e.step, 1);
    EXPECT_TRUE(e.node == 0 || e.node == 1);
  }
}
