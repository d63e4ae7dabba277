// The corotational and stable neo-Hookean tet Forms on a closed tube: no force under rigid
// rotations (a generic one, 90° and 180°); corotational P1 and the stable neo-Hookean energy
// equal to linear P1 to second order in the load; and the corotational model through every
// solver it is meant for (static Newton with the consistent tangent, implicit Euler with the
// warped stiffness re-assembled each step, and implicit Euler with the rest stiffness factorised
// once), each against the Newton equilibrium.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "fem_tube.hpp"
#include "finite_differences.hpp"
#include "msm/fem/corotational_tet.hpp"
#include "msm/fem/linear_tet.hpp"
#include "msm/fem/stable_neo_hookean.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/static_solver.hpp"

using namespace vessel;
using namespace vessel::msm;
using vessel::msm::test::fem_tube;
using vessel::msm::test::fem_tube_problem;
using vessel::msm::test::flat_positions;
using vessel::msm::test::load_free_end;

namespace {

const LameParameters kLame{3.2e4, 4.8e3};  // λ, μ (Pa): E = 14.24 kPa, ν ≈ 0.435

Eigen::VectorXd moved(const TetMesh& mesh, const Mat3& Q, const Vec3& shift) {
  std::vector<Vec3> y;
  for (const Vec3& p : mesh.nodes) y.push_back(Q * p + shift);
  return flat_positions(y);
}

/// ‖∇E‖ at x relative to ‖∇E‖ under a 1 % uniaxial stretch (the force scale of a small strain).
double relative_force(const Form& form, const TetMesh& mesh, const Eigen::VectorXd& x) {
  Eigen::VectorXd g, g1;
  form.gradient(x, g);
  form.gradient(moved(mesh, Eigen::Vector3d(1.01, 1.0, 1.0).asDiagonal(), Vec3::Zero()), g1);
  return g.norm() / g1.norm();
}

}  // namespace

TEST(FemTube, RigidRotationsCarryNoForce) {
  const TetMesh mesh = fem_tube();
  const CorotationalTetTerm corot(mesh.nodes, mesh.tets, kLame);
  const StableNeoHookeanTerm snh(mesh.nodes, mesh.tets, {snh_lambda_for_linear(kLame), kLame.mu});
  const LinearTetTerm linear(mesh.nodes, mesh.tets, kLame);
  const double snh_rest_energy = snh.energy(flat_positions(mesh.nodes));
  const struct {
    const char* name;
    Mat3 Q;
  } turns[] = {
      {"generic", Eigen::AngleAxisd(0.83, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix()},
      {"90° about x", Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix()},
      {"180° about y", Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitY()).toRotationMatrix()},
  };
  for (const auto& t : turns) {
    const Eigen::VectorXd x = moved(mesh, t.Q, Vec3(1e-3, -2e-3, 0.5e-3));
    const double rc = relative_force(corot, mesh, x), rs = relative_force(snh, mesh, x);
    const double rl = relative_force(linear, mesh, x);
    std::cout << "[ rotation ] " << t.name << ": corotational " << rc << ", stable neo-Hookean "
              << rs << " (linear P1: " << rl << ")\n";
    EXPECT_LT(rc, 1e-10) << t.name;
    EXPECT_LT(rs, 1e-10) << t.name;
    EXPECT_GT(rl, 1.0) << t.name;  // the check can fail: linear P1 is strained by a rotation
    EXPECT_LT(corot.energy(x), 1e-20) << t.name;
    EXPECT_NEAR(snh.energy(x), snh_rest_energy, 1e-12 * snh_rest_energy) << t.name;
  }
}

TEST(FemTube, FormDerivativesMatchFiniteDifferences) {
  const TetMesh mesh = fem_tube(1, 6, 2);
  const CorotationalTetTerm corot(mesh.nodes, mesh.tets, kLame);
  const StableNeoHookeanTerm snh(mesh.nodes, mesh.tets, {snh_lambda_for_linear(kLame), kLame.mu});
  Eigen::VectorXd x = moved(mesh,
                            Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized()).toRotationMatrix() *
                                Eigen::Vector3d(1.1, 0.95, 1.02).asDiagonal(),
                            Vec3::Zero());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += 0.05e-3 * std::sin(1.7 * i);
  const auto c = msm::test::check_form_derivatives(corot, x, 1e-9);
  const auto s = msm::test::check_form_derivatives(snh, x, 1e-9);
  std::cout << "[ FD ] corotational Form: " << c.gradient_error << ", " << c.hessian_error
            << "; stable neo-Hookean Form: " << s.gradient_error << ", " << s.hessian_error << "\n";
  for (const auto& r : {c, s}) {
    EXPECT_LT(r.gradient_error, 1e-6);
    EXPECT_LT(r.hessian_error, 1e-6);
  }
}

namespace {

/// A cantilevered tube under an end load P solved by Newton on `nonlinear` and linearly on linear
/// P1 (same μ, λ): u − u_lin = O(P²), so doubling P multiplies the difference by 4.
void expect_linear_to_second_order(const TetMesh& mesh, const TetTerm& nonlinear,
                                   const char* name) {
  const LinearTetTerm linear(mesh.nodes, mesh.tets, kLame);
  Problem pn = fem_tube_problem(mesh, nonlinear), pl = fem_tube_problem(mesh, linear);
  StaticOptions o;
  o.tolerance = 1e-12;
  double previous = 0.0;
  for (double load : {1e-4, 2e-4, 4e-4, 8e-4, 1.6e-3}) {  // N
    load_free_end(mesh, pn, load);
    load_free_end(mesh, pl, load);
    const Eigen::VectorXd un = solve_static(pn, o).x - pn.rest;
    const Eigen::VectorXd ul = solve_linear(pl).x - pl.rest;
    const double diff = (un - ul).norm();
    std::cout << "[ small strain ] " << name << ", P = " << load
              << " N: max|u_lin| = " << ul.reshaped(3, ul.size() / 3).colwise().norm().maxCoeff()
              << " m, ‖u − u_lin‖ = " << diff << " m, relative " << diff / ul.norm();
    if (previous > 0.0) std::cout << ", ratio to the previous load's " << diff / previous;
    std::cout << "\n";
    if (previous > 0.0) {
      EXPECT_NEAR(diff / previous, 4.0, 0.2) << name << ", " << load;
    }
    previous = diff;
  }
}

}  // namespace

TEST(FemTube, CorotationalEqualsLinearToSecondOrderInTheLoad) {
  const TetMesh mesh = fem_tube();
  expect_linear_to_second_order(mesh, CorotationalTetTerm(mesh.nodes, mesh.tets, kLame),
                                "corotational");
}

TEST(FemTube, StableNeoHookeanEqualsLinearToSecondOrderInTheLoad) {
  // The Lamé limit on a tube: with λ = λ_lin + μ (Macklin & Müller 2021) the stable neo-Hookean
  // energy's small-strain response is linear P1's with the same E, ν.
  const TetMesh mesh = fem_tube();
  expect_linear_to_second_order(
      mesh, StableNeoHookeanTerm(mesh.nodes, mesh.tets, {snh_lambda_for_linear(kLame), kLame.mu}),
      "stable neo-Hookean");
}

TEST(FemTube, CorotationalSolversReachTheNewtonEquilibrium) {
  // Newton with the consistent tangent; implicit Euler with the warped stiffness R K₀ Rᵀ
  // re-assembled each step; implicit Euler with K₀ factorised once (the rotation's part of the
  // stiffness then integrated explicitly). ω_max·dt ≫ 1, so backward Euler damps the motion out
  // and a steady state is an equilibrium. At 15 mN the tube's end turns (tip deflection ~ 40 % of
  // the length) and the prefactored rest stiffness diverges at this step; at 1 mN it settles.
  const TetMesh mesh = fem_tube();
  const CorotationalTetTerm consistent(mesh.nodes, mesh.tets, kLame);
  const CorotationalTetTerm warped(mesh.nodes, mesh.tets, kLame, CorotationalStiffness::warped);
  for (double load : {1e-3, 1.5e-2}) {  // N
    Problem p = fem_tube_problem(mesh, consistent);
    load_free_end(mesh, p, load);
    StaticOptions so;
    so.tolerance = 1e-12;
    const StaticResult newton = solve_static(p, so);
    ASSERT_TRUE(newton.converged);
    const Eigen::VectorXd u = newton.x - p.rest;
    std::cout << "[ solvers ] P = " << load << " N: Newton (consistent tangent) "
              << newton.iterations << " iterations, tip deflection "
              << u.reshaped(3, u.size() / 3).colwise().norm().maxCoeff() << " m\n";
    Problem pw = p;
    pw.form = &warped;
    for (ImplicitMatrix matrix :
         {ImplicitMatrix::current_state, ImplicitMatrix::rest_prefactored}) {
      const bool rest = matrix == ImplicitMatrix::rest_prefactored;
      DynamicOptions d;
      d.integrator = Integrator::implicit_euler;
      d.implicit_matrix = matrix;
      d.dt = 0.02;  // s
      d.steps = 400;
      if (rest && load > 1e-2) {
        EXPECT_THROW(integrate(pw, d), DivergenceError);
        std::cout << "[ solvers ]   implicit Euler, rest stiffness prefactored: diverges\n";
        continue;
      }
      const DynamicResult r = integrate(pw, d);
      const double err = (r.x - newton.x).norm() / u.norm();
      std::cout << "[ solvers ]   implicit Euler, "
                << (rest ? "rest stiffness prefactored" : "warped stiffness re-assembled") << ": "
                << r.numeric_factorisations << " factorisations, ‖x − x_Newton‖/‖u‖ = " << err
                << "\n";
      EXPECT_LT(err, 1e-8);
    }
  }
}

// Corotational P1 dynamically: implicit Euler (Baraff & Witkin's one linear solve per step) with
// the warped stiffness R K₀ Rᵀ re-assembled each step (SOFA's TetrahedronFEMForceField), and with
// the rest stiffness K₀ factorised once (the force stays corotational; what K₀ lacks of the
// rotation is integrated explicitly).

namespace {

struct ImplicitVariant {
  const char* name;
  ImplicitMatrix matrix;
};
constexpr ImplicitVariant kImplicitVariants[] = {
    {"warped stiffness re-assembled", ImplicitMatrix::current_state},
    {"rest stiffness prefactored", ImplicitMatrix::rest_prefactored}};

DynamicOptions implicit_euler(ImplicitMatrix matrix, double dt, int steps) {
  DynamicOptions d;
  d.integrator = Integrator::implicit_euler;
  d.implicit_matrix = matrix;
  d.dt = dt;
  d.steps = steps;
  return d;
}

/// The positions after every step of an implicit Euler run of `p` from rest.
std::vector<Eigen::VectorXd> trajectory(const Problem& p, DynamicOptions d,
                                        const Eigen::VectorXd& x0 = {},
                                        const Eigen::VectorXd& v0 = {}) {
  std::vector<Eigen::VectorXd> xs;
  d.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd&) { xs.push_back(x); };
  integrate(p, d, x0, v0);
  return xs;
}

double largest_node_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd d = a - b;
  return d.reshaped(3, d.size() / 3).colwise().norm().maxCoeff();
}

}  // namespace

TEST(FemTube, CorotationalImplicitEulerOscillationEqualsLinearP1sToSecondOrderInTheAmplitude) {
  // A step load on the free end from rest: the tube swings about its deflected shape (its lowest
  // period is ~10 ms, 50 steps of 0.2 ms; implicit Euler damps it by ~1 % a step). Linear P1's
  // implicit Euler is exact backward Euler on a linear system; corotational P1's force and
  // stiffness differ from linear P1's by O(u²) and O(u), so the trajectories part by O(P²):
  // doubling the load multiplies the largest difference over the run by 4.
  const TetMesh mesh = fem_tube();
  const LinearTetTerm linear(mesh.nodes, mesh.tets, kLame);
  const CorotationalTetTerm warped(mesh.nodes, mesh.tets, kLame, CorotationalStiffness::warped);
  constexpr double kDt = 2e-4;  // s
  constexpr int kSteps = 150;
  for (const ImplicitVariant& variant : kImplicitVariants) {
    double previous = 0.0;
    for (double load : {1e-4, 2e-4, 4e-4, 8e-4}) {  // N
      Problem pl = fem_tube_problem(mesh, linear), pc = fem_tube_problem(mesh, warped);
      load_free_end(mesh, pl, load);
      load_free_end(mesh, pc, load);
      const auto xl = trajectory(pl, implicit_euler(ImplicitMatrix::current_state, kDt, kSteps));
      const auto xc = trajectory(pc, implicit_euler(variant.matrix, kDt, kSteps));
      ASSERT_EQ(xl.size(), xc.size());
      double diff = 0.0, swing = 0.0, lowest_after_peak = 1e300, peak = 0.0;
      for (std::size_t k = 0; k < xl.size(); ++k) {
        diff = std::max(diff, largest_node_distance(xc[k], xl[k]));
        const double u = largest_node_distance(xl[k], pl.rest);
        swing = std::max(swing, u);
        if (u >= peak) {
          peak = u;
          lowest_after_peak = u;
        }
        lowest_after_peak = std::min(lowest_after_peak, u);
      }
      std::cout << "[ dynamics ] " << variant.name << ", P = " << load
                << " N: largest linear displacement " << swing << " m, largest difference " << diff
                << " m (relative " << diff / swing << ")";
      if (previous > 0.0) std::cout << ", ratio to the previous load's " << diff / previous;
      std::cout << "\n";
      // It oscillates: after its first peak the linear tip swings back by more than a tenth of it.
      EXPECT_LT(lowest_after_peak, 0.9 * peak) << variant.name;
      EXPECT_LT(diff / swing, 0.05) << variant.name << ", " << load;
      if (previous > 0.0) {
        EXPECT_NEAR(diff / previous, 4.0, 0.2) << variant.name << ", " << load;
      }
      previous = diff;
    }
  }
}

TEST(FemTube, CorotationalImplicitEulerKeepsARigidlyTurnedTubeWhereItIs) {
  // The tube turned by 120° about a generic axis and shifted, its clamp turned with it: no force
  // there, so both implicit Euler variants leave it where it is over 2000 steps; given a small
  // velocity it returns there (implicit Euler damps the motion out). Linear P1,
  // strained by the turn, moves away: the check can fail.
  const TetMesh mesh = fem_tube();
  const CorotationalTetTerm warped(mesh.nodes, mesh.tets, kLame, CorotationalStiffness::warped);
  const LinearTetTerm linear(mesh.nodes, mesh.tets, kLame);
  const Mat3 Q = Eigen::AngleAxisd(2.0 * std::numbers::pi / 3.0, Vec3(0.2, 0.9, -0.4).normalized())
                     .toRotationMatrix();
  const Eigen::VectorXd turned = moved(mesh, Q, Vec3(4e-3, -1e-3, 2e-3));
  constexpr double kSize = 6e-3;  // m, the tube's length
  {
    Problem p = fem_tube_problem(mesh, warped);
    p.rest = turned;  // the clamp holds its turned position
    Eigen::VectorXd g;
    warped.gradient(turned, g);
    Eigen::VectorXd g1;
    warped.gradient(moved(mesh, Eigen::Vector3d(1.01, 1.0, 1.0).asDiagonal(), Vec3::Zero()), g1);
    std::cout << "[ turned ] ‖∇E‖ turned / ‖∇E‖ at 1 % stretch: " << g.norm() / g1.norm() << "\n";
    EXPECT_LT(g.norm() / g1.norm(), 1e-10);
    for (const ImplicitVariant& variant : kImplicitVariants) {
      const DynamicResult still = integrate(p, implicit_euler(variant.matrix, 1e-3, 2000));
      const double drift = largest_node_distance(still.x, turned);
      // A small velocity (1 cm/s), then 1000 steps of 1 ms: back where it was.
      Eigen::VectorXd v0 = Eigen::VectorXd::Zero(p.num_dofs());
      for (Eigen::Index i = 0; i < v0.size(); ++i) {
        v0[i] = p.fixed[i] ? 0.0 : 1e-2 * std::sin(0.37 * static_cast<double>(i));
      }
      double excursion = 0.0;
      DynamicOptions d = implicit_euler(variant.matrix, 1e-3, 1000);
      d.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd&) {
        excursion = std::max(excursion, largest_node_distance(x, turned));
      };
      const DynamicResult back = integrate(p, d, turned, v0);
      const double returned = largest_node_distance(back.x, turned);
      std::cout << "[ turned ] " << variant.name << ": drift over 2000 steps " << drift / kSize
                << " × length; after a kick (largest excursion " << excursion << " m) it ends "
                << returned << " m from the turned shape\n";
      EXPECT_LT(drift / kSize, 1e-12) << variant.name;
      EXPECT_GT(excursion, 1e-6) << variant.name;
      EXPECT_LT(returned, 1e-6 * excursion) << variant.name;
    }
  }
  Problem pl = fem_tube_problem(mesh, linear);
  pl.rest = turned;
  const DynamicResult lin = integrate(pl, implicit_euler(ImplicitMatrix::current_state, 1e-3, 200));
  std::cout << "[ turned ] linear P1 moves " << largest_node_distance(lin.x, turned) << " m\n";
  EXPECT_GT(largest_node_distance(lin.x, turned), 1e-2 * kSize);
}

TEST(FemTube, CorotationalImplicitEulerLosesEnergyAtEveryStepWithoutLoad) {
  // Released from the static shape under an end load (15 mN: the end turned, tip deflection ~40 %
  // of the length; 1 mN for the prefactored rest stiffness, which diverges from the larger turn),
  // no load: backward Euler dissipates, so the total energy ½vᵀMv + E(x) falls at every step.
  const TetMesh mesh = fem_tube();
  const CorotationalTetTerm consistent(mesh.nodes, mesh.tets, kLame);
  const CorotationalTetTerm warped(mesh.nodes, mesh.tets, kLame, CorotationalStiffness::warped);
  for (const ImplicitVariant& variant : kImplicitVariants) {
    const bool rest = variant.matrix == ImplicitMatrix::rest_prefactored;
    Problem p = fem_tube_problem(mesh, consistent);
    load_free_end(mesh, p, rest ? 1e-3 : 1.5e-2);
    StaticOptions so;
    so.tolerance = 1e-12;
    const StaticResult bent = solve_static(p, so);
    ASSERT_TRUE(bent.converged);
    p.form = &warped;
    p.external_force.setZero();
    std::vector<double> energy{total_energy(p, bent.x, Eigen::VectorXd::Zero(p.num_dofs()))};
    DynamicOptions d = implicit_euler(variant.matrix, 5e-4, 300);
    d.on_step = [&](int, const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
      energy.push_back(total_energy(p, x, v));
    };
    integrate(p, d, bent.x);
    int rises = 0;
    double largest_rise = 0.0;
    for (std::size_t k = 1; k < energy.size(); ++k) {
      if (energy[k] > energy[k - 1]) {
        ++rises;
        largest_rise = std::max(largest_rise, (energy[k] - energy[k - 1]) / energy.front());
      }
    }
    std::cout << "[ energy ] " << variant.name << ": " << energy.front() << " J → " << energy.back()
              << " J over " << energy.size() - 1 << " steps, " << rises << " rises (largest "
              << largest_rise << " of the start)\n";
    EXPECT_EQ(rises, 0) << variant.name;
    EXPECT_LT(energy.back(), 0.5 * energy.front()) << variant.name;
  }
}
