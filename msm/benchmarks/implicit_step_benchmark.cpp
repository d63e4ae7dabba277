// Implicit Euler steps on the unstructured volume model (seed 001 springs, consistent masses) of
// the straight tube at a level, under 1 mN on the default contact patch at mid-length (the
// `vesselverify msm --model volume --stiffness seed001` problem), at dt = 1 ms: each step solved
// by CHOLMOD (implicit-euler-rest: A at rest factorised once; implicit-euler: K at the current
// state refactorised every step) and by warm-started PCG at the tolerances given
// (implicit-euler-rest-pcg, implicit-euler-pcg). Prints, per run, the set-up, the median process
// CPU time per step (steps 2 … N; the first includes first-touch effects), CG iterations per step,
// and the largest relative difference of the positions from the CHOLMOD run over the steps,
// max_s ‖x_s − x_s^direct‖ / ‖x_s^direct − x_0‖. Release build; a measurement driver, not a test
// (docs/msm_measurements.md).
//
//   implicit_step_benchmark LEVEL STEPS_REST STEPS_CURRENT [TOLERANCE ...]
//   (STEPS_CURRENT = 0 skips the current-state pair; default tolerances 1e-4 1e-6 1e-8; "none":
//   no PCG runs)
#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "meshes/mesh_cache.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/spring_model.hpp"
#include "msm/solvers/integrators.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Run {
  std::vector<Eigen::VectorXd> x;  ///< positions after each step
  double setup = 0.0;              ///< s (wall, as integrate reports it)
  double step_cpu = 0.0;           ///< median CPU s per step over steps 2 … N
  double cg_per_step = 0.0;
  int cg_max = 0;
  double factor_entries = 0.0;
};

Run run(const Problem& p, ImplicitMatrix matrix, int steps, double tolerance) {
  DynamicOptions o;
  o.integrator = Integrator::implicit_euler;
  o.implicit_matrix = matrix;
  o.dt = 1e-3;
  o.steps = steps;
  o.pcg.tolerance = tolerance;
  Run r;
  std::vector<double> t;
  // The copy of x is outside the timed interval: the clock is read after it.
  o.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
    r.x.push_back(x);
    t.push_back(cpu_now());
  };
  const DynamicResult d = integrate(p, o);
  r.setup = d.setup_seconds;
  r.factor_entries = d.factor_entries;
  r.cg_per_step = static_cast<double>(d.linear_iterations) / std::max(d.steps, 1);
  r.cg_max = d.max_linear_iterations;
  // Step s's CPU time is t[s] − t[s−1] minus the copy in the callback, which is not timed: the
  // copy happens before the clock read, so t[s] − t[s−1] includes one copy (≈ 2 passes over x,
  // 0.1–0.3 ms at level 2, small against the steps measured here).
  std::vector<double> dt;
  for (std::size_t s = 1; s < t.size(); ++s) dt.push_back(t[s] - t[s - 1]);
  std::sort(dt.begin(), dt.end());
  r.step_cpu = dt.empty() ? 0.0 : dt[dt.size() / 2];
  return r;
}

double worst(const Run& a, const Run& ref, const Eigen::VectorXd& rest) {
  double w = 0.0;
  for (std::size_t s = 0; s < std::min(a.x.size(), ref.x.size()); ++s) {
    w = std::max(w, (a.x[s] - ref.x[s]).norm() / (ref.x[s] - rest).norm());
  }
  return w;
}

void row(const std::string& name, const Run& r, const std::string& tol, double error) {
  std::cout << "| " << name << " | " << tol << " | " << std::setprecision(3) << r.setup << " s | "
            << r.step_cpu * 1e3 << " ms | ";
  if (r.cg_max > 0) {
    std::cout << r.cg_per_step << " (max " << r.cg_max << ")";
  } else {
    std::cout << "—";
  }
  std::cout << " | ";
  if (error >= 0) {
    std::cout << std::scientific << std::setprecision(2) << error << std::defaultfloat;
  } else {
    std::cout << "reference";
  }
  std::cout << " |\n" << std::flush;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: implicit_step_benchmark LEVEL STEPS_REST STEPS_CURRENT [TOLERANCE ...]\n";
    return 2;
  }
  const int level = std::atoi(argv[1]);
  const int steps_rest = std::atoi(argv[2]);
  const int steps_current = std::atoi(argv[3]);
  std::vector<double> tolerances;
  bool cg = true;
  for (int i = 4; i < argc; ++i) {
    if (std::string(argv[i]) == "none") cg = false;  // the CHOLMOD steps alone
    else tolerances.push_back(std::atof(argv[i]));
  }
  if (tolerances.empty() && cg) tolerances = {1e-4, 1e-6, 1e-8};

  VesselParams params;
  params.level = level;
  const TetMesh mesh = load_or_generate_vessel(params, default_cache_dir(), {});
  NetworkOptions no;
  no.model = ModelType::volume;
  no.stiffness = StiffnessRule::seed001;
  const BuiltNetwork built = build_network(mesh, params, no);
  const SpringModel model(built.network);
  ContactPatchSpec patch;
  patch.point = Vec3(params.inner_radius, 0.0, 0.5 * params.length);
  patch.force = 1e-3;
  const Problem p = make_problem(model, built.network, built.masses, mesh,
                                 traction_nodal_loads(mesh, contact_patch(mesh, patch)),
                                 {"inlet", "outlet"});
  std::cout << "level " << level << ": " << built.network.nodes.size() << " nodes, "
            << built.network.springs.size() << " springs, " << p.num_dofs() << " dofs\n\n"
            << "| step solved by | CG tolerance | set-up | CPU per step (median) | CG iterations "
               "per step | worst relative difference from CHOLMOD |\n| --- | --- | --- | --- | "
               "--- | --- |\n";
  const Run direct = run(p, ImplicitMatrix::rest_prefactored, steps_rest, 0.0);
  row("implicit-euler-rest (CHOLMOD, factor " + std::to_string(direct.factor_entries / 1e6) +
          " M entries)",
      direct, "—", -1.0);
  for (const double tol : tolerances) {
    const Run r = run(p, ImplicitMatrix::rest_pcg, steps_rest, tol);
    std::ostringstream t;
    t << tol;
    row("implicit-euler-rest-pcg", r, t.str(), worst(r, direct, p.rest));
  }
  if (steps_current > 0) {
    const Run cur = run(p, ImplicitMatrix::current_state, steps_current, 0.0);
    row("implicit-euler (CHOLMOD every step)", cur, "—", -1.0);
    for (const double tol : tolerances) {
      const Run r = run(p, ImplicitMatrix::current_pcg, steps_current, tol);
      std::ostringstream t;
      t << tol;
      row("implicit-euler-pcg", r, t.str(), worst(r, cur, p.rest));
    }
  }
  return 0;
}
