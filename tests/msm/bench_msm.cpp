// Google Benchmark of the mass-spring hot paths on the default vessel (level 0): gradient,
// Hessian assembly, CHOLMOD factorisation, one symplectic Euler step. Not a test: run
// build/tests/msm/msm_bench by hand; timings belong in reports, not in assertions.
#include <benchmark/benchmark.h>

#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/linalg/linear_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

struct Fixture {
  TetMesh mesh = generate_vessel_mesh(VesselParams{});
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
  explicit Fixture(bool volume) {
    const VesselParams params;
    net = volume ? build_volume_network(mesh)
                 : build_triangle_network(wall_surface(mesh, params, WallSurface::inner), 1e-3);
    assign_stiffness(net, volume ? StiffnessRule::seed001 : StiffnessRule::seed000, {});
    model = std::make_unique<SpringModel>(net);
    ContactPatchSpec spec;
    spec.point = Vec3(3e-3, 0, 20e-3);
    spec.force = 1e-3;
    problem = make_problem(*model, net, nodal_masses(net, MassRule::consistent, kVesselDensity),
                           mesh, traction_nodal_loads(mesh, contact_patch(mesh, spec)),
                           {"inlet", "outlet"});
  }
};

Fixture& fixture(bool volume) {
  static Fixture surface(false), vol(true);
  return volume ? vol : surface;
}

void BM_Gradient(benchmark::State& state) {
  Fixture& f = fixture(state.range(0) != 0);
  Eigen::VectorXd g;
  for (auto _ : state) {
    f.model->gradient(f.problem.rest, g);
    benchmark::DoNotOptimize(g.data());
  }
  state.counters["springs"] = static_cast<double>(f.net.springs.size());
}
BENCHMARK(BM_Gradient)->Arg(0)->Arg(1);

void BM_Hessian(benchmark::State& state) {
  Fixture& f = fixture(state.range(0) != 0);
  SparseMatrix H;
  for (auto _ : state) {
    f.model->hessian(f.problem.rest, H, true);
    benchmark::DoNotOptimize(H.valuePtr());
  }
}
BENCHMARK(BM_Hessian)->Arg(0)->Arg(1);

void BM_CholmodFactorisation(benchmark::State& state) {
  Fixture& f = fixture(state.range(0) != 0);
  SparseMatrix H;
  f.model->hessian(f.problem.rest, H, true);
  apply_dirichlet(H, f.problem.fixed);
  CholmodSolver solver;
  solver.factorize(H);  // symbolic analysis once
  for (auto _ : state) solver.factorize(H);
  state.counters["unknowns"] = static_cast<double>(H.rows());
}
BENCHMARK(BM_CholmodFactorisation)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_SymplecticEulerStep(benchmark::State& state) {
  Fixture& f = fixture(state.range(0) != 0);
  DynamicOptions o;
  o.integrator = Integrator::symplectic_euler;
  o.dt = 0.5 * 2.0 / max_frequency_bound(f.problem);
  o.steps = 10;
  for (auto _ : state) benchmark::DoNotOptimize(integrate(f.problem, o).x.data());
  state.SetItemsProcessed(state.iterations() * o.steps);
}
BENCHMARK(BM_SymplecticEulerStep)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
