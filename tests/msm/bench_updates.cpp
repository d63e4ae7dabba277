// Google Benchmark: the time per update of prepared models (msm/solvers/updates.hpp) against the
// cold solve from rest they replace, on the models issue 13 sets targets for: the linearised
// level-0 surface model (seed 000's structured grid, uniform k; target ≤ 0.1 ms per update) and
// the level-1 volume model (seed 001; target ≤ 5 ms), structured straight tube, contact patch at
// mid-length. Set-up (assembly, factorisation at rest) is outside the timed loop. Not a test:
// run build/tests/msm/updates_bench by hand (Release); the figures go in docs/measurements/msm_measurements.md.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/solvers/updates.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// A model of the straight structured tube under the contact patch (3 mm, 0, 20 mm; r = 1 mm).
struct Fixture {
  TetMesh mesh;
  BuiltNetwork built;
  std::unique_ptr<SpringModel> model;
  Problem problem;  ///< at 0.5 mN (contact_straight's budget load)
  Fixture(ModelType type, int level) {
    VesselParams params;
    params.style = MeshStyle::structured;
    params.level = level;
    mesh = generate_vessel_mesh(params);
    NetworkOptions o;
    o.model = type;
    o.surface = WallSurface::mid;
    o.stiffness = type == ModelType::surface ? StiffnessRule::uniform : StiffnessRule::seed001;
    built = build_network(mesh, params, o);
    model = std::make_unique<SpringModel>(built.network);
    ContactPatchSpec spec;
    spec.point = Vec3(3e-3, 0, 20e-3);
    spec.radius = 1e-3;
    spec.force = 5e-4;
    problem = make_problem(*model, built.network, built.masses, mesh,
                           traction_nodal_loads(mesh, contact_patch(mesh, spec)),
                           {"inlet", "outlet"});
  }
};

/// range(0): 0 the level-0 surface model, 1 the level-1 volume model.
Fixture& fixture(const benchmark::State& state) {
  static std::map<int64_t, std::unique_ptr<Fixture>> cache;
  auto& f = cache[state.range(0)];
  if (!f) {
    f = state.range(0) == 0 ? std::make_unique<Fixture>(ModelType::surface, 0)
                            : std::make_unique<Fixture>(ModelType::volume, 1);
  }
  return *f;
}

void label(benchmark::State& state, const Fixture& f) {
  int loaded = 0;  // the patch's free dofs: the responses a linear updater precomputes
  for (Eigen::Index i = 0; i < f.problem.num_dofs(); ++i) {
    if (!f.problem.fixed[i] && f.problem.external_force[i] != 0.0) ++loaded;
  }
  state.SetLabel((state.range(0) == 0 ? "surface L0, " : "volume L1, ") +
                 std::to_string(f.problem.num_dofs()) + " dofs, " + std::to_string(loaded) +
                 " loaded");
}

/// One linear update on the contact patch (the superposition of the responses precomputed at
/// set-up for the patch's dofs), the load alternating between two magnitudes so that every
/// update changes it.
void BM_LinearUpdate(benchmark::State& state) {
  Fixture& f = fixture(state);
  const auto up = prepare_updates(f.problem, parse_solver("linear"));
  const Eigen::VectorXd a = f.problem.external_force, b = 0.5 * a;
  bool flip = false;
  for (auto _ : state) {
    up->update((flip = !flip) ? a : b);
    benchmark::DoNotOptimize(up->state().data());
  }
  label(state, f);
}
BENCHMARK(BM_LinearUpdate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// The same updates by one CHOLMOD solve each: the updater prepared without a load, so that no
/// responses are precomputed (what every linear update was before the superposition).
void BM_LinearUpdateBySolve(benchmark::State& state) {
  Fixture& f = fixture(state);
  Problem unloaded = f.problem;
  unloaded.external_force.setZero();
  const auto up = prepare_updates(unloaded, parse_solver("linear"));
  const Eigen::VectorXd a = f.problem.external_force, b = 0.5 * a;
  bool flip = false;
  for (auto _ : state) {
    up->update((flip = !flip) ? a : b);
    benchmark::DoNotOptimize(up->state().data());
  }
  label(state, f);
}
BENCHMARK(BM_LinearUpdateBySolve)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// What the harness timed before: solve_linear (assembly, factorisation and solve) per update.
void BM_LinearColdSolve(benchmark::State& state) {
  Fixture& f = fixture(state);
  for (auto _ : state) benchmark::DoNotOptimize(solve_linear(f.problem).x.data());
  label(state, f);
}
BENCHMARK(BM_LinearColdSolve)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// Static Newton: one update of a ramp in 8 steps to the load and back (warm-started, modified
/// Newton while the held factorisation converges fast), against a cold solve from rest.
void BM_StaticUpdate(benchmark::State& state) {
  Fixture& f = fixture(state);
  const auto up = prepare_updates(f.problem, parse_solver("static"));
  int k = 0;
  for (auto _ : state) {
    const int step = k < 8 ? k + 1 : 16 - k;  // 1 … 8 … 1
    k = (k + 1) % 16;
    up->update(f.problem.external_force * (step / 8.0));
    benchmark::DoNotOptimize(up->state().data());
  }
  label(state, f);
}
BENCHMARK(BM_StaticUpdate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_StaticColdSolve(benchmark::State& state) {
  Fixture& f = fixture(state);
  for (auto _ : state) benchmark::DoNotOptimize(solve_static(f.problem).x.data());
  label(state, f);
}
BENCHMARK(BM_StaticColdSolve)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
