// Google Benchmark: a region-of-interest solve with the held nodes' unknowns removed
// (msm/model/roi) against the same region held by identity rows in the full system (what
// Problem::fixed alone gives: the full matrix, its fill-in and every spring's Hessian block stay).
// Volume model (seed 001) on the structured straight tube at level 1, contact at mid-length,
// static Newton. Not a test: run build/tests/msm/roi_bench by hand; the figures go in the README.
#include <benchmark/benchmark.h>

#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/model/roi.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

const Vec3 kContact(3e-3, 0, 20e-3);

struct Fixture {
  TetMesh mesh;
  msm::SpringNetwork net;
  std::unique_ptr<msm::SpringModel> model;
  msm::Problem problem;
  Fixture() {
    VesselParams params;
    params.style = MeshStyle::structured;
    params.level = 1;
    mesh = generate_vessel_mesh(params);
    net = msm::build_volume_network(mesh);
    msm::assign_stiffness(net, msm::StiffnessRule::seed001, {});
    model = std::make_unique<msm::SpringModel>(net);
    ContactPatchSpec spec;
    spec.point = kContact;
    spec.radius = 1e-3;
    spec.force = 1e-4;
    problem = msm::make_problem(
        *model, net, msm::nodal_masses(net, msm::MassRule::consistent, msm::kVesselDensity), mesh,
        traction_nodal_loads(mesh, contact_patch(mesh, spec)), {"inlet", "outlet"});
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

/// R in mm from the benchmark argument; 0: the whole vessel.
double radius(const benchmark::State& state) { return static_cast<double>(state.range(0)) * 1e-3; }

void BM_HeldByIdentityRows(benchmark::State& state) {
  Fixture& f = fixture();
  msm::Problem p = f.problem;
  if (radius(state) > 0) {
    const std::vector<char> held = held_nodes(f.problem, kContact, radius(state));
    for (std::size_t i = 0; i < held.size(); ++i) {
      if (held[i]) p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
    }
  }
  for (auto _ : state) benchmark::DoNotOptimize(msm::solve_static(p).x.data());
}

void BM_Eliminated(benchmark::State& state) {
  Fixture& f = fixture();
  const std::vector<char> held = held_nodes(f.problem, kContact, radius(state));
  const RoiNetwork roi = restrict_network(f.net, held);
  const msm::SpringModel model(roi.network);
  const msm::Problem p = restrict_problem(f.problem, roi, held, model);
  state.counters["unknowns"] = static_cast<double>(std::count(p.fixed.begin(), p.fixed.end(), 0));
  for (auto _ : state) benchmark::DoNotOptimize(msm::solve_static(p).x.data());
}

}  // namespace

BENCHMARK(BM_HeldByIdentityRows)
    ->Arg(0)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Eliminated)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
