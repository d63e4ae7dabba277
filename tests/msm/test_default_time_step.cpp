// The default explicit time step (resolved_time_step) with damping: at most the guaranteed damped
// step of the stability study (computed here with the full spectrum, lowest mode included), and
// runs that stay bounded at it where the old default (0.5 × the undamped bound) diverges, on the
// level-0 tube's volume model with its consistent (non-uniform) masses.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "meshes/gmsh_vessel.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/critical_step.hpp"
#include "msm/stability/stability_search.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

struct TubeModel {
  SpringNetwork net;
  std::vector<double> masses;
  TetMesh mesh;
};

const TubeModel& tube() {
  static const TubeModel t = [] {
    TubeModel c;
    c.mesh = generate_vessel_mesh(VesselParams{});
    c.net = build_volume_network(c.mesh);
    assign_stiffness(c.net, StiffnessRule::seed001, StiffnessParams{});
    c.masses = nodal_masses(c.net, MassRule::consistent, kVesselDensity);
    return c;
  }();
  return t;
}

Problem problem_of(const SpringModel& model) {
  const TubeModel& t = tube();
  return make_problem(model, t.net, t.masses, t.mesh, {}, {"inlet", "outlet"});
}

double mean_free_mass(const Problem& p) {
  double sum = 0.0;
  int n = 0;
  for (int i = 0; i < p.num_dofs(); ++i) {
    if (!p.fixed[i]) {
      sum += p.mass[i];
      ++n;
    }
  }
  return sum / n;
}

}  // namespace

TEST(DefaultTimeStep, UndampedIsHalfTheGershgorinBound) {
  const SpringModel model(tube().net);
  const Problem p = problem_of(model);
  const double bound = 2.0 / max_frequency_bound(p);
  for (const char* name : {"explicit-euler", "symplectic-euler", "verlet"}) {
    EXPECT_DOUBLE_EQ(resolved_time_step(p, parse_solver(name)), kExplicitStepFraction * bound);
  }
  EXPECT_DOUBLE_EQ(resolved_time_step(p, parse_solver("implicit-euler")), 10.0 * bound);
  EXPECT_DOUBLE_EQ(resolved_time_step(p, parse_solver("local-global-euler")), 10.0 * bound);
}

TEST(DefaultTimeStep, DampedIsWithinTheGuaranteedStepAndRunsWhereTheOldDefaultDiverges) {
  const SpringModel undamped(tube().net);
  const Problem p0 = problem_of(undamped);
  const double omega_max = analyse_spectrum(p0, {.lowest = false}).omega_max;
  const double old_default = 0.5 * 2.0 / max_frequency_bound(p0);
  // ζ of the top mode at the mean mass: light damping for explicit Euler (its limit is γ/ω²,
  // far below 2/ω), heavy damping for symplectic Euler (4/(γ + √(γ² + 4ω²)) < 1/ω for ζ > 1).
  struct Case {
    Integrator integrator;
    double zeta;
  };
  for (const Case c :
       {Case{Integrator::explicit_euler, 0.1}, Case{Integrator::symplectic_euler, 3.0}}) {
    SCOPED_TRACE(to_string(c.integrator));
    const double damping = 2.0 * c.zeta * omega_max * mean_free_mass(p0);
    const SpringModel model(tube().net, damping);
    const Problem p = problem_of(model);
    SolverSpec spec = parse_solver(to_string(c.integrator));
    const double dt = resolved_time_step(p, spec);
    const double guaranteed = guaranteed_critical_step(c.integrator, analyse_spectrum(p));
    ASSERT_GT(guaranteed, 0.0);
    EXPECT_LE(dt, kExplicitStepFraction * guaranteed * (1 + 1e-9));
    EXPECT_LT(dt, old_default);
    const Eigen::VectorXd v0 = random_velocity(p, 1e-6, 7);
    EXPECT_TRUE(is_stable(p, c.integrator, dt, 3000, v0));
    EXPECT_FALSE(is_stable(p, c.integrator, old_default, 3000, v0));
  }
}

TEST(DefaultTimeStep, DampedVerletKeepsTheUndampedBound) {
  // No damped bound is proven for velocity Verlet (critical_step.hpp): the default stays 0.5 ×
  // 2/ω_max (Gershgorin), as documented.
  const SpringModel undamped(tube().net);
  const double bound = 2.0 / max_frequency_bound(problem_of(undamped));
  const SpringModel model(tube().net, 1e-3);
  EXPECT_DOUBLE_EQ(resolved_time_step(problem_of(model), parse_solver("verlet")),
                   kExplicitStepFraction * bound);
}
