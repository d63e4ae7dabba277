// Time per update of each rod model at N = 50, 200, 1000 segments, set-up apart (Google
// Benchmark; Release build). A 1 m, 1 mm nitinol-like cantilever held at α = PL²/EI = 1:
//  - *NewtonUpdate: the tip load moves by 1 % and the static equilibrium is solved again from
//    the previous one (what a quasi-static haptic loop does each frame);
//  - XpbdStep: one XPBD step (h = 1 ms, 4 Gauss–Seidel sweeps, multipliers restarted each step:
//    Macklin et al.'s XPBD) under the same load;
//  - XpbdDirectStep/N/k: one XPBD step (h = 1 ms) with k direct iterations (a block-tridiagonal
//    Cholesky of all constraint blocks per iteration, multipliers carried between steps), the
//    fast path;
// XPBD rows start after 100 steps and report the tip's deflection (tip_y_over_L; Newton's is
// 0.3017 at N = ∞).
//  - DerImplicitStep: one implicit Euler step (msm/solvers/integrators, implicit-euler: the
//    stiffness at the step's state, refactorised each step), dt = 1 ms, the same tip load. The
//    prefactored variant (implicit-euler-rest) diverges here (N = 50, step 18): the stiffness at
//    rest lacks the bent rod's geometric stiffness.
#include <benchmark/benchmark.h>

#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rod_statics.hpp"
#include "msm/rods/xpbd_rod.hpp"
#include "msm/solvers/integrators.hpp"

namespace {

using namespace vessel::msm;
using namespace vessel::msm::rods;

const RodMaterial kMaterial{50e9, 50e9 / 2.66, 6450.0};
constexpr double kLength = 1.0, kDiameter = 1e-3;

// DER's update is timed at the static solver's default tolerance (CORDE's KKT Newton at 1e-10).
constexpr double kDerTolerance = 1e-8;

double tip_load(double alpha) {
  return alpha * solid_section(kMaterial, kDiameter).EI / (kLength * kLength);
}

void BM_DerNewtonUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  DerRod rod(make_layout(uniform_rod(kMaterial, kLength, kDiameter, n)));
  RodStaticLoad load;
  load.force = VectorXd::Zero(rod.num_dofs());
  const int tip = 3 * rod.layout().tip_node + 1;
  load.force[tip] = tip_load(1.0);
  load.start = solve_rod_static(rod, load, kDerTolerance).x;
  int iterations = 0, k = 0;
  for (auto _ : state) {
    load.force[tip] = tip_load(++k % 2 ? 1.01 : 1.0);
    const RodStaticResult r = solve_rod_static(rod, load, kDerTolerance);
    load.start = r.x;
    iterations += r.newton_iterations;
  }
  state.counters["newton_per_update"] =
      benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
}

void BM_CordeNewtonUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  CordeRod rod(make_layout(uniform_rod(kMaterial, kLength, kDiameter, n)));
  RodStaticLoad load;
  load.force = VectorXd::Zero(rod.num_dofs());
  const int tip = 3 * rod.layout().tip_node + 1;
  load.force[tip] = tip_load(1.0);
  load.start = solve_rod_static(rod, load).x;
  int iterations = 0, k = 0;
  for (auto _ : state) {
    load.force[tip] = tip_load(++k % 2 ? 1.01 : 1.0);
    const RodStaticResult r = solve_rod_static(rod, load);
    load.start = r.x;
    iterations += r.newton_iterations;
  }
  state.counters["newton_per_update"] =
      benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
}

void BM_DerImplicitStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  DerRod rod(make_layout(uniform_rod(kMaterial, kLength, kDiameter, n)));
  Problem problem;
  problem.form = &rod;
  problem.rest = rod.rest_state();
  problem.mass = rod.lumped_mass();
  problem.fixed = rod.clamp_fixed();
  problem.external_force = VectorXd::Zero(rod.num_dofs());
  problem.external_force[3 * rod.layout().tip_node + 1] = tip_load(1.0);
  DynamicOptions options;
  options.integrator = Integrator::implicit_euler;
  options.implicit_matrix = ImplicitMatrix::current_state;
  options.dt = 1e-3;
  constexpr int kSteps = 20;
  options.steps = kSteps;
  VectorXd x = problem.rest, v = VectorXd::Zero(problem.rest.size());
  for (auto _ : state) {
    const DynamicResult r = integrate(problem, options, x, v);  // set-up timed apart
    state.SetIterationTime(r.seconds / kSteps);
    x = r.x;
    v = r.v;
  }
}

void BM_XpbdStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  XpbdOptions options;
  options.solver = XpbdSolver::gauss_seidel;
  options.iterations = 4;
  options.warm_start = false;  // Macklin et al.'s XPBD
  XpbdRod rod(make_layout(uniform_rod(kMaterial, kLength, kDiameter, n)), 0.0, options);
  VectorXd force = VectorXd::Zero(rod.state().size());
  force[3 * rod.tip_node() + 1] = tip_load(1.0);
  for (int k = 0; k < 100; ++k) rod.step(1e-3, force);  // past the first steps' transient
  for (auto _ : state) rod.step(1e-3, force);
  if (!rod.state().allFinite()) state.SkipWithError("the XPBD state is not finite");
  state.counters["tip_y_over_L"] = rod.state()[3 * rod.tip_node() + 1] / kLength;
}

void BM_XpbdDirectStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  XpbdOptions options;
  options.solver = XpbdSolver::direct;
  options.iterations = static_cast<int>(state.range(1));
  XpbdRod rod(make_layout(uniform_rod(kMaterial, kLength, kDiameter, n)), 0.0, options);
  VectorXd force = VectorXd::Zero(rod.state().size());
  force[3 * rod.tip_node() + 1] = tip_load(1.0);
  for (int k = 0; k < 100; ++k) rod.step(1e-3, force);
  for (auto _ : state) rod.step(1e-3, force);
  if (!rod.state().allFinite()) state.SkipWithError("the XPBD state is not finite");
  state.counters["tip_y_over_L"] = rod.state()[3 * rod.tip_node() + 1] / kLength;
}

}  // namespace

BENCHMARK(BM_XpbdStep)->Arg(50)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_XpbdDirectStep)
    ->Args({50, 1})->Args({200, 1})->Args({1000, 1})->Args({50, 2})->Args({200, 2})->Args({1000, 2})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DerNewtonUpdate)->Arg(50)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CordeNewtonUpdate)->Arg(50)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DerImplicitStep)
    ->Arg(50)->Arg(200)->Arg(1000)->UseManualTime()->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
