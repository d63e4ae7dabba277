// Natural frequencies of mass-spring models (msm/dynamics/natural_frequencies): closed forms of
// spring–mass chains (fixed–fixed, fixed–free), a hand-derived two-mass system with unequal
// masses, zero-frequency mechanisms, and the hybrid volume model against a second solver (Eigen's
// dense generalised eigensolver on the Form's own K and M).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

#include "meshes/foundation/errors.hpp"
#include "msm/dynamics/natural_frequencies.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/terms/spring_model.hpp"
#include "tests/fixtures/kuhn_block.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kPi = std::numbers::pi;

/// Nodes 0..n+1 on the x axis 1 m apart, a Hooke spring k between neighbours, mass m_i per node;
/// y and z of every node held (the chain moves along x only), x of node 0 held, and x of node
/// n+1 held (fixed–fixed) or node n+1 absent (fixed–free: node n is the free end).
struct Chain {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

Chain make_chain(int n, double k, const std::vector<double>& masses, bool fixed_far_end,
                 bool hold_y = true) {
  Chain c;
  const int nodes = fixed_far_end ? n + 2 : n + 1;
  for (int i = 0; i < nodes; ++i) c.net.nodes.emplace_back(static_cast<double>(i), 0.0, 0.0);
  for (int i = 0; i + 1 < nodes; ++i) {
    Spring s;
    s.a = i;
    s.b = i + 1;
    s.rest_length = 1.0;
    s.law = {k, k};
    c.net.springs.push_back(s);
  }
  c.model = std::make_unique<SpringModel>(c.net, 0.0);
  Problem& p = c.problem;
  p.form = c.model.get();
  p.rest = flatten(c.net.nodes);
  p.mass.resize(3 * nodes);
  for (int i = 0; i < nodes; ++i) {
    // masses[i − 1] for the moving nodes 1..n; the held ends get 1 kg (never used).
    const double m = (i >= 1 && i <= n) ? masses[static_cast<std::size_t>(i - 1)] : 1.0;
    p.mass.segment<3>(3 * i).setConstant(m);
  }
  p.external_force = Eigen::VectorXd::Zero(3 * nodes);
  p.fixed.assign(static_cast<std::size_t>(3 * nodes), 0);
  for (int i = 0; i < nodes; ++i) {
    if (hold_y) p.fixed[3 * i + 1] = 1;
    p.fixed[3 * i + 2] = 1;
  }
  p.fixed[0] = p.fixed[1] = p.fixed[2] = 1;
  if (fixed_far_end) p.fixed[3 * (nodes - 1)] = p.fixed[3 * (nodes - 1) + 1] = 1;
  return c;
}

/// Fixed–fixed chain of n equal masses m and n + 1 springs k: the eigenvalues of the tridiagonal
/// (k/m)·[2, −1] matrix, ω_j = 2√(k/m)·sin(jπ/(2(n + 1))).
double fixed_fixed_omega(int j, int n, double k, double m) {
  return 2.0 * std::sqrt(k / m) * std::sin(j * kPi / (2.0 * (n + 1)));
}

/// Fixed–free chain of n masses and n springs (last diagonal entry 1 instead of 2):
/// ω_j = 2√(k/m)·sin((2j − 1)π/(2(2n + 1))).
double fixed_free_omega(int j, int n, double k, double m) {
  return 2.0 * std::sqrt(k / m) * std::sin((2 * j - 1) * kPi / (2.0 * (2 * n + 1)));
}

}  // namespace

TEST(NaturalFrequencies, FixedFixedChainMatchesClosedFormWithLanczos) {
  const int n = 60;
  const double k = 41.106, m = 2.5e-4;  // seed 000's spring and a small node mass
  const Chain c = make_chain(n, k, std::vector<double>(n, m), true);
  NaturalFrequencyOptions o;
  o.count = 8;
  o.dense_max_dofs = 0;  // Spectra's shift-invert Lanczos, not the dense path
  const NaturalFrequencies f = natural_frequencies(c.problem, o);
  EXPECT_EQ(f.free_dofs, n);
  EXPECT_GT(f.iterations, 0);
  EXPECT_LT(f.shift, 0.0);
  EXPECT_EQ(f.mechanisms, 0);
  ASSERT_EQ(f.omega.size(), 8u);
  for (int j = 1; j <= 8; ++j) {
    const double exact = fixed_fixed_omega(j, n, k, m);
    EXPECT_NEAR(f.omega[j - 1], exact, 1e-8 * exact) << "mode " << j;
    EXPECT_NEAR(f.frequencies_hz[j - 1], exact / (2 * kPi), 1e-8 * exact);
  }
  // Shapes: K φ = ω² M φ and φᵀ M φ = 1 on the free dofs.
  SparseMatrix K;
  c.model->hessian(c.problem.rest, K, false);
  for (int e = 0; e < 8; ++e) {
    Eigen::VectorXd phi = f.shapes.col(e);
    Eigen::VectorXd r = K * phi - f.omega[e] * f.omega[e] * c.problem.mass.cwiseProduct(phi);
    for (int i = 0; i < r.size(); ++i) {
      if (c.problem.fixed[i]) r[i] = 0.0;
    }
    EXPECT_LT(r.norm(), 1e-7 * (K * phi).norm() + 1e-12);
    EXPECT_NEAR(phi.dot(c.problem.mass.cwiseProduct(phi)), 1.0, 1e-9);
  }
}

TEST(NaturalFrequencies, FixedFreeChainMatchesClosedFormDenseAndLanczos) {
  const double k = 10.0, m = 0.1;
  for (const int n : {9, 300}) {  // dense path (9 dofs) and Lanczos (300)
    const Chain c = make_chain(n, k, std::vector<double>(n, m), false);
    NaturalFrequencyOptions o;
    o.count = 5;
    const NaturalFrequencies f = natural_frequencies(c.problem, o);
    EXPECT_EQ(f.iterations == 0, n <= o.dense_max_dofs);
    for (int j = 1; j <= 5; ++j) {
      const double exact = fixed_free_omega(j, n, k, m);
      EXPECT_NEAR(f.omega[j - 1], exact, 1e-8 * exact) << "n " << n << ", mode " << j;
    }
  }
}

TEST(NaturalFrequencies, UnequalMassesByHand) {
  // Wall – k – m – k – 2m – k – wall: det(K − ω²M) = 0 with K = k[[2, −1], [−1, 2]],
  // M = m·diag(1, 2): with x = ω²m/k, (2 − x)(2 − 2x) − 1 = 2x² − 6x + 3 = 0, x = (3 ∓ √3)/2.
  const double k = 3.0, m = 0.02;
  const Chain c = make_chain(2, k, {m, 2 * m}, true);
  NaturalFrequencyOptions o;
  o.count = 1;  // the lower root (count < free dofs = 2)
  const NaturalFrequencies f = natural_frequencies(c.problem, o);
  EXPECT_NEAR(f.omega[0] * f.omega[0] * m / k, (3 - std::sqrt(3.0)) / 2, 1e-12);
  // Both roots through a mechanism-free three-dof variant would need a new closed form; the
  // mass scaling M^{-1/2} K M^{-1/2} is what this checks (equal masses would give x = 1).
}

TEST(NaturalFrequencies, MechanismsShowAsZeroFrequencies) {
  // The chain with y free: a straight spring has no transverse stiffness at rest, so each of
  // the n interior nodes adds one zero-frequency mode; the shift keeps K − σM factorisable and the
  // axial modes follow the zeros unchanged.
  const int n = 40;
  const double k = 5.0, m = 0.01;
  const Chain c = make_chain(n, k, std::vector<double>(n, m), true, /*hold_y=*/false);
  NaturalFrequencyOptions o;
  o.count = n + 3;
  o.dense_max_dofs = 0;
  const NaturalFrequencies f = natural_frequencies(c.problem, o);
  EXPECT_EQ(f.free_dofs, 2 * n);
  EXPECT_EQ(f.mechanisms, n);
  for (int e = 0; e < n; ++e) EXPECT_LT(f.omega[e], 1e-3 * std::sqrt(k / m));
  for (int j = 1; j <= 3; ++j) {
    const double exact = fixed_fixed_omega(j, n, k, m);
    EXPECT_NEAR(f.omega[n + j - 1], exact, 1e-7 * exact) << "axial mode " << j;
  }
}

TEST(NaturalFrequencies, HybridVolumeModelAgreesWithDenseGeneralisedSolver) {
  // A 3 × 3 × 4 mm block of Kuhn tets, base held, the hybrid volume model at ν = 0.45 (its volume
  // term in K) with consistent masses: Lanczos against Eigen's dense K x = ω² M x on the same
  // free-dof K and M; the springs-only model (κ dropped) is softer in every compared mode.
  TetMesh mesh = vessel::test::kuhn_block(3, 3, 4, 1e-3);
  NetworkOptions no;
  no.model = ModelType::volume;
  no.stiffness = StiffnessRule::van_gelder;
  no.stiffness_params.youngs_modulus = 14.24e3;
  no.stiffness_params.poisson_ratio = 0.45;
  no.volume_term = true;
  no.mass = MassRule::consistent;
  no.density = 1060.0;
  const BuiltNetwork built = build_network(mesh, VesselParams{}, no);
  ASSERT_TRUE(built.terms.volume_kappa.has_value());
  const auto hybrid = make_model(built);
  const auto springs = make_model(built.network);
  auto problem = [&](const Form& form) {
    Problem p;
    p.form = &form;
    p.rest = flatten(built.network.nodes);
    p.mass.resize(p.rest.size());
    for (std::size_t i = 0; i < built.masses.size(); ++i) {
      p.mass.segment<3>(3 * static_cast<Eigen::Index>(i)).setConstant(built.masses[i]);
    }
    p.external_force = Eigen::VectorXd::Zero(p.rest.size());
    p.fixed.assign(static_cast<std::size_t>(p.rest.size()), 0);
    for (std::size_t i = 0; i < built.network.nodes.size(); ++i) {
      if (built.network.nodes[i].z() < 1e-9) p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
    }
    return p;
  };
  const Problem ph = problem(*hybrid), ps = problem(*springs);
  NaturalFrequencyOptions o;
  o.count = 6;
  o.dense_max_dofs = 0;
  const NaturalFrequencies fh = natural_frequencies(ph, o);
  const NaturalFrequencies fs = natural_frequencies(ps, o);

  // Second solver: dense generalised eigenproblem on the free block of the Form's Hessian.
  SparseMatrix K;
  hybrid->hessian(ph.rest, K, false);
  std::vector<int> free;
  for (int i = 0; i < ph.num_dofs(); ++i) {
    if (!ph.fixed[i]) free.push_back(i);
  }
  const Eigen::MatrixXd Kd(K);
  const int nf = static_cast<int>(free.size());
  Eigen::MatrixXd Kf(nf, nf), Mf = Eigen::MatrixXd::Zero(nf, nf);
  for (int a = 0; a < nf; ++a) {
    Mf(a, a) = ph.mass[free[a]];
    for (int b = 0; b < nf; ++b) Kf(a, b) = Kd(free[a], free[b]);
  }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(Kf, Mf);
  ASSERT_EQ(fh.free_dofs, nf);
  for (int e = 0; e < 6; ++e) {
    const double w = std::sqrt(ges.eigenvalues()[e]);
    EXPECT_NEAR(fh.omega[e], w, 1e-7 * w) << "mode " << e;
    EXPECT_LT(fs.omega[e], fh.omega[e]) << "mode " << e;
  }
}

TEST(NaturalFrequencies, RefusesBadCounts) {
  const Chain c = make_chain(5, 1.0, std::vector<double>(5, 1.0), true);
  NaturalFrequencyOptions o;
  o.count = 0;
  EXPECT_THROW((void)natural_frequencies(c.problem, o), InputError);
  o.count = 5;  // = free dofs
  EXPECT_THROW((void)natural_frequencies(c.problem, o), InputError);
}
