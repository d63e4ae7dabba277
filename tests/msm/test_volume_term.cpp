// The volume term of the hybrid model (Golec et al. 2020) and the model that sums it with the
// springs: energy, gradient and Hessian against finite differences and a hand-derived dilation,
// the per-element PSD projection, the critical-step bound, a region of interest, and every solver.
#include <gtest/gtest.h>

#include <iostream>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "finite_differences.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/model/roi.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/terms/volume_term.hpp"
#include "tests/fixtures/kuhn_block.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kE = 14.24e3;

/// An n×n×n block of cubes of side h, each cut into six tets (Kuhn), positively oriented.
TetMesh block_mesh(int n, double h) { return vessel::test::kuhn_block(n, n, n, h); }

BuiltNetwork hybrid(const TetMesh& mesh, double nu) {
  NetworkOptions o;
  o.model = ModelType::volume;
  o.stiffness = StiffnessRule::van_gelder;
  o.stiffness_params.youngs_modulus = kE;
  o.stiffness_params.poisson_ratio = nu;
  o.volume_term = true;
  return build_network(mesh, VesselParams{}, o);
}

Eigen::VectorXd perturbed(const Eigen::VectorXd& x, std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Eigen::VectorXd y = x;
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] += u(rng);
  return y;
}

}  // namespace

TEST(VolumeTerm, KernelMatchesFiniteDifferencesForBothSignsOfKappa) {
  std::mt19937 rng(7);
  const std::array<Vec3, 4> rest{Vec3(0, 0, 0), Vec3(1e-3, 0.1e-3, 0), Vec3(0.2e-3, 0.9e-3, 0.1e-3),
                                 Vec3(0.1e-3, 0.3e-3, 1.1e-3)};
  const double v0 = tet_signed_volume(rest);
  ASSERT_GT(v0, 0.0);
  Eigen::VectorXd x0(12);
  for (int a = 0; a < 4; ++a) x0.segment<3>(3 * a) = rest[a];
  auto corners = [](const Eigen::VectorXd& x) {
    return std::array<Vec3, 4>{x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9)};
  };
  for (double kappa : {5e4, -3e3}) {
    const Eigen::VectorXd x = perturbed(x0, rng, 0.1e-3);
    using C = std::array<Vec3, 4>;
    const auto c = msm::test::check_element_derivatives(
        [&](const C& y) { return volume_energy(y, v0, kappa); },
        [&](const C& y) { return volume_gradient(y, v0, kappa); },
        [&](const C& y) { return volume_hessian(y, v0, kappa, false); }, x, 1e-8);
    EXPECT_LT(c.gradient_error, 1e-6) << kappa;
    EXPECT_LT(c.hessian_error, 1e-6) << kappa;
    EXPECT_LT(c.hessian_asymmetry, 1e-12) << kappa;
    // Projection: PSD, and unchanged where the exact block is already PSD (at rest, κ > 0).
    const Mat12 P = volume_hessian(corners(x), v0, kappa, true);
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat12>(P).eigenvalues().minCoeff(), -1e-9 * P.norm());
  }
  const Mat12 at_rest = volume_hessian(rest, v0, 5e4, false);
  EXPECT_LT((volume_hessian(rest, v0, 5e4, true) - at_rest).norm(), 1e-9 * at_rest.norm());
  EXPECT_LT(volume_hessian(rest, v0, -3e3, true).norm(), 1e-9 * at_rest.norm());
  // By hand: uniform dilation by (1 + e): V = (1 + e)³V₀, W = ½κV₀((1 + e)³ − 1)²; a rigid
  // rotation changes nothing.
  const double e = 1e-2, kappa = 5e4;
  std::array<Vec3, 4> dilated = rest, rotated = rest;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (int a = 0; a < 4; ++a) {
    dilated[a] = (1 + e) * rest[a];
    rotated[a] = R * rest[a] + Vec3(1e-3, 0, 0);
  }
  const double w = 0.5 * kappa * v0 * std::pow(std::pow(1 + e, 3) - 1, 2);
  EXPECT_NEAR(volume_energy(dilated, v0, kappa), w, 1e-12 * w);
  EXPECT_NEAR(volume_energy(rotated, v0, kappa), 0.0, 1e-12 * w);
}

TEST(VolumeTerm, HybridModelIsTheSumOfItsTermsAndMatchesFiniteDifferences) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  ASSERT_TRUE(built.terms.volume_kappa.has_value());
  // κ = λ − μ at ν = 0.45, by hand: λ = E·0.45/(1.45·0.1), μ = E/2.9.
  EXPECT_NEAR(*built.terms.volume_kappa, kE * (0.45 / 0.145 - 1 / 2.9), 1e-9 * kE);
  const auto model = make_model(built);
  ASSERT_NE(model->term<VolumeTerm>(), nullptr);
  std::mt19937 rng(3);
  const Eigen::VectorXd x = perturbed(flatten(built.network.nodes), rng, 0.05e-3);
  EXPECT_NEAR(model->energy(x), model->springs().energy(x) + model->term<VolumeTerm>()->energy(x),
              1e-12 * model->energy(x));
  auto dense_hessian = [&](const Form& f, bool project) {
    return [&f, project](const Eigen::VectorXd& y) -> Eigen::MatrixXd {
      SparseMatrix H;
      f.hessian(y, H, project);
      return Eigen::MatrixXd(H);
    };
  };
  auto grad = [](const Form& f) {
    return [&f](const Eigen::VectorXd& y) -> Eigen::VectorXd {
      Eigen::VectorXd g;
      f.gradient(y, g);
      return g;
    };
  };
  const auto c = msm::test::check_derivatives([&](const Eigen::VectorXd& y) { return model->energy(y); },
                                         grad(*model), dense_hessian(*model, false), x, 1e-9);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
  // Projected: PSD (each spring and tet block projected).
  const Eigen::MatrixXd P = dense_hessian(*model, true)(x);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues().minCoeff(),
            -1e-9 * P.norm());

  // A region of interest drops the springs between held nodes: the model assembles into the union
  // pattern, and still matches finite differences.
  std::vector<char> held(built.network.nodes.size(), 0);
  for (std::size_t i = 0; i < held.size(); ++i) held[i] = built.network.nodes[i].x() > 1.5e-3;
  const RoiNetwork roi = restrict_network(built.network, held);
  ASSERT_FALSE(roi.network.tets.empty());
  const auto roi_model = make_model(roi.network, {.volume_kappa = built.terms.volume_kappa});
  const Eigen::VectorXd xr = perturbed(flatten(roi.network.nodes), rng, 0.05e-3);
  const auto cr =
      msm::test::check_derivatives([&](const Eigen::VectorXd& y) { return roi_model->energy(y); },
                              grad(*roi_model), dense_hessian(*roi_model, false), xr, 1e-9);
  EXPECT_LT(cr.gradient_error, 1e-6);
  EXPECT_LT(cr.hessian_error, 1e-6);
}

TEST(VolumeTerm, CriticalStepBoundAccountsForTheVolumeTerm) {
  // ν = 0.49: κ ≈ 16μ dominates the springs. The Gershgorin bound (max_frequency_bound, which
  // reads the Form's Hessian) must stay above the true ω_max (Lanczos on the exact Hessian) of the
  // hybrid model, and both must rise well above the springs-only model's.
  const TetMesh mesh = block_mesh(3, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.49);
  const auto model = make_model(built);
  const auto springs = make_model(built.network);
  auto problem = [&](const Form& f) {
    Problem p;
    p.form = &f;
    p.rest = flatten(built.network.nodes);
    p.mass = Eigen::VectorXd::Constant(p.rest.size(), 1e-6);
    p.external_force = Eigen::VectorXd::Zero(p.rest.size());
    p.fixed.assign(static_cast<std::size_t>(p.rest.size()), 0);
    for (std::size_t i = 0; i < built.network.nodes.size(); ++i) {
      if (built.network.nodes[i].z() < 1e-9)
        p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
    }
    return p;
  };
  const Problem ph = problem(*model), ps = problem(*springs);
  const Spectrum sh = analyse_spectrum(ph, {.lowest = false});
  const Spectrum ss = analyse_spectrum(ps, {.lowest = false});
  std::printf("omega_max: hybrid %.4g (bound %.4g), springs only %.4g (bound %.4g) rad/s\n",
              sh.omega_max, sh.gershgorin, ss.omega_max, ss.gershgorin);
  EXPECT_GE(sh.gershgorin, sh.omega_max * (1 - 1e-9));
  EXPECT_GT(sh.omega_max, 2.0 * ss.omega_max);
  EXPECT_GT(sh.gershgorin, 2.0 * ss.gershgorin);
}

TEST(VolumeTerm, EverySolverRunsOnTheHybridModelAndAgrees) {
  // A 2 mm block, base fixed, a small downward load on the top: the static Newton answer is the
  // reference; linear and relaxation agree with it; the integrators (with point damping, run long
  // enough to settle) end near it; PBD refuses a volume network.
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const auto model = make_model(built, 2e-4);
  Problem p;
  p.form = model.get();
  p.rest = flatten(built.network.nodes);
  p.mass = Eigen::VectorXd::Constant(p.rest.size(), 1e-6);
  p.external_force = Eigen::VectorXd::Zero(p.rest.size());
  p.fixed.assign(static_cast<std::size_t>(p.rest.size()), 0);
  for (std::size_t i = 0; i < built.network.nodes.size(); ++i) {
    const Vec3& n = built.network.nodes[i];
    if (n.z() < 1e-9) p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
    if (n.z() > 2e-3 - 1e-9) p.external_force[3 * i + 2] = -1e-5;  // N
  }
  // The equilibrium solvers on the undamped model (relaxation brings its own damping).
  const auto undamped = make_model(built);
  Problem q = p;
  q.form = undamped.get();
  const Eigen::VectorXd x_static = solve(q, parse_solver("static")).x;
  const double u = (x_static - p.rest).norm();
  ASSERT_GT(u, 0.0);
  EXPECT_LT((solve(q, parse_solver("linear")).x - x_static).norm(), 0.02 * u);
  const double relaxation = (solve(q, parse_solver("relaxation")).x - x_static).norm() / u;
  std::cout << "  relaxation: |x - x_static| / |u| = " << relaxation << "\n";
  // Relaxation stops at ‖∇Π‖ ≤ 1e-8 ‖f‖: measured 5.7e-8 of |u| here; the integrators run to rest
  // (4e-13 to 5.4e-13 of |u|, the static solve's own tolerance).
  EXPECT_LT(relaxation, 5e-7);
  for (const char* name : {"symplectic-euler", "verlet", "implicit-euler", "implicit-euler-rest"}) {
    SolverSpec s = parse_solver(name);
    s.steps = std::string(name).starts_with("implicit") ? 400 : 20000;
    const SolveResult r = solve(p, s);
    const double rel = (r.x - x_static).norm() / u;
    std::cout << "  " << name << " dt " << r.dt << ": |x - x_static| / |u| = " << rel << "\n";
    EXPECT_LT(rel, 1e-8) << name << " dt " << r.dt;
  }
  EXPECT_THROW((void)solve(p, parse_solver("pbd")), InputError);
}
