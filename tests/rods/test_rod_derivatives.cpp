// Energy, gradient and Hessian of every rod term against central finite differences, at bent,
// stretched and twisted 3D states away from the rest state and from the stored reference frames.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <tuple>

#include "../msm/finite_differences.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/cosserat_terms.hpp"
#include "msm/rods/der_rod.hpp"
#include "msm/rods/rod_loads.hpp"
#include "rod_cases.hpp"

namespace vessel::msm::rods::test {
namespace {

using vessel::msm::test::check_form_derivatives;

/// A rod of 5 segments (0.1 m), clamped at both ends, with a tapered tip section.
RodSpec small_rod() {
  RodSpec spec;
  spec.material = test_material();
  spec.sections = {{0.06, 1e-3, 1e-3, 3}, {0.04, 1e-3, 0.5e-3, 2}};
  spec.clamp_end = true;
  return spec;
}

VectorXd perturbed(const VectorXd& x, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VectorXd y = x;
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] += scale * u(rng);
  return y;
}

TEST(RodDerivatives, DerEnergyGradientHessianAgreeWithFiniteDifferences) {
  DerRod rod(make_layout(small_rod()));
  VectorXd x = perturbed(rod.rest_state(), 4e-3, 1);
  rod.update_reference(x);  // stored frames off the rest tangents
  x = perturbed(x, 2e-3, 2);
  for (int j = 0; j < rod.layout().num_edges(); ++j) x[rod.twist_dof(j)] = 0.3 * j - 0.5;
  const auto c = check_form_derivatives(rod, x, 1e-7);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
  EXPECT_LT(c.hessian_asymmetry, 1e-12);
}

TEST(RodDerivatives, DerRestStateCarriesNoForce) {
  // A rest shape with an offset (a second section) must not load the rod (SOFA BeamAdapter's
  // "exploding" multi-section wires).
  const DerRod rod(make_layout(small_rod()));
  VectorXd g;
  rod.gradient(rod.rest_state(), g);
  const double EA = rod.layout().section[1].EA;  // round-off of the rest lengths: ε·EA
  EXPECT_LT(rod.energy(rod.rest_state()), 1e-24);
  EXPECT_LT(g.norm(), 1e-14 * EA);
}

TEST(RodDerivatives, DerUpdateReferenceKeepsTheEnergy) {
  DerRod rod(make_layout(small_rod()));
  VectorXd x = perturbed(rod.rest_state(), 1e-2, 3);
  const double before = rod.energy(x);
  rod.update_reference(x);
  EXPECT_NEAR(rod.energy(x), before, 1e-12 * std::abs(before));
}

TEST(RodDerivatives, PlanarEndMomentAgreesWithFiniteDifferences) {
  const DerRod rod(make_layout(small_rod()));
  PlanarEndMoment moment(rod.layout(), rod.num_dofs(), Eigen::Vector3d::UnitZ());
  moment.set_moment(0.7);
  const VectorXd x = perturbed(rod.rest_state(), 5e-3, 4);
  const auto c = check_form_derivatives(moment, x, 1e-7);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
}

}  // namespace
}  // namespace vessel::msm::rods::test

namespace vessel::msm::rods::test {
namespace {

using Eigen::MatrixXd;
using vessel::msm::test::check_derivatives;
using vessel::msm::test::check_form_derivatives;

/// A Form's energy, gradient and Hessian as functions, or the difference of two Forms' (one term
/// of an energy that is a sum: the full rod minus the rod without it).
struct FormFunctions {
  std::function<double(const VectorXd&)> energy;
  std::function<VectorXd(const VectorXd&)> gradient;
  std::function<MatrixXd(const VectorXd&)> hessian;
};

FormFunctions of(const Form& a, const Form* minus = nullptr) {
  auto g = [](const Form& f, const VectorXd& y) {
    VectorXd out;
    f.gradient(y, out);
    return out;
  };
  auto h = [](const Form& f, const VectorXd& y) {
    SparseMatrix H;
    f.hessian(y, H, false);
    return MatrixXd(H);
  };
  return {[&a, minus](const VectorXd& y) { return a.energy(y) - (minus ? minus->energy(y) : 0.0); },
          [&a, minus, g](const VectorXd& y) -> VectorXd {
            return minus ? VectorXd(g(a, y) - g(*minus, y)) : g(a, y);
          },
          [&a, minus, h](const VectorXd& y) -> MatrixXd {
            return minus ? MatrixXd(h(a, y) - h(*minus, y)) : h(a, y);
          }};
}

/// The relative errors of the gradient and Hessian against central differences, on the rows of
/// [first, first + count) only: a block of DoFs judged by its own size, not the whole vector's
/// (floored at 1e-9 of the whole, for a block the term does not depend on).
std::pair<double, double> block_errors(const FormFunctions& f, const VectorXd& x, double h,
                                       Eigen::Index first, Eigen::Index count) {
  const VectorXd g_fd = vessel::msm::test::fd_gradient(f.energy, x, h);
  const MatrixXd H_fd = vessel::msm::test::fd_jacobian(f.gradient, x, h);
  const VectorXd g = f.gradient(x);
  const MatrixXd H = f.hessian(x);
  return {(g - g_fd).segment(first, count).norm() /
              std::max(g_fd.segment(first, count).norm(), 1e-9 * g_fd.norm()),
          (H - H_fd).middleRows(first, count).norm() /
              std::max(H_fd.middleRows(first, count).norm(), 1e-9 * H_fd.norm())};
}

TEST(RodDerivatives, CordeEnergyGradientHessianAgreeWithFiniteDifferencesTermByTerm) {
  // The alignment penalty (κ = 0.9·G·A) outweighs bending and torsion by far at this state, so
  // one norm over the whole rod cannot see the Darboux term: each term is checked on its own
  // (bending and torsion: the rod with κ = 1e-30 N; alignment: the full rod minus that one), and
  // each on its position and quaternion blocks separately. Reached: 2e-11 (whole rod, alignment),
  // 4e-10 (bending and torsion), 6e-10 at most on a block. With the Darboux gradient halved the
  // whole rod's norm is still 3.6e-7 (the single-norm check passed it); its own term's is 0.5.
  const CordeRod rod(make_layout(small_rod()));
  const CordeRod darboux_only(make_layout(small_rod()), 1e-30);
  const VectorXd x = perturbed(rod.rest_state(), 3e-3, 5);
  const Eigen::Index positions = 3 * rod.num_nodes(), quaternions = x.size() - positions;
  const std::array<std::pair<const char*, FormFunctions>, 3> terms{
      {{"whole rod", of(rod)},
       {"bending and torsion", of(darboux_only)},
       {"alignment", of(rod, &darboux_only)}}};
  for (const auto& [name, f] : terms) {
    const auto c = check_derivatives(f.energy, f.gradient, f.hessian, x, 1e-7);
    EXPECT_LT(c.gradient_error, 1e-6) << name;
    EXPECT_LT(c.hessian_error, 1e-6) << name;
    for (const auto& [block, first, count] : {std::tuple{"positions", Eigen::Index{0}, positions},
                                              std::tuple{"quaternions", positions, quaternions}}) {
      const auto [g_error, h_error] = block_errors(f, x, 1e-7, first, count);
      EXPECT_LT(g_error, 1e-6) << name << ", " << block;
      EXPECT_LT(h_error, 1e-6) << name << ", " << block;
    }
  }
}

TEST(RodDerivatives, CordeRotationVectorEnergyAgreesWithFiniteDifferences) {
  // Small relative rotations (the series branch of atan(s/w)/s) and large ones (closed form).
  const CordeRod rod(make_layout(small_rod()), 0.0, true, DarbouxMeasure::rotation_vector);
  for (double scale : {3e-3, 0.15}) {
    VectorXd x = perturbed(rod.rest_state(), 3e-3, 5);
    const VectorXd q = perturbed(rod.rest_state(), scale, 8);
    x.tail(x.size() - 3 * rod.num_nodes()) = q.tail(x.size() - 3 * rod.num_nodes());
    const auto c = check_form_derivatives(rod, x, 1e-7);
    EXPECT_LT(c.gradient_error, 1e-6) << scale;
    EXPECT_LT(c.hessian_error, 1e-6) << scale;
  }
}

TEST(RodDerivatives, RotationDarbouxVectorIsTheTurningAngle) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  for (double phi : {1e-4, 0.05, 0.7, 2.5}) {
    const Eigen::Quaterniond a(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()));
    const Eigen::Quaterniond b = a * Eigen::Quaterniond(Eigen::AngleAxisd(phi, axis));
    const std::array<double, 8> q{a.w(), a.x(), a.y(), a.z(), b.w(), b.x(), b.y(), b.z()};
    const V3<double> omega = rotation_darboux_vector(q, 0.5);
    const Eigen::Vector3d o(omega.x, omega.y, omega.z);
    EXPECT_LT((0.5 * o - phi * axis).norm(), 1e-14) << phi;  // in q_a's frame: the axis itself
    const V3<double> paper = darboux_vector(q, 0.5);
    EXPECT_NEAR(0.5 * std::sqrt(dot(paper, paper)), 2.0 * std::sin(phi / 2.0), 1e-14) << phi;
  }
}

TEST(RodDerivatives, CordeConstraintJacobianAndWeightedHessian) {
  const CordeRod rod(make_layout(small_rod()));
  const VectorXd x = perturbed(rod.rest_state(), 3e-3, 6);
  const VectorXd lambda = perturbed(VectorXd::Zero(rod.num_constraints()), 1.0, 7);
  // λ·c(x) as a scalar function: its gradient is Jᵀλ, its Hessian Σ λ_k ∇²c_k.
  const auto c = check_derivatives(
      [&](const VectorXd& y) {
        VectorXd cy;
        rod.evaluate(y, cy);
        return lambda.dot(cy);
      },
      [&](const VectorXd& y) -> VectorXd {
        SparseMatrix J;
        rod.jacobian(y, J);
        return J.transpose() * lambda;
      },
      [&](const VectorXd& y) -> Eigen::MatrixXd {
        SparseMatrix H;
        rod.weighted_hessian(y, lambda, H);
        return Eigen::MatrixXd(H);
      },
      x, 1e-7);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
}

}  // namespace
}  // namespace vessel::msm::rods::test
