/// The finite-strain reference: the neo-Hookean kernel against finite differences of its energy,
/// the assembled tangent against finite differences of the residual, the uniaxial stretch of a
/// cube (closed form) and Rivlin's closed form itself.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "cube_mesh.hpp"
#include "fem_reference/hyperelastic.hpp"
#include "fem_reference/rivlin.hpp"
#include "meshes/foundation/errors.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

constexpr double kE = 14.24e3;

Mat3 random_deformation(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Mat3 F = Mat3::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F(i, j) += u(rng);
  return F;
}

}  // namespace

TEST(NeoHookean, StressIsTheEnergysDerivativeAndTangentTheStresss) {
  Material m;
  m.poisson_ratio = 0.3;
  const NeoHookean nh = NeoHookean::of(m);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const Mat3 F = random_deformation(rng, 0.3);
    ASSERT_GT(F.determinant(), 0.0);
    const Mat3 P = nh.stress(F);
    const Mat9 A = nh.tangent(F);
    const double h = 1e-6;
    for (int b = 0; b < 3; ++b) {
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = F, Fm = F;
        Fp(b, L) += h;
        Fm(b, L) -= h;
        const double dpsi = (nh.energy(Fp) - nh.energy(Fm)) / (2 * h);
        EXPECT_NEAR(P(b, L), dpsi, 1e-6 * nh.mu);
        const Mat3 dP = (nh.stress(Fp) - nh.stress(Fm)) / (2 * h);
        for (int a = 0; a < 3; ++a)
          for (int J = 0; J < 3; ++J)
            EXPECT_NEAR(A(3 * a + J, 3 * b + L), dP(a, J), 1e-6 * nh.lambda);
      }
    }
  }
}

TEST(NeoHookean, LinearisesToLinearElasticityWithTheSameLame) {
  Material m;
  m.poisson_ratio = 0.3;
  const NeoHookean nh = NeoHookean::of(m);
  EXPECT_EQ(nh.energy(Mat3::Identity()), 0.0);
  EXPECT_NEAR(nh.stress(Mat3::Identity()).norm(), 0.0, 1e-12 * nh.mu);
  const Mat9 A = nh.tangent(Mat3::Identity());
  // C_aJbL = λ δ_aJ δ_bL + μ (δ_ab δ_JL + δ_aL δ_Jb)
  for (int a = 0; a < 3; ++a)
    for (int J = 0; J < 3; ++J)
      for (int b = 0; b < 3; ++b)
        for (int L = 0; L < 3; ++L) {
          const double c =
              nh.lambda * (a == J) * (b == L) + nh.mu * ((a == b) * (J == L) + (a == L) * (J == b));
          EXPECT_NEAR(A(3 * a + J, 3 * b + L), c, 1e-9 * nh.lambda);
        }
}

namespace {

/// A loaded cube: rollers on x0, y0, z0, follower pressure on x1, dead gravity.
ElasticityProblem cube_problem(double nu, int degree, Formulation f, double pressure) {
  ElasticityProblem p;
  p.material.poisson_ratio = nu;
  p.options.degree = degree;
  p.options.formulation = f;
  p.options.solver = LinearSolver::direct;
  p.dirichlet = {DirichletCondition::roller("x0", 0), DirichletCondition::roller("y0", 1),
                 DirichletCondition::roller("z0", 2)};
  if (pressure != 0.0) p.pressures = {{"x1", pressure}};
  return p;
}

/// max |K_ij − (R_i(u + h e_j) − R_i(u − h e_j))/2h| over all i, j, relative to max |K_ij|.
double tangent_fd_mismatch(const HyperelasticSolver& s, const std::vector<double>& u, double lf) {
  const auto K = s.tangent_columns(u, lf);
  double kmax = 0.0, err = 0.0;
  for (std::size_t j = 0; j < u.size(); ++j) {
    auto up = u, um = u;
    const double h = 1e-7 * std::max(1e-3, std::abs(u[j]));
    up[j] += h;
    um[j] -= h;
    const auto rp = s.residual(up, lf), rm = s.residual(um, lf);
    for (std::size_t i = 0; i < u.size(); ++i) {
      kmax = std::max(kmax, std::abs(K[j][i]));
      err = std::max(err, std::abs(K[j][i] - (rp[i] - rm[i]) / (2 * h)));
    }
  }
  return err / kmax;
}

/// Random DoF values: displacements up to `amplitude` (m), pressures up to `pressure` (Pa).
std::vector<double> random_state(const HyperelasticSolver& s, std::mt19937& rng, double amplitude,
                                 double pressure) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  const auto comp = s.dof_components();
  std::vector<double> u(s.n_dofs());
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = d(rng) * (comp[i] < 3 ? amplitude : pressure);
  return u;
}

}  // namespace

TEST(HyperelasticTangent, MatchesFiniteDifferencesOfTheResidual) {
  const double L = 1e-3;
  // Two cells per side for P1; one for P2 (81 DoFs: a finite-difference column per DoF).
  const TetMesh meshes[2] = {test::cube_mesh(2, L), test::cube_mesh(1, L)};
  std::mt19937 rng(3);
  struct Case {
    int degree;
    Formulation f;
    double nu;
    bool follower;
  };
  for (const Case c :
       {Case{1, Formulation::displacement, 0.3, true},
        Case{2, Formulation::displacement, 0.3, true},
        Case{1, Formulation::displacement, 0.3, false}, Case{2, Formulation::mixed, 0.45, true},
        Case{2, Formulation::mixed, 0.5, true}}) {
    ElasticityProblem p = cube_problem(c.nu, c.degree, c.f, 2000.0);
    p.gravity = Vec3(0, 0, -9.81 * 50);
    HyperelasticOptions o;
    o.follower_pressure = c.follower;
    HyperelasticSolver s(meshes[c.degree - 1], p, o);
    // Displacements of 5 % of the cube and pressures of the order of μ: well into finite strain.
    const auto u = random_state(s, rng, 0.05 * L, 0.5 * p.material.mu());
    const double mismatch = tangent_fd_mismatch(s, u, 0.8);
    std::cout << "  tangent vs FD: degree " << c.degree << " " << to_string(c.f) << " nu " << c.nu
              << (c.follower ? " follower" : " dead") << " pressure: max rel mismatch " << mismatch
              << "\n";
    EXPECT_LT(mismatch, 1e-6);
  }
}

namespace {

/// Uniaxial stress of compressible neo-Hookean, stretch l along x: the lateral stretch t solves
/// σ_yy = (μ(t² − 1) + λ ln(l t²))/J = 0 (bisection; σ_yy increases with t), and
/// σ_xx = μ(l² − t²)/J, J = l t² (Cauchy stress σ = (μ(B − I) + λ ln J I)/J).
struct Uniaxial {
  double lateral, cauchy;
};
Uniaxial uniaxial_stress(double l, double mu, double lambda) {
  double lo = 1e-3, hi = 10.0;
  for (int i = 0; i < 200; ++i) {
    const double t = 0.5 * (lo + hi);
    (mu * (t * t - 1) + lambda * std::log(l * t * t) < 0 ? lo : hi) = t;
  }
  const double t = 0.5 * (lo + hi);
  return {t, mu * (l * l - t * t) / (l * t * t)};
}

}  // namespace

TEST(HyperelasticCube, UniaxialStretchMatchesTheClosedForm) {
  // A homogeneous deformation is in every element's space, so the discrete solution is exact up
  // to the Newton tolerance: P1, P2 (compressible) and Taylor–Hood at ν = 0.5.
  const double L = 1e-3;
  const TetMesh mesh = test::cube_mesh(2, L);
  for (const double stretch : {1.5, 0.8}) {
    for (const auto& [degree, f, nu] :
         {std::tuple{1, Formulation::displacement, 0.3},
          std::tuple{2, Formulation::displacement, 0.3}, std::tuple{2, Formulation::mixed, 0.5}}) {
      Material m;
      m.poisson_ratio = nu;
      const double mu = m.mu(), lambda = m.lambda();
      // ν = 0.5: t = l^(−1/2) and σ = μ(l² − 1/l) (the λ → ∞ limit of the above).
      const Uniaxial exact = std::isinf(lambda) ? Uniaxial{1.0 / std::sqrt(stretch),
                                                           mu * (stretch * stretch - 1.0 / stretch)}
                                                : uniaxial_stress(stretch, mu, lambda);
      // The Cauchy traction σ_xx on the deformed face is a follower "pressure" −σ_xx.
      HyperelasticSolver s(mesh, cube_problem(nu, degree, f, -exact.cauchy));
      const auto& r = s.solve();
      ASSERT_TRUE(r.completed) << r.stop_reason;
      const Vec3 u = s.displacement_at({Vec3(L, L, L)})[0];
      const Vec3 expect((stretch - 1) * L, (exact.lateral - 1) * L, (exact.lateral - 1) * L);
      std::cout << "  uniaxial l=" << stretch << " " << r.element << " nu " << nu << ": steps "
                << r.steps.size() << " (rejected " << r.rejected_steps << "), Newton "
                << r.newton_iterations << ", |u - exact| / L = " << (u - expect).norm() / L << "\n";
      EXPECT_LT((u - expect).norm(), 1e-8 * L);
      EXPECT_GT(r.max_abs_principal_strain, 0.1);
    }
  }
}

TEST(RivlinTubeClosedForm, QuadratureOfTheEquilibriumIntegralMatchesTheClosedForm) {
  const RivlinTube t;
  for (double a_over_A : {1.01, 1.2, 1.5, 2.0, 4.0}) {
    const double a = a_over_A * t.inner_radius;
    const double closed = t.pressure(a), quad = t.pressure_by_quadrature(a);
    EXPECT_NEAR(quad, closed, 1e-10 * closed) << "a/A " << a_over_A;
    EXPECT_NEAR(t.inner_radius_at(closed), a, 1e-12 * a);
  }
  EXPECT_NEAR(t.pressure(t.inner_radius), 0.0, 1e-12 * t.shear_modulus);
  EXPECT_LT(t.pressure(100 * t.inner_radius), t.limit_pressure());
  EXPECT_THROW((void)t.inner_radius_at(t.limit_pressure()), std::domain_error);
  // Small pressure: the linear (Lamé, ν = 0.5) inner displacement u = P a b² / (2μ (b² − a²)).
  const double P = 1e-6 * t.shear_modulus;
  const double A = t.inner_radius, B = t.outer_radius;
  const double lame = P * A * B * B / (2 * t.shear_modulus * (B * B - A * A));
  EXPECT_NEAR(t.inner_radius_at(P) - A, lame, 1e-5 * lame);
}

namespace {

/// The stretch whose uniaxial Cauchy stress is `cauchy` (bisection on the closed form; the stress
/// grows with the stretch).
double stretch_at_cauchy(double cauchy, double mu, double lambda) {
  double lo = 0.3, hi = 3.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (uniaxial_stress(mid, mu, lambda).cauchy < cauchy ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

TEST(HyperelasticContinuation, CheckpointsMatchTheClosedFormAtEachLoad) {
  // One continuation to stretch 1.5 with checkpoints at a quarter and half the load: at each the
  // cube's corner sits where the closed form puts it for that Cauchy stress (the follower
  // traction scales with the load factor), and the observer reads the same state.
  const double L = 1e-3;
  const TetMesh mesh = test::cube_mesh(2, L);
  Material m;
  m.poisson_ratio = 0.3;
  const double mu = m.mu(), lambda = m.lambda();
  const Uniaxial full = uniaxial_stress(1.5, mu, lambda);
  HyperelasticOptions o;
  o.checkpoints = {0.25, 0.5, 1.0};
  HyperelasticSolver s(mesh, cube_problem(0.3, 1, Formulation::displacement, -full.cauchy), o);
  std::vector<Vec3> observed;
  const auto& r = s.solve([&](const HyperelasticSolver& at, const Checkpoint& c) {
    observed.push_back(at.displacement_at({Vec3(L, L, L)})[0]);
    EXPECT_EQ(c.load_steps, static_cast<int>(at.result().steps.size()));
    return std::string();
  });
  ASSERT_TRUE(r.completed) << r.stop_reason;
  ASSERT_EQ(r.checkpoints.size(), 3u);
  ASSERT_EQ(observed.size(), 3u);
  const std::size_t corner = mesh.nodes.size() - 1;  // (L, L, L)
  ASSERT_LT((mesh.nodes[corner] - Vec3(L, L, L)).norm(), 1e-15);
  for (std::size_t k = 0; k < 3; ++k) {
    const Checkpoint& c = r.checkpoints[k];
    EXPECT_DOUBLE_EQ(c.load_factor, o.checkpoints[k]);
    const double l = stretch_at_cauchy(c.load_factor * full.cauchy, mu, lambda);
    const double t = uniaxial_stress(l, mu, lambda).lateral;
    const Vec3 expect((l - 1) * L, (t - 1) * L, (t - 1) * L);
    EXPECT_LT((c.nodal_displacement[corner] - expect).norm(), 1e-8 * L) << "checkpoint " << k;
    EXPECT_LT((observed[k] - expect).norm(), 1e-8 * L) << "checkpoint " << k;
    if (k > 0) {
      EXPECT_GE(c.newton_iterations, r.checkpoints[k - 1].newton_iterations);
    }
  }
}

TEST(HyperelasticContinuation, AStepThatReachesACheckpointWithinRoundOffEndsOnIt) {
  // Ten steps of 0.1 sum to 0.9999999999999999: the last must still end on the checkpoint at 1
  // (and record it), not stop a round-off short of the target with no checkpoint there.
  const TetMesh mesh = test::cube_mesh(1, 1e-3);
  HyperelasticOptions o;
  o.initial_step = o.max_step = 0.1;
  o.checkpoints = {1.0};
  HyperelasticSolver s(mesh, cube_problem(0.3, 1, Formulation::displacement, -2000.0), o);
  const auto& r = s.solve([](const HyperelasticSolver&, const Checkpoint&) { return std::string(); });
  ASSERT_TRUE(r.completed) << r.stop_reason;
  ASSERT_EQ(r.checkpoints.size(), 1u);
  EXPECT_EQ(r.checkpoints[0].load_factor, 1.0);
  EXPECT_EQ(r.load_factor, 1.0);
}

TEST(HyperelasticContinuation, AnObserverStopsTheContinuationWithItsReason) {
  const TetMesh mesh = test::cube_mesh(1, 1e-3);
  HyperelasticOptions o;
  o.checkpoints = {0.2, 0.6, 1.0};
  HyperelasticSolver s(mesh, cube_problem(0.3, 1, Formulation::displacement, -2000.0), o);
  const auto& r = s.solve([](const HyperelasticSolver&, const Checkpoint& c) {
    return c.load_factor >= 0.6 ? std::string("enough") : std::string();
  });
  EXPECT_FALSE(r.completed);
  EXPECT_EQ(r.stop_reason, "enough");
  EXPECT_DOUBLE_EQ(r.load_factor, 0.6);
  EXPECT_EQ(r.checkpoints.size(), 2u);
}

TEST(HyperelasticContinuation, NewtonTakesFullStepsOnABarSaggingBetweenClampedEnds) {
  // A 10 × 1 × 1 mm bar clamped at both ends under 5 g sags by about 5 % of its length: its
  // Newton steps stretch it axially (membrane forces of ½ w'² ≈ 1 %), which raises the residual's
  // norm although the step is right. Armijo on the potential energy takes the full steps:
  // quadratic convergence in one load step. The answer must equal a continuation in eight
  // small steps (a second solution path) to the tolerance.
  TetMesh bar = test::cube_mesh(3, 1e-3);
  for (Vec3& x : bar.nodes) x.x() *= 10.0;
  ElasticityProblem p;
  p.material.poisson_ratio = 0.45;
  p.options.degree = 2;
  p.options.solver = LinearSolver::direct;
  p.dirichlet = {DirichletCondition::clamped("x0"), DirichletCondition::clamped("x1")};
  p.gravity = Vec3(0, 0, -5 * 9.81);
  HyperelasticOptions one;
  one.max_newton_iterations = 8;
  one.min_step = 1.0;  // no halving: one load step or a failure
  HyperelasticSolver s1(bar, p, one);
  const auto& r1 = s1.solve();
  ASSERT_TRUE(r1.completed) << r1.stop_reason;
  EXPECT_EQ(r1.steps.size(), 1u);
  HyperelasticOptions eight;
  eight.initial_step = eight.max_step = 0.125;
  HyperelasticSolver s8(bar, p, eight);
  const auto& r8 = s8.solve();
  ASSERT_TRUE(r8.completed) << r8.stop_reason;
  double diff = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < r1.nodal_displacement.size(); ++i) {
    diff = std::max(diff, (r1.nodal_displacement[i] - r8.nodal_displacement[i]).norm());
    norm = std::max(norm, r8.nodal_displacement[i].norm());
  }
  std::cout << "  sagging bar: one step " << r1.newton_iterations << " Newton iterations, eight steps "
            << r8.newton_iterations << "; max |u| " << norm * 1e3 << " mm, paths differ by "
            << diff / norm << "\n";
  EXPECT_GT(norm, 0.03 * 10e-3);
  EXPECT_LT(diff, 1e-7 * norm);
}

TEST(HyperelasticContinuation, NewtonFailureReportsTheLargestLoadReached) {
  // One Newton iteration per step cannot reach the tolerance: the increment fails, and halving
  // it would fall below min_step; the result keeps load factor 0 and says why.
  const TetMesh mesh = test::cube_mesh(1, 1e-3);
  HyperelasticOptions o;
  o.max_newton_iterations = 1;
  o.min_step = 0.3;
  o.checkpoints = {0.5, 1.0};
  HyperelasticSolver s(mesh, cube_problem(0.3, 1, Formulation::displacement, -2000.0), o);
  const auto& r = s.solve();
  EXPECT_FALSE(r.completed);
  EXPECT_EQ(r.load_factor, 0.0);
  EXPECT_TRUE(r.checkpoints.empty());
  // The first step ends at the checkpoint 0.5, fails, and half of it (0.25) is below min_step.
  EXPECT_EQ(r.rejected_steps, 1);
  EXPECT_NE(r.stop_reason.find("no equilibrium found beyond load factor 0: at 0.5"),
            std::string::npos)
      << r.stop_reason;
  EXPECT_NE(r.stop_reason.find("Newton did not converge in 1 iterations"), std::string::npos)
      << r.stop_reason;
}

namespace {

/// The cube [0, L]³ (groups x0 … z1) and, a gap g beyond its face x1, a block of side 2L
/// (groups b_x0 … b_z1) shifted off the cube's node planes: two bodies in one mesh.
TetMesh cube_facing_a_block(double L, double g) {
  TetMesh m = test::cube_mesh(2, L);
  const TetMesh b = test::cube_mesh(2, 2 * L);
  const int nodes = static_cast<int>(m.nodes.size()), triangles = static_cast<int>(m.triangles.size());
  const Vec3 shift(L + g, -0.37 * L, -0.41 * L);
  for (const Vec3& x : b.nodes) m.nodes.push_back(x + shift);
  for (Tet t : b.tets) {
    for (int& v : t) v += nodes;
    m.tets.push_back(t);
  }
  for (Triangle t : b.triangles) {
    for (int& v : t) v += nodes;
    m.triangles.push_back(t);
  }
  for (PhysicalGroup grp : b.groups) {
    grp.name = "b_" + grp.name;
    grp.tag += 6;
    for (int& e : grp.elements) e += triangles;
    m.groups.push_back(grp);
  }
  return m;
}

}  // namespace

TEST(HyperelasticContinuation, StopsWhereTheWallWouldPassThroughItself) {
  // The cube is pulled along x towards the clamped block (Cauchy traction up to stretch 1.5);
  // its face x1 reaches the block at stretch 1 + g/L = 1.2, i.e. at the load factor
  // s* = σ(1.2)/σ(1.5) of the closed form. Beyond it the face's nodes would lie inside the
  // block, so the continuation stops there, to within the step it can no longer halve.
  const double L = 1e-3, g = 0.2e-3;
  const TetMesh mesh = cube_facing_a_block(L, g);
  Material m;
  m.poisson_ratio = 0.3;
  const double mu = m.mu(), lambda = m.lambda();
  const double full = uniaxial_stress(1.5, mu, lambda).cauchy;
  const double s_touch = uniaxial_stress(1.2, mu, lambda).cauchy / full;
  ElasticityProblem p = cube_problem(0.3, 1, Formulation::displacement, -full);
  p.dirichlet.push_back(DirichletCondition::clamped("b_x1"));
  HyperelasticOptions o;
  o.min_step = 0.01;
  HyperelasticSolver s(mesh, p, o);
  const auto& r = s.solve();
  std::cout << "  self-contact expected at load factor " << s_touch << ", stopped at "
            << r.load_factor << ": " << r.stop_reason << "\n";
  EXPECT_FALSE(r.completed);
  EXPECT_TRUE(r.self_contact);
  EXPECT_NE(r.stop_reason.find("the wall passes through itself"), std::string::npos) << r.stop_reason;
  // The last failed step was shorter than 2·min_step and began at the load reached.
  EXPECT_LE(r.load_factor, s_touch + 1e-9);
  EXPECT_GE(r.load_factor, s_touch - 2 * o.min_step);
  // Not a Newton failure: the same problem without the check reaches the full load.
  o.stop_at_self_contact = false;
  HyperelasticSolver free(mesh, p, o);
  EXPECT_TRUE(free.solve().completed);
  EXPECT_FALSE(free.result().self_contact);
}

TEST(HyperelasticContinuation, RefusesCheckpointsOutOfOrderOrBeyondTheTarget) {
  const TetMesh mesh = test::cube_mesh(1, 1e-3);
  for (const std::vector<double>& bad : {std::vector<double>{0.5, 0.2}, {0.5, 1.5}, {0.0}}) {
    HyperelasticOptions o;
    o.checkpoints = bad;
    const ElasticityProblem p = cube_problem(0.3, 1, Formulation::displacement, -1.0);
    EXPECT_THROW({ HyperelasticSolver s(mesh, p, o); }, InputError);
  }
}

namespace vessel::fem {
namespace {

// The free rows' field at points (free_displacement_at) against an affine field: its interpolant
// on the rows (interpolate_rows) is exact at P1 and P2, so at any point inside the cube the
// field comes back, and a point outside is refused.
TEST(HyperelasticFreeRows, AnAffineFieldsRowsGiveItBackAtAnyPoint) {
  const double L = 1e-3;
  const TetMesh mesh = test::cube_mesh(2, L);
  const Vec3 b(1e-4, -2e-4, 3e-4);
  const auto field = [&](const Vec3& x) -> Vec3 { return x[0] * b; };  // zero on x0
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> in(0.05 * L, 0.95 * L);
  std::vector<Vec3> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(in(rng), in(rng), in(rng));
  for (const int degree : {1, 2}) {
    ElasticityProblem p;
    p.options.degree = degree;
    p.dirichlet = {DirichletCondition::clamped("x0")};
    const HyperelasticSolver s(mesh, p);
    const Eigen::VectorXd u = interpolate_rows(s.free_dofs(), field);
    const std::vector<Vec3> at = s.free_displacement_at(u, points);
    for (std::size_t i = 0; i < points.size(); ++i) {
      EXPECT_LT((at[i] - field(points[i])).norm(), 1e-12 * b.norm() * L) << "P" << degree;
    }
    EXPECT_THROW((void)s.free_displacement_at(u, {Vec3(2 * L, 0, 0)}), InputError);
  }
}

}  // namespace
}  // namespace vessel::fem
