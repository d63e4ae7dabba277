// Critical time steps: the closed-form per-mode bounds against the spectral radius of each
// integrator's own one-step map, the Lanczos ω_max against a dense eigensolver, and runs at
// 0.9× / 1.1× the predicted step on a small tetrahedral box.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iostream>
#include <random>

#include "msm/mass/mass_rules.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/terms/spring_model.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// One Hooke spring along x from a fixed node at the origin to node 1 at (1 m, 0, 0) whose y and
/// z are fixed: exactly m ẍ = −k x − c ẋ for small x, ω² = k/m, γ = c/m.
struct Oscillator {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

Oscillator make_oscillator(double k, double m, double c) {
  Oscillator o;
  o.net.nodes = {Vec3::Zero(), Vec3(1.0, 0, 0)};
  Spring s;
  s.a = 0;
  s.b = 1;
  s.rest_length = 1.0;
  s.law = {k, k};
  o.net.springs.push_back(s);
  o.model = std::make_unique<SpringModel>(o.net, c);
  Problem& p = o.problem;
  p.form = o.model.get();
  p.rest = flatten(o.net.nodes);
  p.mass = Eigen::VectorXd::Constant(6, m);
  p.external_force = Eigen::VectorXd::Zero(6);
  p.fixed = {1, 1, 1, 0, 1, 1};
  return o;
}

/// Spectral radius of the integrator's one-step map on (x, v) of the oscillator, built column by
/// column by running integrate() for one step (the map is linear: displacements of 1e-9 m on a
/// 1 m spring keep ψ = ½k(L − l)² exactly quadratic up to rounding).
double spectral_radius(const Oscillator& o, Integrator integrator, double h, double omega) {
  Eigen::Matrix2d A;
  for (int col = 0; col < 2; ++col) {
    Eigen::VectorXd x0 = o.problem.rest, v0 = Eigen::VectorXd::Zero(6);
    const double amp = 1e-9;
    if (col == 0)
      x0[3] += amp;
    else
      v0[3] = amp * omega;
    DynamicOptions d;
    d.integrator = integrator;
    d.dt = h;
    d.steps = 1;
    d.blowup_factor = 1e300;
    const DynamicResult r = integrate(o.problem, d, x0, v0);
    A(0, col) = (r.x[3] - o.problem.rest[3]) / (col == 0 ? amp : amp * omega);
    A(1, col) = r.v[3] / (col == 0 ? amp : amp * omega);
  }
  return A.eigenvalues().cwiseAbs().maxCoeff();
}

/// A 4×3×3-cell box (4 mm cells, jittered), six Kuhn tets per cell: a small volume mesh.
TetMesh box_mesh(double jitter = 0.15) {
  const int nx = 4, ny = 3, nz = 3;
  const double h = 4e-3;
  TetMesh mesh;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  auto id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.nodes.emplace_back(h * (i + u(rng)), h * (j + u(rng)), h * (k + u(rng)));
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int v[8] = {
            id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
            id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
        // Kuhn: the six tets around the diagonal v0–v6.
        const int paths[6][2] = {{1, 2}, {1, 5}, {3, 2}, {3, 7}, {4, 5}, {4, 7}};
        for (const auto& p : paths) {
          Tet t{v[0], v[p[0]], v[p[1]], v[6]};
          if (signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]],
                            mesh.nodes[t[3]]) < 0)
            std::swap(t[2], t[3]);
          mesh.tets.push_back(t);
        }
      }
  return mesh;
}

/// Volume model (seed001 stiffness) on the box, nodes with x = 0 fixed.
struct BoxModel {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

BoxModel make_box_model(MassRule mass_rule, double point_damping = 0.0) {
  BoxModel b;
  b.net = build_volume_network(box_mesh());
  assign_stiffness(b.net, StiffnessRule::seed001, StiffnessParams{});
  b.model = std::make_unique<SpringModel>(b.net, point_damping);
  const auto masses = nodal_masses(b.net, mass_rule, kVesselDensity);
  Problem& p = b.problem;
  p.form = b.model.get();
  p.rest = flatten(b.net.nodes);
  p.mass.resize(p.rest.size());
  for (std::size_t i = 0; i < masses.size(); ++i) p.mass.segment<3>(3 * i).setConstant(masses[i]);
  p.external_force = Eigen::VectorXd::Zero(p.rest.size());
  p.fixed.assign(p.rest.size(), 0);
  for (std::size_t i = 0; i < b.net.nodes.size(); ++i) {
    if (b.net.nodes[i].x() < 2e-3) p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
  }
  return b;
}

/// Runs `steps` steps from a small random velocity; true if no DivergenceError.
bool runs_bounded(const Problem& p, Integrator integrator, double dt, int steps,
                  double* max_energy_ratio = nullptr) {
  const Eigen::VectorXd v0 = random_velocity(p, 1e-6, 3);
  const double H0 = total_energy(p, p.rest, v0);
  double worst = 1.0;
  DynamicOptions d;
  d.integrator = integrator;
  d.dt = dt;
  d.steps = steps;
  d.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
    worst = std::max(worst, total_energy(p, x, v) / H0);
  };
  try {
    (void)integrate(p, d, p.rest, v0);
  } catch (const DivergenceError&) {
    return false;
  }
  if (max_energy_ratio) *max_energy_ratio = worst;
  return true;
}

}  // namespace

TEST(CriticalStep, ClosedFormsMatchTheSpectralRadiusOfEachIntegratorsOneStepMap) {
  const double k = 40.0, m = 1e-3;
  const double omega = std::sqrt(k / m);
  // ζ from undamped to heavily overdamped (γ = 2ζω).
  for (double zeta : {0.0, 0.05, 0.3, 0.9, 1.5, 4.0}) {
    const double gamma = 2 * zeta * omega;
    const Oscillator o = make_oscillator(k, m, gamma * m);
    for (Integrator in :
         {Integrator::explicit_euler, Integrator::symplectic_euler, Integrator::verlet}) {
      const double hc = critical_step_mode(in, omega, gamma);
      SCOPED_TRACE(to_string(in) + " zeta " + std::to_string(zeta));
      if (in == Integrator::explicit_euler && zeta == 0.0) {
        EXPECT_EQ(hc, 0.0);
        for (double h : {1e-6, 1e-4, 1e-2}) EXPECT_GT(spectral_radius(o, in, h, omega), 1.0);
        continue;
      }
      ASSERT_GT(hc, 0.0);
      EXPECT_LE(spectral_radius(o, in, 0.99 * hc, omega), 1.0 + 1e-6);
      EXPECT_GT(spectral_radius(o, in, 1.01 * hc, omega), 1.0 + 1e-6);
    }
  }
  // Hand-derived special values: 2/ω (undamped symplectic Euler and Verlet), 2ζ/ω (underdamped
  // explicit Euler), 2/γ at ω → 0 (overdamped explicit Euler).
  EXPECT_DOUBLE_EQ(critical_step_mode(Integrator::symplectic_euler, 100.0, 0.0), 0.02);
  EXPECT_NEAR(critical_step_mode(Integrator::verlet, 100.0, 0.0), 0.02, 1e-15);
  EXPECT_DOUBLE_EQ(critical_step_mode(Integrator::explicit_euler, 100.0, 2 * 0.1 * 100.0),
                   2 * 0.1 / 100.0);
  EXPECT_NEAR(critical_step_mode(Integrator::explicit_euler, 1e-6, 50.0), 2.0 / 50.0, 1e-12);
  EXPECT_TRUE(std::isinf(critical_step_mode(Integrator::implicit_euler, 100.0, 0.0)));
}

TEST(CriticalStep, ExplicitEulerWithStrongDampingIsLimitedByTheLowestMode) {
  // h_crit(ω) = γ/ω² above ω = γ/2 but 2/(γ/2 + √(γ²/4 − ω²)) < 4/γ below: with ω_max only
  // slightly above γ/√2 the lowest mode binds.
  Spectrum s;
  s.omega_max = 100.0;
  s.gamma_max = 150.0;  // γ/ω_max² = 0.015 s
  s.omega_min = 1.0;
  s.gamma_min = 150.0;  // 2/(75 + √(75² − 1)) ≈ 0.01333 s
  s.has_lowest = true;
  EXPECT_NEAR(predicted_critical_step(Integrator::explicit_euler, s),
              2.0 / (75.0 + std::sqrt(75.0 * 75.0 - 1.0)), 1e-15);
  s.has_lowest = false;
  EXPECT_DOUBLE_EQ(predicted_critical_step(Integrator::explicit_euler, s), 0.015);
}

TEST(CriticalStep, LanczosAgreesWithADenseEigensolverAndLiesBelowGershgorin) {
  const BoxModel b = make_box_model(MassRule::consistent, 1e-4);
  const Problem& p = b.problem;
  const Spectrum s = analyse_spectrum(p);
  // Dense: M^{-1/2} K M^{-1/2} on the free dofs (Eigen's SelfAdjointEigenSolver).
  SparseMatrix K;
  p.form->hessian(p.rest, K, false);
  std::vector<int> free;
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (!p.fixed[i]) free.push_back(i);
  }
  const int n = static_cast<int>(free.size());
  ASSERT_EQ(s.free_dofs, n);
  ASSERT_GT(n, 100);
  const Eigen::MatrixXd Kd(K);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      A(i, j) = Kd(free[i], free[j]) / std::sqrt(p.mass[free[i]] * p.mass[free[j]]);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
  const double dense_max = std::sqrt(es.eigenvalues()[n - 1]);
  const double dense_min = std::sqrt(es.eigenvalues()[0]);
  EXPECT_NEAR(s.omega_max, dense_max, 1e-8 * dense_max);
  EXPECT_NEAR(s.omega_min, dense_min, 1e-6 * dense_min);
  EXPECT_LT(s.omega_max, s.gershgorin);
  // Point damping c: γ = c yᵀM⁻¹y / yᵀy for the dense top eigenvector y.
  const Eigen::VectorXd y = es.eigenvectors().col(n - 1);
  double gamma = 0.0;
  for (int i = 0; i < n; ++i) gamma += 1e-4 * y[i] * y[i] / p.mass[free[i]];
  EXPECT_NEAR(s.gamma_max, gamma / y.squaredNorm(), 1e-6 * gamma);
}

TEST(CriticalStep, ConditionallyStableIntegratorsAreStableAt09AndUnstableAt11OfThePrediction) {
  // Undamped, consistent (non-uniform) masses: symplectic Euler and Verlet, 2/ω_max.
  {
    const BoxModel b = make_box_model(MassRule::consistent);
    const Spectrum s = analyse_spectrum(b.problem);
    for (Integrator in : {Integrator::symplectic_euler, Integrator::verlet}) {
      const double hc = predicted_critical_step(in, s);
      EXPECT_NEAR(hc, 2.0 / s.omega_max, 1e-12 * hc);
      double ratio = 0.0;
      EXPECT_TRUE(runs_bounded(b.problem, in, 0.9 * hc, 3000, &ratio)) << to_string(in);
      EXPECT_LT(ratio, 10.0) << to_string(in);
      EXPECT_FALSE(runs_bounded(b.problem, in, 1.1 * hc, 3000)) << to_string(in);
    }
  }
  // Point damping, uniform masses (so that c/m is one γ for every mode): ζ = 0.3 on the top mode.
  {
    const BoxModel probe = make_box_model(MassRule::uniform);
    const Spectrum s0 = analyse_spectrum(probe.problem, {.lowest = false});
    const double c = 2 * 0.3 * s0.omega_max * probe.problem.mass[0];
    const BoxModel b = make_box_model(MassRule::uniform, c);
    const Spectrum s = analyse_spectrum(b.problem);
    EXPECT_NEAR(s.gamma_max, c / b.problem.mass[0], 1e-9 * s.gamma_max);
    for (Integrator in :
         {Integrator::explicit_euler, Integrator::symplectic_euler, Integrator::verlet}) {
      const double hc = predicted_critical_step(in, s);
      EXPECT_TRUE(runs_bounded(b.problem, in, 0.9 * hc, 3000)) << to_string(in);
      EXPECT_FALSE(runs_bounded(b.problem, in, 1.1 * hc, 3000)) << to_string(in);
    }
    // Explicit Euler: 2ζ/ω_max, the damping-free integrators' bound shrunk by 0.3.
    EXPECT_NEAR(predicted_critical_step(Integrator::explicit_euler, s), 0.6 / s.omega_max,
                1e-9 / s.omega_max);
  }
}

TEST(CriticalStep, UndampedExplicitEulerGainsEnergyAtEveryStepAtEveryStepSize) {
  const BoxModel b = make_box_model(MassRule::consistent);
  const Problem& p = b.problem;
  const Spectrum s = analyse_spectrum(p, {.lowest = false});
  // Displacements of ~1e-6 of a cell: far above rounding of L − l, far below nonlinearity.
  const Eigen::VectorXd v0 = random_velocity(p, 1e-6 * 4e-3 * s.omega_max, 5);
  for (double fraction : {1e-3, 1e-2, 0.1, 0.5, 0.9}) {
    const double dt = fraction * 2.0 / s.omega_max;
    double previous = total_energy(p, p.rest, v0);
    const double H0 = previous;
    int decreases = 0;
    DynamicOptions d;
    d.integrator = Integrator::explicit_euler;
    d.dt = dt;
    d.steps = 200;
    d.blowup_factor = 1e300;
    d.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
      const double e = total_energy(p, x, v);
      if (!(e > previous)) ++decreases;
      previous = e;
    };
    (void)integrate(p, d, p.rest, v0);
    EXPECT_EQ(decreases, 0) << fraction;
    EXPECT_GT(previous, H0) << fraction;
  }
}

TEST(CriticalStep, ImplicitEulerStaysBoundedAt100TimesTheCriticalStep) {
  const BoxModel b = make_box_model(MassRule::consistent);
  const Spectrum s = analyse_spectrum(b.problem, {.lowest = false});
  double ratio = 0.0;
  ASSERT_TRUE(
      runs_bounded(b.problem, Integrator::implicit_euler, 100 * 2.0 / s.omega_max, 200, &ratio));
  EXPECT_LE(ratio, 1.0 + 1e-9);  // backward Euler dissipates: never above the initial energy
}

TEST(CriticalStep, GuaranteedDampedStepIsStableWithNonUniformMasses) {
  // Consistent (non-uniform) masses with point damping c: M⁻¹C = diag(c/m_i) is not a multiple
  // of the identity, the modes do not decouple, and the modal prediction is only an estimate.
  // The guaranteed step (Rayleigh-quotient rectangle, critical_step.hpp) must be stable.
  const BoxModel probe = make_box_model(MassRule::consistent);
  const Spectrum s0 = analyse_spectrum(probe.problem, {.lowest = false});
  EXPECT_NEAR(guaranteed_critical_step(Integrator::symplectic_euler, s0), 2.0 / s0.omega_max,
              1e-12 / s0.omega_max);  // undamped: exact, 2/ω_max
  double m_min = INFINITY, m_max = 0.0, m_mean = 0.0;
  int free = 0;
  for (Eigen::Index i = 0; i < probe.problem.mass.size(); ++i) {
    if (probe.problem.fixed[static_cast<std::size_t>(i)]) continue;
    m_min = std::min(m_min, probe.problem.mass[i]);
    m_max = std::max(m_max, probe.problem.mass[i]);
    m_mean += probe.problem.mass[i];
    ++free;
  }
  m_mean /= free;
  ASSERT_GT(m_max / m_min, 1.5);  // really non-uniform
  for (double zeta : {0.3, 1.0, 3.0}) {
    const double c = 2.0 * zeta * s0.omega_max * m_mean;
    const BoxModel b = make_box_model(MassRule::consistent, c);
    const Spectrum s = analyse_spectrum(b.problem);
    // Point damping's C = c·I: the extreme damping rates are c/m_max and c/m_min exactly.
    EXPECT_NEAR(s.gamma_lo, c / m_max, 1e-9 * c / m_max);
    EXPECT_NEAR(s.gamma_hi, c / m_min, 1e-9 * c / m_min);
    for (Integrator in : {Integrator::explicit_euler, Integrator::symplectic_euler}) {
      SCOPED_TRACE(to_string(in) + ", zeta " + std::to_string(zeta));
      const double guaranteed = guaranteed_critical_step(in, s);
      const double predicted = predicted_critical_step(in, s);
      ASSERT_GT(guaranteed, 0.0);
      // The prediction's (ω, γ) pairs lie in the rectangle, so the bound cannot exceed it.
      EXPECT_LE(guaranteed, predicted * (1 + 1e-12));
      StabilitySearchOptions o;
      o.integrator = in;
      o.steps = 2000;
      o.tolerance = 5e-3;
      const StabilitySearchResult r = find_stable_step(b.problem, predicted, o);
      EXPECT_GE(r.stable_dt, 0.9 * guaranteed)
          << "found " << r.stable_dt << " guaranteed " << guaranteed << " predicted " << predicted;
      // Not vacuous: on this model the worst corner is nearly reached (measured ≤ 1.8).
      EXPECT_LT(r.stable_dt, 2.0 * guaranteed);
      EXPECT_TRUE(runs_bounded(b.problem, in, guaranteed, 5000));
      std::cout << "  " << to_string(in) << " zeta " << zeta << ": found/predicted "
                << r.stable_dt / predicted << ", found/guaranteed " << r.stable_dt / guaranteed
                << "\n";
    }
  }
  // No bound is proven for damped Verlet.
  const BoxModel damped = make_box_model(MassRule::consistent, 2.0 * 0.3 * s0.omega_max * m_mean);
  EXPECT_TRUE(
      std::isnan(guaranteed_critical_step(Integrator::verlet, analyse_spectrum(damped.problem))));
}

TEST(StabilitySearch, BisectionFindsTheUndampedSymplecticEulerLimit) {
  const BoxModel b = make_box_model(MassRule::consistent);
  const Spectrum s = analyse_spectrum(b.problem, {.lowest = false});
  const double predicted = 2.0 / s.omega_max;
  StabilitySearchOptions o;
  o.integrator = Integrator::symplectic_euler;
  o.steps = 2000;
  o.tolerance = 2e-3;
  // Start 30 % off, so that the bracket has to be searched for.
  const StabilitySearchResult r = find_stable_step(b.problem, 1.3 * predicted, o);
  EXPECT_LT(r.stable_dt, r.unstable_dt);
  EXPECT_LE(r.unstable_dt - r.stable_dt, 2e-3 * r.stable_dt * 1.0000001);
  EXPECT_NEAR(r.stable_dt / predicted, 1.0, 0.01);
}

TEST(CriticalStep, PowerIterationAgreesWithADenseEigensolver) {
  // The same box and dense M^{-1/2} K M^{-1/2} as the Lanczos test: power iteration's ω_max is a
  // second, independent estimate of 2/ω_max (its Rayleigh quotient cannot exceed the top one).
  const BoxModel b = make_box_model(MassRule::consistent, 0.0);
  const Problem& p = b.problem;
  SparseMatrix K;
  p.form->hessian(p.rest, K, false);
  std::vector<int> free;
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (!p.fixed[i]) free.push_back(i);
  }
  const int n = static_cast<int>(free.size());
  const Eigen::MatrixXd Kd(K);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      A(i, j) = Kd(free[i], free[j]) / std::sqrt(p.mass[free[i]] * p.mass[free[j]]);
  const double dense_max =
      std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues()[n - 1]);
  const double power = power_iteration_omega_max(p, 1e-13, 200000);
  std::cout << "[ power iteration ] ω_max " << power << " rad/s, dense " << dense_max << "\n";
  EXPECT_LE(power, dense_max * (1.0 + 1e-12));
  EXPECT_NEAR(power, dense_max, 1e-4 * dense_max);
}

TEST(StabilitySearch, GenericBisectionBracketsAndNarrowsAKnownThreshold) {
  // A trial stable below 3.7e-4 s: bracketed from guesses above and below, narrowed to 0.5 %.
  for (const double guess : {1e-5, 3.7e-4, 1e-2}) {
    const StabilitySearchResult r =
        bisect_stable_step(guess, 5e-3, 60, [](double dt) { return dt <= 3.7e-4; });
    EXPECT_LE(r.stable_dt, 3.7e-4) << guess;
    EXPECT_GT(r.unstable_dt, 3.7e-4) << guess;
    EXPECT_LE(r.unstable_dt - r.stable_dt, 5e-3 * r.stable_dt * 1.0000001) << guess;
  }
  EXPECT_THROW(bisect_stable_step(1e-3, 5e-3, 10, [](double) { return true; }), std::runtime_error);
}
