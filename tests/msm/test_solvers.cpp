// Static Newton, the linearised model, dynamic relaxation and the integrators on problems with
// closed-form answers: Hooke's law on a spring and a chain (seed 000 Fig. 5: 0–140 mN), and the
// energy of an undamped linear oscillator.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/model/build_network.hpp"
#include "msm/solvers/exact_backoff.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/terms/spring_model.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// A chain of springs along x (node 0 fixed; y and z of every node fixed: Hooke's 1D setting),
/// stiffness k[i] between nodes i and i+1, rest length 1 mm, mass m per node, force F on the end.
struct Chain {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

Chain make_chain(const std::vector<double>& k, double F, double mass = 1e-4) {
  Chain c;
  const int n = static_cast<int>(k.size()) + 1;
  for (int i = 0; i < n; ++i) c.net.nodes.push_back(Vec3(1e-3 * i, 0, 0));
  for (int i = 0; i + 1 < n; ++i) {
    Spring s;
    s.a = i;
    s.b = i + 1;
    s.rest_length = 1e-3;
    s.law = {k[i], k[i]};
    c.net.springs.push_back(s);
  }
  c.model = std::make_unique<SpringModel>(c.net);
  Problem& p = c.problem;
  p.form = c.model.get();
  p.rest = flatten(c.net.nodes);
  p.mass = Eigen::VectorXd::Constant(3 * n, mass);
  p.external_force = Eigen::VectorXd::Zero(3 * n);
  p.external_force[3 * (n - 1)] = F;
  p.fixed.assign(3 * n, 0);
  for (int i = 0; i < n; ++i) p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
  p.fixed[0] = 1;
  return c;
}

double end_displacement(const Problem& p, const Eigen::VectorXd& x) {
  const Eigen::Index e = x.size() - 3;
  return x[e] - p.rest[e];
}

}  // namespace

TEST(StaticSolver, OneSpringFollowsHookesLawFrom0To140mN) {
  // Seed 000 Fig. 5: k = 41.106 N/m, F = 0 … 140 mN → δ = F/k (3.41 mm at 140 mN).
  for (double F = 0.0; F <= 0.140 + 1e-12; F += 0.010) {
    Chain c = make_chain({41.106}, F);
    const StaticResult r = solve_static(c.problem);
    EXPECT_NEAR(end_displacement(c.problem, r.x), F / 41.106, 1e-12) << F;
    const StaticResult l = solve_linear(c.problem);
    EXPECT_NEAR(end_displacement(c.problem, l.x), F / 41.106, 1e-12) << F;
  }
}

TEST(StaticSolver, ChainIsSpringsInSeriesAndReusesTheSymbolicFactorisation) {
  const std::vector<double> k{10.0, 41.106, 25.0, 80.0, 15.0};
  double compliance = 0.0;
  for (double ki : k) compliance += 1.0 / ki;
  for (double F : {0.0, 0.035, 0.070, 0.140}) {
    Chain c = make_chain(k, F);
    const StaticResult r = solve_static(c.problem);
    EXPECT_NEAR(end_displacement(c.problem, r.x), F * compliance, 1e-12);
    // Every spring carries F.
    for (std::size_t i = 0; i < k.size(); ++i) {
      const double L = r.x[3 * (i + 1)] - r.x[3 * i];
      EXPECT_NEAR(k[i] * (L - 1e-3), F, 1e-10);
    }
    EXPECT_LE(r.symbolic_analyses, 1);
  }
}

TEST(StaticSolver, BilinearChainBeyondTheThreshold) {
  // One bilinear spring (seed 001 eq. 1): k1 = 20, k2 = 60 N/m, Δx_c = 1 mm. F = 0.05 N:
  // F = k1 Δx_c + k2 (δ − Δx_c) → δ = Δx_c + (F − k1 Δx_c)/k2.
  Chain c = make_chain({20.0}, 0.05);
  c.net.springs[0].law = {20.0, 60.0, 1e-3};
  c.model = std::make_unique<SpringModel>(c.net);
  c.problem.form = c.model.get();
  const StaticResult r = solve_static(c.problem);
  EXPECT_NEAR(end_displacement(c.problem, r.x), 1e-3 + (0.05 - 0.02) / 60.0, 1e-12);
}

TEST(DynamicRelaxation, ReachesHookesLawOnTheChain) {
  const std::vector<double> k{10.0, 41.106, 25.0};
  double compliance = 0.0;
  for (double ki : k) compliance += 1.0 / ki;
  for (double F : {0.010, 0.070, 0.140}) {
    Chain c = make_chain(k, F);
    RelaxationOptions o;
    o.tolerance = 1e-10;
    const RelaxationResult r = dynamic_relaxation(c.problem, o);
    EXPECT_NEAR(end_displacement(c.problem, r.x), F * compliance, 1e-8 * F * compliance);
    EXPECT_GT(r.steps, 1);
  }
}

namespace {
/// Undamped oscillator: one spring k, free node mass m, released from 0.01 mm stretch.
struct EnergyRun {
  std::vector<double> energy;
};
EnergyRun run_oscillator(Integrator integrator, double dt_over_critical, int steps) {
  const double k = 41.106, m = 1e-3;
  Chain c = make_chain({k}, 0.0, m);
  DynamicOptions o;
  o.integrator = integrator;
  o.dt = dt_over_critical * 2.0 / std::sqrt(k / m);
  o.steps = steps;
  EnergyRun run;
  o.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
    run.energy.push_back(total_energy(c.problem, x, v));
  };
  Eigen::VectorXd x0 = c.problem.rest;
  x0[3] += 1e-5;  // small enough that the spring never passes through zero length
  run.energy.push_back(total_energy(c.problem, x0, Eigen::VectorXd::Zero(x0.size())));
  (void)integrate(c.problem, o, x0);
  return run;
}
}  // namespace

TEST(Integrators, UndampedEnergyBoundedForSymplecticAndVerletGrowingForExplicitEuler) {
  const int steps = 2000;
  const double ratio = 0.2;  // dt = 0.2 × critical step 2/ω, so ωh = 0.4
  const auto sym = run_oscillator(Integrator::symplectic_euler, ratio, steps);
  const auto ver = run_oscillator(Integrator::verlet, ratio, steps);
  const auto exp = run_oscillator(Integrator::explicit_euler, ratio, 40);
  const auto imp = run_oscillator(Integrator::implicit_euler, ratio, steps);
  const double E0 = sym.energy.front();
  auto max_dev = [&](const EnergyRun& r) {
    double d = 0;
    for (double e : r.energy) d = std::max(d, std::abs(e - E0) / E0);
    return d;
  };
  std::printf(
      "undamped oscillator, dt = %.2f x critical: max |E-E0|/E0 symplectic Euler %.4f "
      "(%d steps), Verlet %.4f; explicit Euler E/E0 after 40 steps %.1f; implicit Euler "
      "E/E0 after %d steps %.3g\n",
      ratio, max_dev(sym), steps, max_dev(ver), exp.energy.back() / E0, steps,
      imp.energy.back() / E0);
  // Symplectic Euler conserves a modified energy: the true one oscillates by O(ωh) (25 % here)
  // here and does not drift; Verlet by O((ωh)²) = ±4 %.
  EXPECT_LT(max_dev(sym), 0.3);
  EXPECT_LT(max_dev(ver), 0.05);
  EXPECT_NEAR(sym.energy.back() / E0, 1.0, 0.3);
  // Explicit Euler (seed 000 eq. 3.7) on a linear oscillator multiplies the energy by exactly
  // 1 + (ωh)² each step.
  const double wh = 2.0 * ratio;
  EXPECT_NEAR(exp.energy.back() / E0, std::pow(1 + wh * wh, 40), 1e-8 * std::pow(1 + wh * wh, 40));
  EXPECT_GT(exp.energy.back() / E0, 300.0);
  // Run on, it trips the divergence detection (energy beyond 1000 × its start).
  EXPECT_THROW((void)run_oscillator(Integrator::explicit_euler, ratio, 100), DivergenceError);
  // Implicit Euler dissipates: monotone decrease.
  for (std::size_t i = 1; i < imp.energy.size(); ++i)
    EXPECT_LE(imp.energy[i], imp.energy[i - 1] + 1e-15 * E0);
  EXPECT_LT(imp.energy.back() / E0, 0.01);
}

TEST(Integrators, BlowUpStopsWithStepNodeAndEnergy) {
  const double k = 41.106, m = 1e-3;
  Chain c = make_chain({k}, 0.0, m);
  DynamicOptions o;
  o.integrator = Integrator::symplectic_euler;
  o.dt = 1.2 * 2.0 / std::sqrt(k / m);  // beyond the critical step
  o.steps = 10000;
  Eigen::VectorXd x0 = c.problem.rest;
  x0[3] += 1e-4;
  try {
    (void)integrate(c.problem, o, x0);
    FAIL() << "expected DivergenceError";
  } catch (const DivergenceError& e) {
    EXPECT_EQ(e.node, 1);
    EXPECT_GT(e.step, 1);
    EXPECT_LT(e.step, 10000);
    EXPECT_NE(std::string(e.what()).find("step"), std::string::npos);
  }
  // The bound on ω is an upper bound: at 0.99 × 2/bound symplectic Euler is stable.
  const double w = max_frequency_bound(c.problem);
  EXPECT_GE(w, std::sqrt(k / m) * (1 - 1e-12));
  o.dt = 0.99 * 2.0 / w;
  EXPECT_NO_THROW((void)integrate(c.problem, o, x0));
  o.dt = 0.0;
  EXPECT_THROW((void)integrate(c.problem, o, x0), InputError);
}

TEST(Integrators, DampedImplicitEulerSettlesOnTheStaticAnswer) {
  Chain c = make_chain({41.106, 20.0}, 0.1, 1e-4);
  c.net.springs[0].damping = 0.05;                       // axial damping, seed 000 eq. (3.4)
  c.model = std::make_unique<SpringModel>(c.net, 0.01);  // point damping, eq. (3.3)
  c.problem.form = c.model.get();
  DynamicOptions o;
  o.integrator = Integrator::implicit_euler;
  o.dt = 1e-3;
  o.steps = 3000;
  const DynamicResult r = integrate(c.problem, o);
  EXPECT_NEAR(end_displacement(c.problem, r.x), 0.1 * (1 / 41.106 + 1 / 20.0), 1e-9);
}

TEST(Solvers, NewtonRelaxationAndLinearisedModelAgreeOnTheVesselVolumeModel) {
  // Three independent routes to the static answer of the volume model under the shared contact
  // patch: Newton/CHOLMOD, dynamic relaxation (explicit), and — at a load small enough to be
  // linear — the stiffness at rest.
  const VesselParams params;
  const TetMesh mesh = generate_vessel_mesh(params);
  SpringNetwork net = build_volume_network(mesh);
  assign_stiffness(net, StiffnessRule::seed001, StiffnessParams{});
  const SpringModel model(net);
  const auto masses = nodal_masses(net, MassRule::consistent, kVesselDensity);
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 20e-3);
  spec.radius = 1e-3;
  for (double force : {1e-3, 1e-7}) {
    spec.force = force;
    const auto loads = traction_nodal_loads(mesh, contact_patch(mesh, spec));
    const Problem p = make_problem(model, net, masses, mesh, loads, {"inlet", "outlet"});
    const StaticResult newton = solve_static(p);
    const Eigen::VectorXd u = newton.x - p.rest;
    if (force > 1e-5) {
      RelaxationOptions o;
      o.tolerance = 1e-9;
      const RelaxationResult dr = dynamic_relaxation(p, o);
      EXPECT_LT((dr.x - newton.x).norm(), 1e-6 * u.norm());
    } else {
      const StaticResult lin = solve_linear(p);
      EXPECT_LT((lin.x - newton.x).norm(), 1e-4 * u.norm());
    }
  }
}

namespace {
/// A node between two fixed nodes 2 mm apart, joined by springs of rest length L0 = 1.2 mm
/// (compressed, so the straight state is a saddle: transverse stiffness 2k(1 − L0/l) < 0), pushed
/// sideways by f. Starts straight; the stable equilibrium solves 2k(L − L0)·y/L = f. There the
/// projected Hessian has no y stiffness at all: before the regularisation floor of CholmodSolver
/// (relative to the mean diagonal) every variant failed at iteration 0.
struct Snap {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};
Snap make_snap(double k, double f) {
  Snap s;
  s.net.nodes = {Vec3(-1e-3, 0, 0), Vec3(0, 0, 0), Vec3(1e-3, 0, 0)};
  for (int b : {0, 2}) {
    Spring sp;
    sp.a = 1;
    sp.b = b;
    sp.rest_length = 1.2e-3;
    sp.law = {k, k};
    s.net.springs.push_back(sp);
  }
  s.model = std::make_unique<SpringModel>(s.net);
  Problem& p = s.problem;
  p.form = s.model.get();
  p.rest = flatten(s.net.nodes);
  p.mass = Eigen::VectorXd::Constant(9, 1e-4);
  p.external_force = Eigen::VectorXd::Zero(9);
  p.external_force[4] = f;
  p.fixed.assign(9, 1);
  p.fixed[3] = p.fixed[4] = 0;  // node 1 moves in x and y
  return s;
}
}  // namespace

TEST(StaticSolver, CompressedPairSnapsToTheStableEquilibriumWithAndWithoutNegativeCurvature) {
  const double k = 10.0, f = 1e-4, L0 = 1.2e-3, h = 1e-3;
  // Truth by bisection on 2k(L − L0)y/L − f, increasing in y beyond L = L0.
  double lo = std::sqrt(L0 * L0 - h * h), hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double y = 0.5 * (lo + hi), L = std::hypot(h, y);
    (2 * k * (L - L0) * y / L - f > 0 ? hi : lo) = y;
  }
  for (int iterations : {0, 20}) {
    for (double shift : {1.0, 0.3}) {
      Snap s = make_snap(k, f);
      StaticOptions o;
      o.curvature_iterations = iterations;
      o.curvature_shift = shift;
      const StaticResult r = solve_static(s.problem, o);
      EXPECT_NEAR(r.x[4], lo, 1e-12) << iterations << " " << shift;
      EXPECT_NEAR(r.x[3], 0.0, 1e-15);
      EXPECT_GT(r.indefinite_iterations, 0);
      if (iterations == 0) EXPECT_EQ(r.negative_curvature_steps, 0);
    }
  }
}

TEST(StaticSolver, SurfaceMembraneEquilibriumBalancesTheLoadAndIsStable) {
  // The surface model of the level-0 vessel under the shared contact patch (a buckling membrane:
  // most Newton iterations have an indefinite Hessian). Independent checks of the answer: the
  // reactions at the fixed ends balance the applied load, and the equilibrium is a minimum (the
  // exact Hessian on the free dofs is positive definite there: Cholesky succeeds). Both the
  // projected Newton and the negative-curvature variant get there.
  const VesselParams params;
  const TetMesh mesh = generate_vessel_mesh(params);
  SpringNetwork net = build_triangle_network(
      wall_surface(mesh, params, WallSurface::inner), params.wall_thickness);
  assign_stiffness(net, StiffnessRule::seed000, StiffnessParams{});
  const SpringModel model(net);
  const auto masses = nodal_masses(net, MassRule::consistent, kVesselDensity);
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 20e-3);
  spec.force = 1e-3;
  const auto loads = traction_nodal_loads(mesh, contact_patch(mesh, spec));
  const Problem p = make_problem(model, net, masses, mesh, loads, {"inlet", "outlet"});
  for (int iterations : {0, 20}) {
    StaticOptions o;
    o.curvature_iterations = iterations;
    const StaticResult r = solve_static(p, o);
    Eigen::VectorXd g;
    model.gradient(r.x, g);  // −(internal forces); on fixed dofs the supports provide R = g
    Eigen::Vector3d reaction = Eigen::Vector3d::Zero(), load = Eigen::Vector3d::Zero();
    for (int i = 0; i < p.num_dofs(); ++i) {
      load[i % 3] += p.external_force[i];
      if (p.fixed[i]) reaction[i % 3] += g[i];
    }
    EXPECT_LT((reaction + load).norm(), 1e-9 * load.norm()) << iterations;
    SparseMatrix H;
    model.hessian(r.x, H, false);
    apply_dirichlet(H, p.fixed);
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(H);
    ASSERT_EQ(ldlt.info(), Eigen::Success);
    EXPECT_GT(ldlt.vectorD().minCoeff(), 0.0) << iterations;
    EXPECT_GT(r.indefinite_iterations, r.iterations / 4);
  }
}

TEST(Solve, EveryNamedSolverRoundTripsAndUnknownNamesAreListed) {
  for (const char* name : kSolverNames) EXPECT_EQ(to_string(parse_solver(name)), name);
  EXPECT_EQ(parse_solver("pbd").kind, SolverKind::pbd);
  EXPECT_TRUE(parse_solver("verlet").is_dynamic());
  EXPECT_FALSE(parse_solver("relaxation").is_dynamic());
  try {
    (void)parse_solver("rk4");
    FAIL() << "rk4 accepted";
  } catch (const vessel::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'rk4'"), std::string::npos) << m;
    EXPECT_NE(m.find("implicit-euler, implicit-euler-pcg, implicit-euler-rest, "
                     "implicit-euler-rest-pcg, pbd"),
              std::string::npos)
        << m;
  }
}

TEST(Solve, OneEntryReachesHookesLawWithEveryStaticSolver) {
  // k = 41.106 N/m under 10 mN: u = F/k (Hooke), by Newton, the linearised model and relaxation.
  const double k = 41.106, F = 0.01;
  for (const char* name : {"static", "linear", "relaxation"}) {
    Chain c = make_chain({k}, F);
    const SolveResult r = solve(c.problem, parse_solver(name));
    EXPECT_NEAR(end_displacement(c.problem, r.x), F / k, 1e-6 * F / k) << name;
  }
}

TEST(Solve, DynamicSolversNeedStepsAndPbdNeedsASurfaceNetwork) {
  Chain c = make_chain({41.106}, 0.01);
  SolverSpec verlet = parse_solver("verlet");
  EXPECT_THROW((void)solve(c.problem, verlet), vessel::InputError);  // steps = 0
  verlet.steps = 10;
  int observed = 0;
  const SolveResult r = solve(c.problem, verlet, nullptr, [&](int, const Eigen::VectorXd&) { ++observed; });
  EXPECT_EQ(observed, 10);
  EXPECT_GT(r.dt, 0.0);  // automatic: half the critical-step bound
  EXPECT_NEAR(r.dt, 0.5 * 2.0 / max_frequency_bound(c.problem), 1e-15);
  SolverSpec pbd = parse_solver("pbd");
  pbd.steps = 5;
  EXPECT_THROW((void)solve(c.problem, pbd, &c.net), vessel::InputError);  // a chain has no triangles
  EXPECT_THROW((void)solve(c.problem, pbd), vessel::InputError);
}

TEST(StaticSolver, TrustRegionSnapsToTheClosedFormEquilibriumFromTheSaddle) {
  // The compressed pair starts at a saddle (straight, transverse stiffness < 0): the trust region
  // must follow the negative curvature. Truth as above, by bisection.
  const double k = 10.0, f = 1e-4, L0 = 1.2e-3, h = 1e-3;
  double lo = std::sqrt(L0 * L0 - h * h), hi = 1.0;
  for (int i = 0; i < 200; ++i) {
    const double y = 0.5 * (lo + hi), L = std::hypot(h, y);
    (2 * k * (L - L0) * y / L - f > 0 ? hi : lo) = y;
  }
  Snap s = make_snap(k, f);
  StaticOptions o;
  o.globalisation = StaticGlobalisation::trust_region;
  const StaticResult r = solve_static(s.problem, o);
  EXPECT_NEAR(r.x[4], lo, 1e-12);
  EXPECT_NEAR(r.x[3], 0.0, 1e-15);
  EXPECT_GT(r.negative_curvature_steps, 0);
}

TEST(StaticSolver, TrustRegionFollowsHookesLawOnTheChain) {
  // Springs in series: u = F Σ 1/k_i at the free end (as the line-search test above).
  const std::vector<double> k{10.0, 20.0, 40.0};
  const double F = 1e-2;
  Chain c = make_chain(k, F);
  StaticOptions o;
  o.globalisation = StaticGlobalisation::trust_region;
  const StaticResult r = solve_static(c.problem, o);
  EXPECT_NEAR(end_displacement(c.problem, r.x), F * (1 / 10.0 + 1 / 20.0 + 1 / 40.0), 1e-12);
  EXPECT_EQ(parse_static_globalisation("trust-region"), StaticGlobalisation::trust_region);
  EXPECT_EQ(to_string(StaticGlobalisation::line_search), "line-search");
  EXPECT_THROW((void)parse_static_globalisation("dogleg"), InputError);
}

TEST(StaticSolver, TrustRegionEqualsLineSearchNewtonWhereBothConverge) {
  // Two globalisations of Newton on the same potential; where the line-search Newton converges
  // and the equilibrium is unique (the volume model: positive-definite Hessian on every
  // iteration; the structured level-0 membrane, whose equilibrium both reach) their answers
  // agree to what the residual tolerance allows: |Δx| ≤ ‖residual‖/λ_min, here ≤ 1e-6 ‖u‖.
  for (const ModelType type : {ModelType::volume, ModelType::surface}) {
    VesselParams params;
    if (type == ModelType::surface) params.style = MeshStyle::structured;
    const TetMesh mesh = generate_vessel_mesh(params);
    NetworkOptions no;
    no.model = type;
    no.stiffness = type == ModelType::surface ? StiffnessRule::seed000 : StiffnessRule::seed001;
    const BuiltNetwork built = build_network(mesh, params, no);
    const SpringModel model(built.network);
    ContactPatchSpec spec;
    spec.point = Vec3(3e-3, 0, 20e-3);
    spec.radius = 1e-3;
    spec.force = 1e-3;
    const Problem p =
        make_problem(model, built.network, built.masses, mesh,
                     traction_nodal_loads(mesh, contact_patch(mesh, spec)), {"inlet", "outlet"});
    StaticOptions o;
    const StaticResult ls = solve_static(p, o);
    o.globalisation = StaticGlobalisation::trust_region;
    const StaticResult tr = solve_static(p, o);
    const Eigen::VectorXd u = ls.x - p.rest;
    EXPECT_LT((tr.x - ls.x).norm(), 1e-6 * u.norm()) << (type == ModelType::surface);
    EXPECT_LE(tr.residual, 1e-8 * p.external_force.norm());
    // One factorisation per iteration, never of an indefinite Hessian.
    EXPECT_EQ(tr.numeric_factorisations, tr.iterations);
  }
}

// The exact Hessian's back-off by hand: after each failure the next 1, 2, 4, then at most
// `longest` (4) iterations skip it; a success resets it; with longest 0 every iteration tries.
TEST(ExactBackoff, SkipsDoubleAfterEachFailureUpToTheLongestAndResetOnSuccess) {
  msm::ExactBackoff b(4);
  std::string tried;
  // The exact Hessian fails at every iteration before 14 and works from 14 on.
  for (int it = 0; it < 18; ++it) {
    const bool t = b.try_exact();
    tried += t ? 'T' : '.';
    if (t) b.record(it >= 14);
  }
  // Tried and failed at 0, 2, 5, 10 (skipping 1, 2, 4, 4 after them); tried at 15: it works.
  EXPECT_EQ(tried, "T.T..T....T....TTT");
  msm::ExactBackoff never(0);
  for (int it = 0; it < 5; ++it) {
    EXPECT_TRUE(never.try_exact());
    never.record(false);
  }
}
