// Accuracy of Liu et al. 2013's local–global solver per iteration count against Newton, on the
// mass-spring models of a scene (default verification/scenes/contact_straight.toml): the static
// problem (local-global vs solve_static) and one implicit Euler step (local-global-euler vs the
// same step solved by Newton to convergence, implicit_euler_step_newton), with set-up and
// per-iteration times. Prints Markdown tables (docs/measurements/msm_measurements.md). Release build.
//
//   local_global_accuracy [scene.toml] [force N] [dt s]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "msm/terms/spring_model.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/local_global.hpp"
#include "msm/solvers/static_solver.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

const std::vector<int> kIterations{1, 2, 5, 10, 20, 50};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string sci(double v, int digits = 2) {
  std::ostringstream s;
  s << std::scientific << std::setprecision(digits) << v;
  return s.str();
}

/// Displacement of the node nearest the contact point, m (the scenes' QoI).
double qoi(const msm::Problem& p, const Eigen::VectorXd& x, std::size_t node) {
  return (x.segment<3>(3 * static_cast<Eigen::Index>(node)) -
          p.rest.segment<3>(3 * static_cast<Eigen::Index>(node)))
      .norm();
}

/// Time per local–global iteration (local step + global step), set-up apart: the median of 5
/// runs of 10; `setup_seconds` receives the system's set-up time.
double local_global_iteration_seconds(const msm::Problem& p, double& setup_seconds) {
  const msm::LocalGlobalSystem sys(p, 0.0, "local-global");
  const Eigen::VectorXd b = sys.constant_rhs(Eigen::VectorXd(), Eigen::VectorXd());
  Eigen::VectorXd x = p.rest;
  msm::SpringDirections d;
  std::vector<double> ts;
  for (int r = 0; r < 5; ++r) {
    const double t = now();
    for (int i = 0; i < 10; ++i) {
      sys.local_step(x, d);
      sys.global_step(d, b, x);
    }
    ts.push_back((now() - t) / 10);
  }
  setup_seconds = sys.setup_seconds();
  return median(ts);
}

/// The static problem: local–global after kIterations iterations against Newton's solution.
void statics_table(const msm::Problem& p, std::size_t node) {
  double t = now();
  const msm::StaticResult newton = msm::solve_static(p);
  const double newton_s = now() - t;
  const Eigen::VectorXd u = newton.x - p.rest;
  const double q_ref = qoi(p, newton.x, node);
  msm::LocalGlobalOptions o;
  o.max_iterations = 20000;
  std::vector<std::pair<double, double>> at(kIterations.size());  // (relative error, QoI error)
  o.on_half_step = [&](int it, bool global, const Eigen::VectorXd& x, double) {
    if (!global) return;
    const auto k = std::find(kIterations.begin(), kIterations.end(), it);
    if (k == kIterations.end()) return;
    at[static_cast<std::size_t>(k - kIterations.begin())] = {(x - newton.x).norm() / u.norm(),
                                                             std::abs(qoi(p, x, node) - q_ref)};
  };
  std::string converged;
  try {
    const msm::StaticResult lg = msm::solve_static_local_global(p, o);
    converged = std::to_string(lg.iterations) + " iterations, " + sci(lg.seconds) + " s";
  } catch (const std::runtime_error& e) {
    converged = std::string("not within 20000 iterations");
  }
  double setup = 0.0;
  const double per_iteration = local_global_iteration_seconds(p, setup);
  std::cout << "Statics: Newton " << newton.iterations << " iterations, " << sci(newton_s)
            << " s; QoI " << sci(q_ref * 1e3, 4) << " mm. Local-global set-up " << sci(setup)
            << " s, " << sci(per_iteration * 1e3)
            << " ms per iteration (median of 5 × 10), to the 1e-8 gradient tolerance: "
            << converged << ".\n\n";
  std::cout
      << "| iterations | rel. error ‖x − x_Newton‖/‖u‖ | QoI error (mm) |\n| --- | --- | --- |\n";
  for (std::size_t i = 0; i < kIterations.size(); ++i) {
    std::cout << "| " << kIterations[i] << " | " << sci(at[i].first) << " | "
              << sci(at[i].second * 1e3) << " |\n";
  }
}

/// One implicit Euler step of the load applied at t = 0: the state after 4 steps (Newton, to
/// convergence) is the step's start, so the step has momentum as well as the load. The
/// linearised step and local–global after kIterations iterations against Newton's step.
void implicit_step_table(const msm::Problem& p, std::size_t node, double dt) {
  Eigen::VectorXd x = p.rest, v = Eigen::VectorXd::Zero(p.num_dofs());
  msm::StaticOptions tight;
  tight.tolerance = 1e-12;
  for (int s = 0; s < 4; ++s) {
    const Eigen::VectorXd x1 = msm::implicit_euler_step_newton(p, x, v, dt, tight);
    v = (x1 - x) / dt;
    x = x1;
  }
  const double t = now();
  const Eigen::VectorXd ref = msm::implicit_euler_step_newton(p, x, v, dt, tight);
  const double newton_step_s = now() - t;
  msm::DynamicOptions lin;
  lin.integrator = msm::Integrator::implicit_euler;
  lin.dt = dt;
  lin.steps = 1;
  const msm::DynamicResult linear = msm::integrate(p, lin, x, v);
  const double step = (ref - x).norm();
  std::cout << "\nImplicit Euler step of " << dt << " s (the 5th after the load is applied): "
            << "Newton to convergence " << sci(newton_step_s) << " s; the linearised step "
            << "(implicit-euler, one Newton iteration) " << sci(linear.seconds) << " s, rel. error "
            << sci((linear.x - ref).norm() / step) << ".\n\n";
  std::cout << "| iterations | rel. error ‖x − x_Newton‖/‖x_Newton − x_n‖ | QoI error (mm) | "
               "time per step (ms, median of 5) | set-up (ms) |\n| --- | --- | --- | --- | --- |\n";
  for (const int k : kIterations) {
    msm::LocalGlobalOptions lo;
    lo.iterations = k;
    msm::DynamicOptions d;
    d.dt = dt;
    d.steps = 1;
    std::vector<double> ts, setups;
    msm::DynamicResult r;
    for (int rep = 0; rep < 5; ++rep) {
      r = msm::integrate_local_global(p, d, lo, x, v);
      ts.push_back(r.seconds);
      setups.push_back(r.setup_seconds);
    }
    std::cout << "| " << k << " | " << sci((r.x - ref).norm() / step) << " | "
              << sci(std::abs(qoi(p, r.x, node) - qoi(p, ref, node)) * 1e3) << " | "
              << sci(median(ts) * 1e3) << " | " << sci(median(setups) * 1e3) << " |\n";
  }
}

void measure(const Scene& scene, const ModelSpec& spec, int level, double force, double dt) {
  const TetMesh mesh = scene_mesh(scene, level, "");
  VesselParams vessel = scene.vessel;
  vessel.level = level;
  const double nu = scene.poisson_ratios.front();
  const msm::BuiltNetwork built =
      msm::build_network(mesh, vessel, network_options(scene, spec, nu));
  const msm::SpringModel model(built.network, spec.damping);
  const msm::Problem p = msm_problem(scene, model, built, mesh, force);
  const std::size_t node = nearest_node(built.network.nodes, qoi_point(scene));
  std::cout << "\n### " << spec.name << ", level " << level << ": " << built.network.nodes.size()
            << " nodes, " << built.network.springs.size() << " springs, force " << force
            << " N\n\n";
  statics_table(p, node);
  implicit_step_table(p, node, dt);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Scene scene =
        read_scene(argc > 1 ? argv[1] : "verification/scenes/contact_straight.toml");
    const double force = argc > 2 ? std::stod(argv[2]) : scene.budget.magnitude;
    const double dt = argc > 3 ? std::stod(argv[3]) : 1e-3;
    for (const ModelSpec& spec : scene.models) {
      if (spec.kind == ModelKind::volume_msm) {
        for (int level : {0, 1}) measure(scene, spec, level, force, dt);
      } else if (spec.kind == ModelKind::surface_msm) {
        measure(scene, spec, 0, force, dt);
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "local_global_accuracy: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
