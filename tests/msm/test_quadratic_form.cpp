// QuadraticForm (a linear body given by its stiffness matrix: how the harness times FEM with the
// mass-spring models' updaters): derivatives against finite differences, and the linear and
// static updaters on it against a second solver (Eigen's LDLT of K).
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "meshes/foundation/errors.hpp"
#include "msm/form/quadratic_form.hpp"
#include "msm/solvers/updates.hpp"
#include "tests/msm/finite_differences.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// A sparse SPD stiffness: a 1D chain of springs k = 40 N/m fixed at both ends, plus random
/// symmetric couplings made diagonally dominant.
SparseMatrix chain_stiffness(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<Eigen::Triplet<double>> t;
  std::vector<double> diag(static_cast<std::size_t>(n), 80.0);
  for (int i = 0; i + 1 < n; ++i) {
    t.emplace_back(i, i + 1, -40.0);
    t.emplace_back(i + 1, i, -40.0);
  }
  for (int k = 0; k < n; ++k) {
    const int i = pick(rng), j = pick(rng);
    if (i == j) continue;
    const double v = u(rng);
    t.emplace_back(i, j, -v);
    t.emplace_back(j, i, -v);
    diag[static_cast<std::size_t>(i)] += v;
    diag[static_cast<std::size_t>(j)] += v;
  }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diag[static_cast<std::size_t>(i)]);
  SparseMatrix K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

}  // namespace

TEST(QuadraticForm, DerivativesMatchFiniteDifferences) {
  const int n = 30;
  const SparseMatrix K = chain_stiffness(n, 3);
  const VectorXd x0 = VectorXd::LinSpaced(n, 0.0, 1e-2);
  const QuadraticForm form(K, x0);
  std::mt19937 rng(7);
  std::normal_distribution<double> d(0.0, 1e-4);
  VectorXd x = x0;
  for (Eigen::Index i = 0; i < n; ++i) x[i] += d(rng);
  const auto c = test::check_form_derivatives(form, x, 1e-7);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
  EXPECT_LT(c.hessian_asymmetry, 1e-14);
  EXPECT_NEAR(form.energy(x0), 0.0, 1e-300);
}

TEST(QuadraticForm, LinearAndStaticUpdatesSolveKuEqualsF) {
  // A load on five dofs: the linear updater superposes the responses it prepared for them; a
  // load elsewhere is solved with its factor; static Newton on a quadratic energy stops at once.
  // Each against Eigen's LDLT of K.
  const int n = 200;
  const SparseMatrix K = chain_stiffness(n, 11);
  const QuadraticForm form(K, VectorXd::Zero(n));
  Problem p;
  p.form = &form;
  p.rest = VectorXd::Zero(n);
  p.mass = VectorXd::Ones(n);
  p.fixed.assign(static_cast<std::size_t>(n), 0);
  p.external_force = VectorXd::Zero(n);
  for (int i = 90; i < 95; ++i) p.external_force[i] = 1e-3 * (i - 88);
  const Eigen::SimplicialLDLT<SparseMatrix> ldlt(K);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  VectorXd elsewhere = p.external_force;
  elsewhere[10] = 2e-3;
  for (const char* name : {"linear", "static"}) {
    const auto up = prepare_updates(p, parse_solver(name));
    const std::vector<std::pair<VectorXd, bool>> loads{{0.5 * p.external_force, true},
                                                        {elsewhere, false}};
    for (const auto& [f, on_prepared_dofs] : loads) {
      const UpdateResult r = up->update(f);
      const VectorXd u = ldlt.solve(f);
      EXPECT_LT((up->state() - u).norm(), 1e-8 * u.norm()) << name;
      if (std::string(name) == "linear") EXPECT_EQ(r.superposed, on_prepared_dofs) << name;
      EXPECT_LE(r.iterations, 2) << name;
      EXPECT_EQ(r.factorisations, 0) << name;
    }
  }
}

TEST(QuadraticForm, RefusesAStiffnessOfAnotherSize) {
  EXPECT_THROW(QuadraticForm(chain_stiffness(5, 1), VectorXd::Zero(4)), InputError);
  EXPECT_THROW(QuadraticForm(SparseMatrix(4, 5), VectorXd::Zero(4)), InputError);
}
