// Prepared updates (msm/solvers/updates.hpp) against independent answers: closed forms on
// hand-built networks (Hooke's law in series, a bilinear spring, a pretensioned pair pulled
// sideways), and cold solves from rest (solve_linear, solve_static) on the level-0 vessel.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>

#include "meshes/foundation/errors.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/solvers/updates.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

/// Springs between the listed nodes; mass irrelevant (static answers).
struct Network {
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;

  void finish(const std::vector<int>& fixed_nodes) {
    model = std::make_unique<SpringModel>(net);
    const auto n = static_cast<Eigen::Index>(net.nodes.size());
    problem.form = model.get();
    problem.rest = flatten(net.nodes);
    problem.mass = Eigen::VectorXd::Constant(3 * n, 1e-4);
    problem.external_force = Eigen::VectorXd::Zero(3 * n);
    problem.fixed.assign(static_cast<std::size_t>(3 * n), 0);
    for (const int i : fixed_nodes) {
      for (int c = 0; c < 3; ++c) problem.fixed[static_cast<std::size_t>(3 * i + c)] = 1;
    }
  }
  void add(int a, int b, SpringLaw law) {
    Spring s;
    s.a = a;
    s.b = b;
    s.rest_length = (net.nodes[b] - net.nodes[a]).norm();
    s.law = law;
    net.springs.push_back(s);
  }
};

/// A chain along x (node 0 fixed, y and z of every node fixed), 1 mm springs of the given laws.
Network chain(const std::vector<SpringLaw>& laws) {
  Network c;
  const int n = static_cast<int>(laws.size()) + 1;
  for (int i = 0; i < n; ++i) c.net.nodes.push_back(Vec3(1e-3 * i, 0, 0));
  for (int i = 0; i + 1 < n; ++i) c.add(i, i + 1, laws[static_cast<std::size_t>(i)]);
  c.finish({0});
  for (int i = 0; i < n; ++i) c.problem.fixed[3 * i + 1] = c.problem.fixed[3 * i + 2] = 1;
  return c;
}

/// Load vector with force F along x on the chain's end node.
Eigen::VectorXd end_load(const Problem& p, double F) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(p.num_dofs());
  f[p.num_dofs() - 3] = F;
  return f;
}

/// The level-0 vessel's volume model (seed 001 springs) under the shared contact patch.
struct Tube {
  TetMesh mesh;
  SpringNetwork net;
  std::unique_ptr<SpringModel> model;
  Problem problem;  ///< at unit contact force, 1 N
};

Tube tube() {
  Tube t;
  const VesselParams params;
  t.mesh = generate_vessel_mesh(params);
  t.net = build_volume_network(t.mesh);
  assign_stiffness(t.net, StiffnessRule::seed001, StiffnessParams{});
  t.model = std::make_unique<SpringModel>(t.net);
  const auto masses = nodal_masses(t.net, MassRule::consistent, kVesselDensity);
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 20e-3);
  spec.radius = 1e-3;
  spec.force = 1.0;
  const auto loads = traction_nodal_loads(t.mesh, contact_patch(t.mesh, spec));
  t.problem = make_problem(*t.model, t.net, masses, t.mesh, loads, {"inlet", "outlet"});
  return t;
}

SolverSpec spec_of(const char* name) { return parse_solver(name); }

}  // namespace

TEST(Updates, LinearUpdatesFollowHookesLawInSeries) {
  // Springs in series under F on the end: δ = F Σ 1/k_i, at every step of a ramp to 140 mN.
  const std::vector<double> k{10.0, 41.106, 25.0, 80.0, 15.0};
  std::vector<SpringLaw> laws;
  double compliance = 0.0;
  for (const double ki : k) {
    laws.push_back({ki, ki});
    compliance += 1.0 / ki;
  }
  Network c = chain(laws);
  const auto up = prepare_updates(c.problem, spec_of("linear"));
  EXPECT_EQ(up->factorisations(), 1);
  for (int s = 1; s <= 10; ++s) {
    const double F = 0.140 * s / 10.0;
    up->update(end_load(c.problem, F));
    const Eigen::Index e = c.problem.num_dofs() - 3;
    EXPECT_NEAR(up->state()[e] - c.problem.rest[e], F * compliance, 1e-12) << F;
  }
  EXPECT_EQ(up->factorisations(), 1);  // factorised once, at set-up
}

TEST(Updates, PrefactoredLinearUpdatesEqualSolveLinearOnARamp) {
  Tube t = tube();
  const auto up = prepare_updates(t.problem, spec_of("linear"));
  for (int s = 1; s <= 8; ++s) {
    Problem p = t.problem;
    p.external_force = t.problem.external_force * (1e-3 * s / 8.0);
    const UpdateResult r = up->update(p.external_force);
    EXPECT_EQ(r.factorisations, 0);
    const StaticResult cold = solve_linear(p);  // assembled and factorised afresh
    const double u = (cold.x - p.rest).norm();
    ASSERT_GT(u, 0.0);
    EXPECT_LT((up->state() - cold.x).norm(), 1e-12 * u) << s;
  }
  EXPECT_EQ(up->factorisations(), 1);
}

TEST(Updates, LinearUpdatesSuperposeOnThePreparedPatchAndSolveElsewhere) {
  // Loads on the prepared patch's dofs, with any values there, are the superposition of the
  // responses solved for at set-up; a load on any other dof is solved with the factor. Both equal
  // a cold solve_linear of the same load.
  Tube t = tube();
  const auto up = prepare_updates(t.problem, spec_of("linear"));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  Eigen::VectorXd on_patch = Eigen::VectorXd::Zero(t.problem.num_dofs());
  int loaded = 0;
  for (Eigen::Index i = 0; i < on_patch.size(); ++i) {
    if (t.problem.external_force[i] != 0.0 && !t.problem.fixed[i]) {
      on_patch[i] = u(rng);  // not proportional to the prepared load
      ++loaded;
    }
  }
  ASSERT_GT(loaded, 3);
  Eigen::VectorXd elsewhere = on_patch;
  Eigen::Index other = 0;  // a free dof off the patch
  while (t.problem.fixed[other] || t.problem.external_force[other] != 0.0) ++other;
  elsewhere[other] = 2e-4;
  for (const auto& [f, superposed] : {std::pair{on_patch, true}, std::pair{elsewhere, false}}) {
    const UpdateResult r = up->update(f);
    EXPECT_EQ(r.superposed, superposed);
    EXPECT_EQ(r.factorisations, 0);
    Problem p = t.problem;
    p.external_force = f;
    const StaticResult cold = solve_linear(p);
    const double size = (cold.x - p.rest).norm();
    ASSERT_GT(size, 0.0);
    EXPECT_LT((up->state() - cold.x).norm(), 1e-12 * size) << superposed;
  }
  // Prepared without a load: nothing precomputed, every update solves.
  Problem unloaded = t.problem;
  unloaded.external_force.setZero();
  EXPECT_FALSE(prepare_updates(unloaded, spec_of("linear"))->update(on_patch).superposed);
  EXPECT_EQ(up->factorisations(), 1);
}

TEST(Updates, WarmStartedNewtonCrossesTheBilinearThresholdAsHookesLawSays) {
  // One bilinear spring (seed 001 eq. 1): k1 = 20, k2 = 60 N/m, Δx_c = 1 mm; δ(F) = F/k1 below
  // F_c = k1 Δx_c = 20 mN, Δx_c + (F − F_c)/k2 above. Beyond the threshold the factorisation
  // of k1 over-shoots (modified Newton diverges by |1 − k2/k1| = 2 per step): full Newton must
  // take over there, and the factorisation must be reused below it.
  Network c = chain({{20.0, 60.0, 1e-3}});
  const auto up = prepare_updates(c.problem, spec_of("static"));
  int reused = 0, refactorised = 0;
  for (int s = 1; s <= 10; ++s) {
    const double F = 0.05 * s / 10.0;
    const UpdateResult r = up->update(end_load(c.problem, F));
    (r.factorisations == 0 ? reused : refactorised) += 1;
    const double expected = F <= 0.02 ? F / 20.0 : 1e-3 + (F - 0.02) / 60.0;
    EXPECT_NEAR(up->state()[3] - c.problem.rest[3], expected, 1e-12) << F;
  }
  EXPECT_GE(reused, 1);
  EXPECT_GE(refactorised, 1);
}

TEST(Updates, ModifiedNewtonReachesThePretensionedPairsClosedFormEquilibrium) {
  // A node between two fixed nodes 2.4 mm apart, springs of rest length 1 mm and k = 10 N/m
  // (pretensioned: the transverse stiffness at rest is 2k(1 − L0/l) = 3.3 N/m), pulled sideways
  // by f. Equilibrium: 2k(L − L0)·y/L = f, L = √(l² + y²) — solved here by bisection. The
  // transverse stiffness grows with y, so the factorisation at rest is reused at first and
  // replaced later.
  Network c;
  c.net.nodes = {Vec3(-1.2e-3, 0, 0), Vec3(0, 0, 0), Vec3(1.2e-3, 0, 0)};
  c.add(0, 1, {10.0, 10.0});
  c.add(1, 2, {10.0, 10.0});
  for (Spring& s : c.net.springs) s.rest_length = 1e-3;
  c.finish({0, 2});
  const auto closed_form = [](double f) {
    const auto force = [](double y) {
      const double L = std::hypot(1.2e-3, y);
      return 2.0 * 10.0 * (L - 1e-3) * y / L;
    };
    double lo = 0.0, hi = 1e-2;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (force(mid) < f ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  const auto up = prepare_updates(c.problem, spec_of("static"));
  int reused = 0, refactorised = 0;
  for (int s = 1; s <= 10; ++s) {
    const double f = 0.01 * s / 10.0;
    Eigen::VectorXd load = Eigen::VectorXd::Zero(9);
    load[4] = f;
    const UpdateResult r = up->update(load);
    (r.factorisations == 0 ? reused : refactorised) += 1;
    const double y = closed_form(f);
    // ‖∇Π‖ ≤ 1e-8 f, and the tangent stiffness exceeds the secant f/y (the pair stiffens): the
    // solver's tolerance bounds |Δy| by 1e-8 y.
    EXPECT_NEAR(up->state()[4], y, 1e-8 * y) << f;
    EXPECT_NEAR(up->state()[3], 0.0, 1e-15);
    EXPECT_NEAR(up->state()[5], 0.0, 1e-15);
  }
  EXPECT_GE(reused, 1);
  EXPECT_GE(refactorised, 1);
}

TEST(Updates, WarmStartedNewtonOverALoadRampEqualsColdStarts) {
  // The level-0 vessel's volume model from 0 to 10 mN (about 30 % strain at the patch: well into
  // the geometric nonlinearity) in 8 updates, each from the previous state; every state against
  // Newton from rest at the same load. Both stop at ‖∇Π‖ ≤ 1e-8 ‖f‖, so they agree to the
  // solver's tolerance times the compliance (here 1e-6 of the displacement is ample).
  Tube t = tube();
  const auto up = prepare_updates(t.problem, spec_of("static"));
  int reused = 0;
  for (int s = 1; s <= 8; ++s) {
    Problem p = t.problem;
    p.external_force = t.problem.external_force * (1e-2 * s / 8.0);
    const UpdateResult r = up->update(p.external_force);
    reused += r.reused_iterations;
    Eigen::VectorXd g;
    p.potential_gradient(up->state(), g);
    EXPECT_LE(g.norm(), 1e-8 * p.external_force.norm()) << s;
    EXPECT_LE(r.residual, 1e-8 * p.external_force.norm()) << s;
    const StaticResult cold = solve_static(p);
    const double u = (cold.x - p.rest).norm();
    EXPECT_LT((up->state() - cold.x).norm(), 1e-6 * u) << s;
  }
  // Measured: the first steps refactorise (the held factor over-shoots: the residual grows), the
  // later ones iterate with the factor the previous update's Newton left.
  EXPECT_GE(reused, 1);
}

TEST(Updates, AtSmallLoadsTheFactorisationAtRestCarriesMostUpdates) {
  // The same vessel ramped to 0.5 mN (contact_straight's budget load, ~3 % strain): modified
  // Newton with K at rest converges on most updates without any factorisation, to the same states
  // as Newton from rest.
  Tube t = tube();
  const auto up = prepare_updates(t.problem, spec_of("static"));
  int without_factorisation = 0;
  for (int s = 1; s <= 8; ++s) {
    Problem p = t.problem;
    p.external_force = t.problem.external_force * (5e-4 * s / 8.0);
    const UpdateResult r = up->update(p.external_force);
    if (r.factorisations == 0) {
      ++without_factorisation;
      EXPECT_EQ(r.reused_iterations, r.iterations);
    }
    const StaticResult cold = solve_static(p);
    EXPECT_LT((up->state() - cold.x).norm(), 1e-6 * (cold.x - p.rest).norm()) << s;
  }
  EXPECT_GE(without_factorisation, 4);
}

TEST(Updates, OnlyStaticAndLinearArePreparedAndLoadsAreChecked) {
  Network c = chain({{10.0, 10.0}});
  EXPECT_TRUE(supports_updates(spec_of("static")));
  EXPECT_TRUE(supports_updates(spec_of("linear")));
  for (const char* name : {"relaxation", "symplectic-euler", "implicit-euler-rest", "pbd"}) {
    EXPECT_FALSE(supports_updates(spec_of(name))) << name;
    EXPECT_THROW(prepare_updates(c.problem, spec_of(name)), InputError) << name;
  }
  const auto up = prepare_updates(c.problem, spec_of("linear"));
  try {
    up->update(Eigen::VectorXd::Zero(5));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected a load vector of 6 entries"), std::string::npos)
        << e.what();
  }
}
