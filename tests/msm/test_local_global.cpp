// Liu et al. 2013's local–global solver against independent solvers: static Newton (solve_static)
// on the level-0 tube, Newton on the implicit Euler step's incremental potential, the monotone
// decrease of the local–global objective (block coordinate descent), and its refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/local_global.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// The level-0 tube's volume model (seed 001 stiffness, Hooke) under the shared contact patch,
/// both ends fixed.
struct Tube {
  TetMesh mesh;
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

const Tube& tube() {
  static const Tube t = [] {
    Tube c;
    const VesselParams params;
    c.mesh = generate_vessel_mesh(params);
    c.net = build_volume_network(c.mesh);
    assign_stiffness(c.net, StiffnessRule::seed001, StiffnessParams{});
    c.model = std::make_unique<SpringModel>(c.net);
    const auto masses = nodal_masses(c.net, MassRule::consistent, kVesselDensity);
    ContactPatchSpec spec;
    spec.point = Vec3(3e-3, 0, 20e-3);
    spec.radius = 1e-3;
    spec.force = 1e-3;  // N: a strain of a few per cent, clearly nonlinear in the directions
    const auto loads = traction_nodal_loads(c.mesh, contact_patch(c.mesh, spec));
    c.problem = make_problem(*c.model, c.net, masses, c.mesh, loads, {"inlet", "outlet"});
    return c;
  }();
  return t;
}

/// A 3 × 3 × 2 lattice of 1 mm cells with edge and face-diagonal Hooke springs and point damping;
/// the x = 0 face fixed, a load on the far corner.
struct Lattice {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;
};

Lattice make_lattice(double point_damping, double axial_damping = 0.0) {
  Lattice c;
  const int nx = 3, ny = 3, nz = 2;
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) c.net.nodes.push_back(Vec3(1e-3 * i, 1e-3 * j, 1e-3 * k));
  const int n = static_cast<int>(c.net.nodes.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const double d = (c.net.nodes[a] - c.net.nodes[b]).norm();
      if (d > 1.5e-3) continue;
      Spring s;
      s.a = a;
      s.b = b;
      s.rest_length = d;
      s.law = {50.0, 50.0};
      s.damping = axial_damping;
      c.net.springs.push_back(s);
    }
  }
  c.model = std::make_unique<SpringModel>(c.net, point_damping);
  Problem& p = c.problem;
  p.form = c.model.get();
  p.rest = flatten(c.net.nodes);
  p.mass = Eigen::VectorXd::Constant(3 * n, 1e-5);
  p.external_force = Eigen::VectorXd::Zero(3 * n);
  p.external_force.segment<3>(3 * id(nx - 1, ny - 1, nz - 1)) = Vec3(0.0, -0.02, 0.03);
  p.fixed.assign(3 * n, 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int d = 0; d < 3; ++d) p.fixed[3 * id(0, j, k) + d] = 1;
  return c;
}

/// A Form that is not a plain SpringModel (stands for any model with other energy terms).
class WrappedSprings : public Form {
 public:
  explicit WrappedSprings(const SpringModel& m) : m_(m) {}
  [[nodiscard]] int num_dofs() const override { return m_.num_dofs(); }
  [[nodiscard]] double energy(const VectorXd& x) const override { return m_.energy(x); }
  void gradient(const VectorXd& x, VectorXd& g) const override { m_.gradient(x, g); }
  void hessian(const VectorXd& x, SparseMatrix& H, bool psd) const override {
    m_.hessian(x, H, psd);
  }

 private:
  const SpringModel& m_;
};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(LocalGlobal, StaticSolveConvergesToStaticNewtonOnTheTube) {
  const Problem& p = tube().problem;
  const StaticResult newton = solve_static(p);
  LocalGlobalOptions o;
  o.tolerance = 1e-10;  // measured: about 2000 iterations, error 1.6e-10 against Newton
  const StaticResult lg = solve_static_local_global(p, o);
  ASSERT_TRUE(lg.converged);
  EXPECT_EQ(lg.numeric_factorisations, 1);
  const Eigen::VectorXd u = newton.x - p.rest;
  EXPECT_GT(u.cwiseAbs().maxCoeff(), 1e-5);  // a real deformation (> 10 µm)
  EXPECT_LT((lg.x - newton.x).norm(), 1e-8 * u.norm()) << lg.iterations << " iterations";
  // And the gradient of the model's own energy (not the solver's objective) vanishes there.
  Eigen::VectorXd g;
  p.potential_gradient(lg.x, g);
  EXPECT_LT(g.norm(), 2e-10 * p.external_force.norm());
}

TEST(LocalGlobal, EveryLocalAndGlobalStepDoesNotIncreaseTheObjective) {
  // Block coordinate descent (Liu et al.): the local step minimises g over d, the global step
  // over x, so g never increases; after a local step g(x, d(x)) is the total potential Π(x),
  // here evaluated by the spring model itself.
  const Problem& p = tube().problem;
  LocalGlobalOptions o;
  o.max_iterations = 60;
  o.tolerance = 1e-300;  // run all 60 iterations
  std::vector<double> values;
  int local_checks = 0;
  o.on_half_step = [&](int, bool global, const VectorXd& x, double g) {
    if (!global) {
      EXPECT_NEAR(g, p.potential(x), 1e-10 * std::abs(g) + 1e-18);
      ++local_checks;
    }
    values.push_back(g);
  };
  EXPECT_THROW(solve_static_local_global(p, o), std::runtime_error);  // not converged in 60
  ASSERT_EQ(local_checks, 61);
  ASSERT_EQ(values.size(), 121u);
  const double scale = std::abs(values.back());
  for (std::size_t i = 1; i < values.size(); ++i) {
    EXPECT_LE(values[i], values[i - 1] + 1e-13 * scale) << "half step " << i;
  }
  EXPECT_LT(values.back(), values.front());
}

TEST(LocalGlobal, EulerWithManyIterationsEqualsImplicitEulerByNewton) {
  // Three implicit Euler steps of the damped lattice, each solved by Newton to convergence on the
  // incremental potential, against local-global-euler with 3000 iterations per step; and fewer
  // iterations are less accurate (Liu et al.'s convergence, not a claim about its rate).
  const Lattice c = make_lattice(2e-4);
  const Problem& p = c.problem;
  const double h = 1e-3;
  const int steps = 3;
  Eigen::VectorXd x = p.rest, v = Eigen::VectorXd::Zero(p.num_dofs());
  StaticOptions tight;
  tight.tolerance = 1e-13;
  for (int s = 0; s < steps; ++s) {
    const Eigen::VectorXd x1 = implicit_euler_step_newton(p, x, v, h, tight);
    v = (x1 - x) / h;
    x = x1;
  }
  const double u = (x - p.rest).norm();
  ASSERT_GT(u, 1e-5);
  DynamicOptions d;
  d.dt = h;
  d.steps = steps;
  double previous = HUGE_VAL;
  for (int iterations : {1, 10, 100, 3000}) {
    LocalGlobalOptions o;
    o.iterations = iterations;
    const DynamicResult r = integrate_local_global(p, d, o);
    const double error = (r.x - x).norm() / u;
    EXPECT_LT(error, previous) << iterations;
    previous = error;
    if (iterations == 3000) {
      EXPECT_LT(error, 1e-9);
      EXPECT_LT((r.v - v).norm(), 1e-8 * v.norm());
      EXPECT_EQ(r.numeric_factorisations, 1);
    }
  }
}

TEST(LocalGlobal, NamedInSolveWithItsIterationsSetting) {
  const Lattice c = make_lattice(2e-4);
  SolverSpec spec = parse_solver("local-global-euler");
  EXPECT_EQ(spec.kind, SolverKind::local_global_euler);
  EXPECT_TRUE(spec.is_dynamic());
  EXPECT_EQ(spec.local_global.iterations, 10);
  EXPECT_FALSE(parse_solver("local-global").is_dynamic());
  spec.dt = 1e-3;
  spec.steps = 2;
  spec.local_global.iterations = 7;
  const SolveResult s = solve(c.problem, spec);
  LocalGlobalOptions o;
  o.iterations = 7;
  DynamicOptions d;
  d.dt = 1e-3;
  d.steps = 2;
  EXPECT_EQ((s.x - integrate_local_global(c.problem, d, o).x).norm(), 0.0);
  const SolveResult st = solve(c.problem, parse_solver("local-global"));
  EXPECT_LT((st.x - solve_static(c.problem).x).norm(), 1e-7 * (st.x - c.problem.rest).norm());
}

TEST(LocalGlobal, RunsOnTheFactorysSpringsOnlyModelAndRefusesItsVolumeTerm) {
  // The harness and the msm command build every model with make_model: without a volume term it
  // is the same springs, so local-global must give the SpringModel's answer bit for bit.
  const Lattice c = make_lattice(2e-4);
  const auto factory_model = make_model(c.net, {}, 2e-4);
  Problem via_factory = c.problem;
  via_factory.form = factory_model.get();
  DynamicOptions d;
  d.dt = 1e-3;
  d.steps = 3;
  EXPECT_EQ((integrate_local_global(via_factory, d).x - integrate_local_global(c.problem, d).x)
                .norm(),
            0.0);
  // With the hybrid model's volume term: refused, naming why.
  const auto hybrid = make_model(tube().net, {.volume_kappa = 1.0e3});
  Problem with_volume = tube().problem;
  with_volume.form = hybrid.get();
  const std::string e = error_of([&] { solve_static_local_global(with_volume); });
  EXPECT_NE(e.find("volume term"), std::string::npos) << e;
}

TEST(LocalGlobal, RefusesWhatItCannotSolveNamingTheSolverAndWhy) {
  const Lattice c = make_lattice(2e-4);
  // A bilinear spring (seed 001 eq. 1).
  Lattice bilinear = make_lattice(0.0);
  bilinear.net.springs[3].law = {50.0, 80.0, 1e-5};
  bilinear.model = std::make_unique<SpringModel>(bilinear.net);
  bilinear.problem.form = bilinear.model.get();
  std::string e = error_of([&] { solve_static_local_global(bilinear.problem); });
  EXPECT_NE(e.find("local-global"), std::string::npos) << e;
  EXPECT_NE(e.find("bilinear"), std::string::npos) << e;
  // A Form that is not a plain spring model.
  const WrappedSprings wrapped(*c.model);
  Problem other = c.problem;
  other.form = &wrapped;
  DynamicOptions d;
  d.dt = 1e-3;
  d.steps = 1;
  e = error_of([&] { integrate_local_global(other, d); });
  EXPECT_NE(e.find("local-global-euler"), std::string::npos) << e;
  EXPECT_NE(e.find("plain spring model"), std::string::npos) << e;
  // Axial damping (direction-dependent: no constant matrix).
  const Lattice axial = make_lattice(0.0, 1e-3);
  e = error_of([&] { integrate_local_global(axial.problem, d); });
  EXPECT_NE(e.find("axial damping"), std::string::npos) << e;
  // Statics without supports: L is singular.
  Problem floating = c.problem;
  floating.fixed.assign(floating.fixed.size(), 0);
  e = error_of([&] { solve_static_local_global(floating); });
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
  // Only some dofs of a node fixed.
  Problem partial = c.problem;
  partial.fixed[3 * 4 + 1] = 1;
  e = error_of([&] { solve_static_local_global(partial); });
  EXPECT_NE(e.find("some of its dofs"), std::string::npos) << e;
  // Bad settings.
  LocalGlobalOptions zero;
  zero.iterations = 0;
  e = error_of([&] { integrate_local_global(c.problem, d, zero); });
  EXPECT_NE(e.find("iterations"), std::string::npos) << e;
}
