// The explicit integrators (which take ∇E from the previous step's check, computed with the energy
// in one pass) against the textbook updates written out here with separate gradient and energy
// calls, on a damped volume network with loads and fixed nodes.
#include <gtest/gtest.h>

#include <random>

#include "meshes/gmsh_vessel.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/integrators.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// m a = −∇E(x) + f_damp(x, v) + f_ext, zero on fixed dofs.
Eigen::VectorXd acceleration(const Problem& p, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
  Eigen::VectorXd g, d;
  p.form->gradient(x, g);
  p.form->damping_force(x, v, d);
  Eigen::VectorXd a = (-g + d + p.external_force).cwiseQuotient(p.mass);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (p.fixed[i]) a[i] = 0.0;
  }
  return a;
}

}  // namespace

TEST(ExplicitSteps, MatchTheTextbookUpdatesAndReportTheEnergyOfTheFinalState) {
  VesselParams params;
  const TetMesh mesh = generate_vessel_mesh(params);
  NetworkOptions o;
  o.model = ModelType::volume;
  o.stiffness = StiffnessRule::seed001;
  o.axial_damping = 1e-4;
  const BuiltNetwork built = build_network(mesh, params, o);
  SpringModel model(built.network, 1e-6);
  Problem p;
  p.form = &model;
  p.rest = flatten(built.network.nodes);
  const Eigen::Index n = p.rest.size();
  p.mass.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) p.mass[i] = built.masses[static_cast<std::size_t>(i / 3)];
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1e-4);
  p.external_force = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) p.external_force[i] = noise(rng);
  p.fixed.assign(static_cast<std::size_t>(n), 0);
  for (Eigen::Index i = 0; i < 30; ++i) p.fixed[static_cast<std::size_t>(i)] = 1;
  const double h = 0.2 * 2.0 / max_frequency_bound(p);
  Eigen::VectorXd v0(n);
  for (Eigen::Index i = 0; i < n; ++i) v0[i] = p.fixed[i] ? 0.0 : 1e-3 * noise(rng);
  const int steps = 25;
  for (Integrator integrator :
       {Integrator::explicit_euler, Integrator::symplectic_euler, Integrator::verlet}) {
    DynamicOptions opt;
    opt.integrator = integrator;
    opt.dt = h;
    opt.steps = steps;
    const DynamicResult r = integrate(p, opt, p.rest, v0);
    Eigen::VectorXd x = p.rest, v = v0;
    for (int s = 0; s < steps; ++s) {
      if (integrator == Integrator::explicit_euler) {  // seed 000 eq. (3.7)
        const Eigen::VectorXd a = acceleration(p, x, v);
        x += h * v;
        v += h * a;
      } else if (integrator == Integrator::symplectic_euler) {
        v += h * acceleration(p, x, v);
        x += h * v;
      } else {  // velocity Verlet
        const Eigen::VectorXd v_half = v + 0.5 * h * acceleration(p, x, v);
        x += h * v_half;
        v = v_half + 0.5 * h * acceleration(p, x, v_half);
      }
    }
    const double dx = (r.x - x).lpNorm<Eigen::Infinity>() / (x - p.rest).lpNorm<Eigen::Infinity>();
    const double dv = (r.v - v).lpNorm<Eigen::Infinity>() / v.lpNorm<Eigen::Infinity>();
    EXPECT_LT(dx, 1e-12) << to_string(integrator);
    EXPECT_LT(dv, 1e-12) << to_string(integrator);
    // The reported energy is ½vᵀMv + E(x) − f·(x − x0) of the final state, E by its own pass.
    const double e = 0.5 * v.dot(p.mass.cwiseProduct(v)) + model.reference_energy(x) -
                     p.external_force.dot(x - p.rest);
    EXPECT_NEAR(r.energy, e, 1e-10 * std::abs(e)) << to_string(integrator);
  }
}
