// Implicit Euler steps on the unstructured volume model (seed 001 springs, consistent masses) of
// the straight tube at a level, under 1 mN on the default contact patch at mid-length (the
// `vesselverify msm --model volume --stiffness seed001` problem), at dt = 1 ms: each step solved
// by CHOLMOD (implicit-euler-rest: A at rest factorised once; implicit-euler: K at the current
// state refactorised every step) and by warm-started PCG at the tolerances given
// (implicit-euler-rest-pcg, implicit-euler-pcg). Prints, per run, the set-up, the median process
// CPU time per step (steps 2 … N; the first includes first-touch effects), CG iterations per step,
// and the largest relative difference of the positions from the CHOLMOD run over the steps,
// max_s ‖x_s − x_s^direct‖ / ‖x_s^direct − x_0‖. "threads=N" adds implicit-euler-rest with N
// solver threads (set_solver_threads: the solve's two sweeps on N threads) and, for the factor
// of A, the bandwidth bound measured in the same run: the solve alone on 1 and N threads against
// two reads of as many numbers as the factor holds, on 1 and N threads (the sweeps read the
// factor once each; the median of 9). Release build; a measurement driver, not a test
// (docs/measurements/msm_measurements.md).
//
//   implicit_step_benchmark LEVEL STEPS_REST STEPS_CURRENT [TOLERANCE ...] [threads=N]
//   (STEPS_CURRENT = 0 skips the current-state pair; default tolerances 1e-4 1e-6 1e-8; "none":
//   no PCG runs)
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "meshes/mesh_cache.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/linalg/linear_solver.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Run {
  std::vector<Eigen::VectorXd> x;  ///< positions after each step
  double setup = 0.0;              ///< s (wall, as integrate reports it)
  double step_cpu = 0.0;           ///< median CPU s per step over steps 2 … N
  double step_wall = 0.0;          ///< median wall-clock s per step over steps 2 … N
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
  std::vector<double> t, tw;
  // The copy of x is outside the timed interval: the clock is read after it.
  o.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
    r.x.push_back(x);
    t.push_back(cpu_now());
    tw.push_back(wall_now());
  };
  const DynamicResult d = integrate(p, o);
  r.setup = d.setup_seconds;
  r.factor_entries = d.factor_entries;
  r.cg_per_step = static_cast<double>(d.linear_iterations) / std::max(d.steps, 1);
  r.cg_max = d.max_linear_iterations;
  // Step s's CPU time is t[s] − t[s−1] minus the copy in the callback, which is not timed: the
  // copy happens before the clock read, so t[s] − t[s−1] includes one copy (≈ 2 passes over x,
  // 0.1–0.3 ms at level 2, small against the steps measured here).
  std::vector<double> dt, dtw;
  for (std::size_t s = 1; s < t.size(); ++s) {
    dt.push_back(t[s] - t[s - 1]);
    dtw.push_back(tw[s] - tw[s - 1]);
  }
  r.step_cpu = median(dt);
  r.step_wall = median(dtw);
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
            << r.step_cpu * 1e3 << " ms (wall " << r.step_wall * 1e3 << " ms) | ";
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

/// The solve alone (CholmodSolver::solve_into, median of 9) on one and on `threads` threads,
/// against two reads of as many doubles as the factor stores, on as many threads: the bandwidth
/// bound of a solve in the same run.
void bound(const Problem& p, int threads) {
  const double h = 1e-3;
  SparseMatrix K, D;
  p.form->hessian(p.rest, K, true);
  p.form->damping_jacobian(p.rest, D);
  SparseMatrix A = h * h * K + h * D;  // integrators.cpp's implicit_euler_matrix
  for (int i = 0; i < p.num_dofs(); ++i) A.coeffRef(i, i) += p.mass[i];
  apply_dirichlet(A, p.fixed);
  CholmodSolver solver;
  solver.factorize(A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(p.num_dofs(), -1.0, 1.0);
  Eigen::VectorXd x;
  const auto entries = static_cast<std::size_t>(solver.factor_entries());
  const std::vector<double> numbers(entries, 1e-9);
  std::cout << "\nfactor: " << static_cast<double>(entries) / 1e6 << " M numbers ("
            << 8e-6 * static_cast<double>(entries)
            << " MB)\n\n| threads | solve alone (median of 9) | two reads of the factor's size "
               "(median of 9) | read bandwidth |\n| --- | --- | --- | --- |\n";
  for (const int t : {1, threads}) {
    set_solver_threads(t);
    std::vector<double> solve_s, read_s;
    double sink = 0.0;
    for (int r = 0; r < 9; ++r) {
      double t0 = wall_now();
      solver.solve_into(b, x);
      solve_s.push_back(wall_now() - t0);
      std::vector<double> part(static_cast<std::size_t>(t));
      t0 = wall_now();
      std::vector<std::thread> extra;
      auto read = [&](int k) {
        const std::size_t lo = entries * k / t, hi = entries * (k + 1) / t;
        part[k] = Eigen::Map<const Eigen::VectorXd>(numbers.data() + lo,
                                                    static_cast<Eigen::Index>(hi - lo)).sum();
      };
      for (int k = 1; k < t; ++k) extra.emplace_back(read, k);
      read(0);
      for (std::thread& e : extra) e.join();
      read_s.push_back(wall_now() - t0);
      for (const double v : part) sink += v;
    }
    set_solver_threads(1);
    const double one_read = median(read_s);
    std::cout << "| " << t << " (" << solver.last_solve_threads() << " in the solve) | "
              << std::setprecision(3) << median(solve_s) * 1e3 << " ms | " << 2e3 * one_read
              << " ms | " << 8e-9 * static_cast<double>(entries) / one_read << " GB/s |"
              << (sink < 0 ? " " : "") << "\n";
  }
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
  int threads = 1;
  for (int i = 4; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "none") cg = false;  // the CHOLMOD steps alone
    else if (a.rfind("threads=", 0) == 0) threads = std::atoi(a.c_str() + 8);
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
  if (threads > 1) {
    set_solver_threads(threads);
    const Run par = run(p, ImplicitMatrix::rest_prefactored, steps_rest, 0.0);
    set_solver_threads(1);
    row("implicit-euler-rest, solve on " + std::to_string(threads) + " threads", par, "—",
        worst(par, direct, p.rest));
  }
  for (const double tol : tolerances) {
    const Run r = run(p, ImplicitMatrix::rest_pcg, steps_rest, tol);
    std::ostringstream t;
    t << tol;
    row("implicit-euler-rest-pcg", r, t.str(), worst(r, direct, p.rest));
  }
  if (threads > 1) bound(p, threads);
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
