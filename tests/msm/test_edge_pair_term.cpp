// The edge-pair term (Kikuuwe et al. 2009's edge-based StVK tetrahedron): its energy against StVK
// computed from the deformation gradient, its derivatives against finite differences, its
// stiffness at rest against P1's element stiffness from the shape-function gradients (derived
// here independently), the P1 patch test on a block of tets (which a spring network fails), and
// the network options' refusals.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <random>

#include "finite_differences.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/model/roi.hpp"
#include "msm/solvers/solve.hpp"
#include "tests/fem/cube_mesh.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kE = 14.24e3;

/// A scalene tet of about 1 mm, positively oriented.
std::array<Vec3, 4> rest_tet() {
  return {Vec3(0, 0, 0), Vec3(1.1e-3, 0.1e-3, -0.05e-3), Vec3(0.3e-3, 0.9e-3, 0.1e-3),
          Vec3(0.2e-3, 0.25e-3, 1.2e-3)};
}

std::array<Vec3, 4> deformed(const std::array<Vec3, 4>& X, std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  std::array<Vec3, 4> x = X;
  for (Vec3& p : x) p += Vec3(u(rng), u(rng), u(rng));
  return x;
}

Eigen::Matrix3d edge_matrix(const std::array<Vec3, 4>& x) {
  Eigen::Matrix3d D;
  D << x[1] - x[0], x[2] - x[0], x[3] - x[0];
  return D;
}

/// StVK from the deformation gradient F = d·D⁻¹: V₀(μ E:E + ½λ (tr E)²), E = ½(FᵀF − I).
double stvk_energy(const std::array<Vec3, 4>& x, const std::array<Vec3, 4>& X,
                   const LameParameters& m) {
  const Eigen::Matrix3d D = edge_matrix(X);
  const Eigen::Matrix3d F = edge_matrix(x) * D.inverse();
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  const double v0 = std::abs(D.determinant()) / 6.0;
  return v0 * (m.mu * (E.array() * E.array()).sum() + 0.5 * m.lambda * E.trace() * E.trace());
}

/// P1's element stiffness V·Bᵀ·C·B from the barycentric gradients ∇N_a (rows of D⁻¹ for nodes
/// 1–3, minus their sum for node 0) and the isotropic tensor in engineering Voigt notation.
Mat12 p1_element_stiffness(const std::array<Vec3, 4>& X, const LameParameters& m) {
  const Eigen::Matrix3d Dinv = edge_matrix(X).inverse();
  std::array<Vec3, 4> grad;
  for (int a = 1; a < 4; ++a) grad[a] = Dinv.row(a - 1).transpose();
  grad[0] = -(grad[1] + grad[2] + grad[3]);
  Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
  for (int a = 0; a < 4; ++a) {
    const Vec3& g = grad[a];
    const int c = 3 * a;
    B(0, c) = g.x();
    B(1, c + 1) = g.y();
    B(2, c + 2) = g.z();
    B(3, c + 1) = g.z();  // γ_yz
    B(3, c + 2) = g.y();
    B(4, c) = g.z();  // γ_xz
    B(4, c + 2) = g.x();
    B(5, c) = g.y();  // γ_xy
    B(5, c + 1) = g.x();
  }
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  C.topLeftCorner<3, 3>().setConstant(m.lambda);
  for (int i = 0; i < 3; ++i) C(i, i) += 2 * m.mu;
  for (int i = 3; i < 6; ++i) C(i, i) = m.mu;
  const double v = std::abs(edge_matrix(X).determinant()) / 6.0;
  return v * B.transpose() * C * B;
}

Eigen::VectorXd stacked(const std::array<Vec3, 4>& x) {
  Eigen::VectorXd v(12);
  for (int a = 0; a < 4; ++a) v.segment<3>(3 * a) = x[a];
  return v;
}

/// The network's problem at rest: unit-ish masses, no load, nothing held.
Problem problem_at_rest(const Form& form, const SpringNetwork& network) {
  Problem p;
  p.form = &form;
  p.rest = flatten(network.nodes);
  p.mass = Eigen::VectorXd::Constant(p.rest.size(), 1e-6);
  p.external_force = Eigen::VectorXd::Zero(p.rest.size());
  p.fixed.assign(static_cast<std::size_t>(p.rest.size()), 0);
  return p;
}

NetworkOptions edge_pair_options(double nu) {
  NetworkOptions o;
  o.model = ModelType::volume;
  o.stiffness_params.youngs_modulus = kE;
  o.stiffness_params.poisson_ratio = nu;
  o.edge_pairs = true;
  return o;
}

}  // namespace

TEST(EdgePairTerm, LameParametersByHand) {
  const LameParameters m = lame_parameters(kE, 0.3);
  EXPECT_NEAR(m.lambda, kE * 0.3 / (1.3 * 0.4), 1e-9 * kE);
  EXPECT_NEAR(m.mu, kE / 2.6, 1e-9 * kE);
  EXPECT_DOUBLE_EQ(lame_parameters(kE, 0.0).lambda, 0.0);
  EXPECT_THROW((void)lame_parameters(kE, 0.5), InputError);
  EXPECT_THROW((void)lame_parameters(kE, -0.1), InputError);
  EXPECT_THROW((void)lame_parameters(0.0, 0.3), InputError);
}

TEST(EdgePairTerm, EnergyIsStVenantKirchhoffOfTheDeformationGradient) {
  const auto X = rest_tet();
  std::mt19937 rng(7);
  for (double nu : {0.0, 0.25, 0.45, 0.49}) {
    const LameParameters m = lame_parameters(kE, nu);
    const Mat6 C = edge_pair_coefficients(X, m);
    // Large deformations too (20 % of the edge): the identity is exact, not a linearisation.
    for (double amplitude : {1e-6, 0.2e-3}) {
      const auto x = deformed(X, rng, amplitude);
      const double expected = stvk_energy(x, X, m);
      EXPECT_NEAR(edge_pair_energy(x, X, C), expected, 1e-10 * expected) << "ν " << nu;
    }
    // A rigid rotation stores nothing.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    std::array<Vec3, 4> rotated;
    for (int a = 0; a < 4; ++a) rotated[a] = R * X[a] + Vec3(1e-3, 0, 0);
    EXPECT_NEAR(edge_pair_energy(rotated, X, C), 0.0, 1e-12 * stvk_energy(deformed(X, rng, 1e-4), X, m));
  }
}

TEST(EdgePairTerm, KernelMatchesFiniteDifferences) {
  const auto X = rest_tet();
  std::mt19937 rng(11);
  for (double nu : {0.0, 0.45}) {
    const Mat6 C = edge_pair_coefficients(X, lame_parameters(kE, nu));
    const std::array<Vec3, 4> corners = deformed(X, rng, 0.1e-3);
    const Eigen::VectorXd x = stacked(corners);
    using Corners = std::array<Vec3, 4>;
    const auto c = msm::test::check_element_derivatives(
        [&](const Corners& y) { return edge_pair_energy(y, X, C); },
        [&](const Corners& y) { return edge_pair_gradient(y, X, C); },
        [&](const Corners& y) { return edge_pair_hessian(y, X, C, false); }, x, 1e-9);
    EXPECT_LT(c.gradient_error, 1e-6) << "ν " << nu;
    EXPECT_LT(c.hessian_error, 1e-6) << "ν " << nu;
    EXPECT_LT(c.hessian_asymmetry, 1e-12) << "ν " << nu;
    // Forces along the edges sum to zero (translation invariance).
    const Vec12 g = edge_pair_gradient(corners, X, C);
    EXPECT_LT((g.segment<3>(0) + g.segment<3>(3) + g.segment<3>(6) + g.segment<3>(9)).norm(),
              1e-12 * g.norm());
  }
  // Compressed: the Hessian can be indefinite; the projection is PSD.
  const Mat6 C = edge_pair_coefficients(X, lame_parameters(kE, 0.3));
  std::array<Vec3, 4> squashed = X;
  squashed[3] = 0.3 * X[3] + 0.7 * X[0];
  const Mat12 P = edge_pair_hessian(squashed, X, C, true);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat12>(P).eigenvalues().minCoeff(), -1e-9 * P.norm());
}

TEST(EdgePairTerm, StiffnessAtRestIsP1ElementStiffness) {
  const auto X = rest_tet();
  for (double nu : {0.0, 0.3, 0.49}) {
    const LameParameters m = lame_parameters(kE, nu);
    const Mat12 K = p1_element_stiffness(X, m);
    const Mat12 H = edge_pair_hessian(X, X, edge_pair_coefficients(X, m), false);
    EXPECT_LT((H - K).norm(), 1e-10 * K.norm()) << "ν " << nu;
  }
}

TEST(EdgePairTerm, PassesThePatchTestWhichSpringsFail) {
  // A 2 mm block of 3³ cubes (Kuhn tets) with its interior nodes jittered by up to 10 % of a cube
  // (an irregular mesh: on the regular Kuhn lattice an affine field is an equilibrium of any
  // spring network by symmetry), every boundary node moved by a small affine field u = G·X, the
  // interior free: P1 reproduces the affine field exactly at the interior nodes; so must the
  // edge-pair model, at every ν. A van-gelder spring network does not.
  TetMesh mesh = vessel::test::cube_mesh(3, 2e-3);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> jitter(-0.1 * 2e-3 / 3, 0.1 * 2e-3 / 3);
  for (Vec3& n : mesh.nodes) {
    const bool boundary = (n.array() < 1e-9).any() || (n.array() > 2e-3 - 1e-9).any();
    if (!boundary) n += Vec3(jitter(rng), jitter(rng), jitter(rng));
  }
  Eigen::Matrix3d G;
  G << 1e-3, 2e-4, -3e-4, 0.5e-4, -4e-4, 1e-4, 2e-4, 3e-4, 6e-4;
  auto interior_error = [&](const NetworkOptions& o) {
    const BuiltNetwork built = build_network(mesh, VesselParams{}, o);
    const auto model = make_model(built);
    Problem p = problem_at_rest(*model, built.network);
    Eigen::VectorXd affine = p.rest;
    std::vector<int> interior;
    for (std::size_t i = 0; i < built.network.nodes.size(); ++i) {
      const Vec3& n = built.network.nodes[i];
      affine.segment<3>(3 * i) += G * n;
      const bool boundary = (n.array() < 1e-9).any() || (n.array() > 2e-3 - 1e-9).any();
      if (boundary) {
        p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
        p.rest.segment<3>(3 * i) = affine.segment<3>(3 * i);  // held where the field puts it
      } else {
        interior.push_back(static_cast<int>(i));
      }
    }
    // The solver starts from p.rest (boundary already moved) and holds fixed dofs there; the
    // energy is measured from the network's own rest shape inside the model.
    const Eigen::VectorXd x = solve(p, parse_solver("static")).x;
    double err = 0.0, ref = 0.0;
    for (int i : interior) {
      err = std::max(err, (x.segment<3>(3 * i) - affine.segment<3>(3 * i)).norm());
      ref = std::max(ref, (G * built.network.nodes[i]).norm());
    }
    return err / ref;
  };
  ASSERT_GE(mesh.nodes.size(), 64u);
  for (double nu : {0.0, 0.25, 0.45, 0.49}) {
    EXPECT_LT(interior_error(edge_pair_options(nu)), 1e-6) << "ν " << nu;
  }
  NetworkOptions springs;
  springs.model = ModelType::volume;
  springs.stiffness = StiffnessRule::van_gelder;
  springs.stiffness_params.youngs_modulus = kE;
  springs.stiffness_params.poisson_ratio = 0.25;
  EXPECT_GT(interior_error(springs), 1e-3);
}

TEST(EdgePairTerm, NetworkReplacesTheSpringsAndSumsToFiniteDifferences) {
  const TetMesh mesh = vessel::test::cube_mesh(2, 2e-3);
  const BuiltNetwork built = build_network(mesh, VesselParams{}, edge_pair_options(0.1));
  EXPECT_TRUE(built.network.springs.empty());
  ASSERT_TRUE(built.terms.edge_pairs.has_value());
  EXPECT_NEAR(built.terms.edge_pairs->mu, kE / 2.2, 1e-9 * kE);
  // Masses as the springs' network of the same tets has them.
  NetworkOptions plain = edge_pair_options(0.1);
  plain.edge_pairs = false;
  const BuiltNetwork springs = build_network(mesh, VesselParams{}, plain);
  ASSERT_EQ(built.masses.size(), springs.masses.size());
  for (std::size_t i = 0; i < built.masses.size(); ++i) {
    EXPECT_DOUBLE_EQ(built.masses[i], springs.masses[i]);
  }
  const auto model = make_model(built);
  ASSERT_NE(model->term<EdgePairTerm>(), nullptr);
  EXPECT_EQ(plain_spring_model(*model), nullptr);
  std::mt19937 rng(5);
  Eigen::VectorXd x = flatten(built.network.nodes);
  std::uniform_real_distribution<double> u(-0.05e-3, 0.05e-3);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += u(rng);
  const auto c = msm::test::check_form_derivatives(*model, x, 1e-9);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
  EXPECT_GT(model->max_strain(x), 0.0);
}

TEST(EdgePairTerm, RefusesWhatItCannotBe) {
  const TetMesh mesh = vessel::test::cube_mesh(1, 1e-3);
  NetworkOptions o = edge_pair_options(0.5);
  EXPECT_THROW((void)build_network(mesh, VesselParams{}, o), InputError);
  o = edge_pair_options(0.3);
  o.volume_term = true;
  o.stiffness = StiffnessRule::van_gelder;
  EXPECT_THROW((void)build_network(mesh, VesselParams{}, o), InputError);
  o = edge_pair_options(0.3);
  std::array<Vec3, 4> flat = rest_tet();
  flat[3] = flat[1] + flat[2] - flat[0];  // coplanar
  EXPECT_THROW((void)edge_pair_coefficients(flat, lame_parameters(kE, 0.3)), InputError);
}

TEST(EdgePairTerm, RegionOfInterestSolvesWhatTheWholeModelSolvesWithTheSameNodesHeld) {
  // A 3 mm block, base fixed, a small load on the top face; nodes with x > 2 mm held. The region
  // of interest (restrict_network, restrict_problem) must give, at its nodes, what the whole
  // model gives with the same nodes fixed. The edge-pair model has no springs, so the region
  // finds the held nodes that bound its moving tets through the tets themselves.
  const TetMesh mesh = vessel::test::cube_mesh(3, 3e-3);
  const BuiltNetwork built = build_network(mesh, VesselParams{}, edge_pair_options(0.45));
  const auto model = make_model(built);
  Problem full = problem_at_rest(*model, built.network);
  std::vector<char> held(built.network.nodes.size(), 0);
  for (std::size_t i = 0; i < built.network.nodes.size(); ++i) {
    const Vec3& n = built.network.nodes[i];
    if (n.z() < 1e-9) full.fixed[3 * i] = full.fixed[3 * i + 1] = full.fixed[3 * i + 2] = 1;
    if (n.z() > 3e-3 - 1e-9) full.external_force[3 * i + 2] = -1e-6;  // N
    held[i] = n.x() > 2e-3 + 1e-9 || n.z() < 1e-9;
  }
  Problem whole = full;
  for (std::size_t i = 0; i < held.size(); ++i) {
    if (held[i]) whole.fixed[3 * i] = whole.fixed[3 * i + 1] = whole.fixed[3 * i + 2] = 1;
  }
  const SolveResult a = solve(whole, parse_solver("static"));
  const RoiNetwork roi = restrict_network(built.network, held);
  std::size_t moving_tets = 0;
  for (const Tet& t : built.network.tets) {
    moving_tets += !(held[t[0]] && held[t[1]] && held[t[2]] && held[t[3]]);
  }
  EXPECT_EQ(roi.network.tets.size(), moving_tets);
  const auto roi_model = make_model(roi.network, {.edge_pairs = built.terms.edge_pairs});
  const Problem part = restrict_problem(full, roi, held, *roi_model);
  const SolveResult b = solve(part, parse_solver("static"));
  const double u = (a.x - whole.rest).lpNorm<Eigen::Infinity>();
  ASSERT_GT(u, 0.0);
  for (std::size_t k = 0; k < roi.full_index.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(roi.full_index[k]);
    EXPECT_LT((b.x.segment<3>(3 * static_cast<Eigen::Index>(k)) - a.x.segment<3>(3 * i)).norm(),
              1e-8 * u)
        << "node " << i;
  }
}
