// Twist buckling of a rod clamped at both ends (Greenhill): the straight rod under end twist Θ
// loses stability at M_t·L/EI = μ, the first non-zero root of tan(μ/2) = μ/2 (8.9868).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fem_reference/rod_theory/elastica.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/der_rod.hpp"
#include "rod_cases.hpp"
#include "rod_eigen.hpp"

namespace vessel::msm::rods::test {
namespace {

/// M_t L/EI at which the DER rod's Hessian at the uniformly twisted straight state (an
/// equilibrium: each vertex carries M_t l̄_i/GJ of twist) stops being positive definite.
double der_greenhill(int segments) {
  RodSpec spec = uniform_rod(test_material(), kLength, kDiameter, segments);
  spec.clamp_end = true;
  const DerRod rod(make_layout(spec));
  const double EI = rod.layout().section[1].EI, GJ = rod.layout().section[1].GJ;
  const int edges = rod.layout().num_edges();  // ghost, N material, ghost
  const auto min_eigenvalue = [&](double mu) {
    const double total = mu * EI / GJ;  // Θ = M_t L/GJ
    VectorXd x = rod.rest_state();
    for (int j = 1; j + 1 < edges; ++j) x[rod.twist_dof(j)] = total * (j - 0.5) / segments;
    x[rod.twist_dof(edges - 1)] = total;
    SparseMatrix H;
    rod.hessian(x, H, false);
    return smallest_eigenvalue(H, rod.clamp_fixed());
  };
  return find_sign_change(min_eigenvalue, 5.0, 12.0);
}

/// The same for a quaternion rod's energy: CORDE (inextensible) or XPBD's (CORDE's terms with
/// the unit quaternions as the only constraints; XPBD's statics are this energy's equilibria,
/// tests/rods/test_xpbd.cpp). The uniformly twisted straight state carries the same torque
/// GJ sin(Δθ_i)/l̄_i at every vertex (the paper's Darboux vector): Δθ = a inside, asin(sin a / 2)
/// at the two half-segment end vertices, M_t = GJ sin(a)/l. It is checked to be an equilibrium
/// (the unit quaternions' multipliers from ∇E); the Hessian of the Lagrangian on the constraints'
/// null space stops being positive definite at M_t L/EI.
double quaternion_greenhill(int segments, bool inextensible) {
  RodSpec spec = uniform_rod(test_material(), kLength, kDiameter, segments);
  spec.clamp_end = true;
  const CordeRod rod(make_layout(spec), 0.0, inextensible);
  const RodLayout& L = rod.layout();
  const double EI = L.section[1].EI, GJ = L.section[1].GJ, l = kLength / segments;
  const int edges = L.num_edges();  // ghost, N material, ghost
  const auto state = [&](double mu, VectorXd& x, VectorXd& lambda) {
    const double a = std::asin(mu * EI * l / (GJ * kLength));
    const double end = std::asin(std::sin(a) / 2.0);
    x = rod.rest_state();
    double theta = 0.0;
    for (int j = 1; j < edges; ++j) {
      theta += (j == 1 || j == edges - 1) ? end : a;
      const Eigen::Quaterniond q =
          rod.clamp_frame() * Eigen::Quaterniond(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
      x.segment<4>(rod.quaternion_dof(j)) << q.w(), q.x(), q.y(), q.z();
    }
    VectorXd g;
    rod.gradient(x, g);
    lambda = VectorXd::Zero(rod.num_constraints());
    int row = 0;
    for (int j = 0; j < edges; ++j) {
      if (L.ghost[j]) continue;
      if (inextensible) ++row;  // no axial force: the stretch multipliers are zero
      const int d = rod.quaternion_dof(j);
      lambda[row++] = -g.segment<4>(d).dot(x.segment<4>(d)) / 2.0;  // ∇E + 2μ q = 0
    }
    SparseMatrix J;
    rod.jacobian(x, J);
    VectorXd residual = g + J.transpose() * lambda;
    const auto fixed = rod.clamp_fixed();
    for (int i = 0; i < residual.size(); ++i) residual[i] = fixed[i] ? 0.0 : residual[i];
    return residual.norm();
  };
  VectorXd x, lambda;
  // Equilibrium to round-off of the torque 8 EI/L carried by the quaternions.
  EXPECT_LT(state(8.0, x, lambda), 1e-7 * 8.0 * EI / kLength) << "twisted state not an equilibrium";
  const auto min_eigenvalue = [&](double mu) {
    state(mu, x, lambda);
    SparseMatrix H, Hc, J;
    rod.hessian(x, H, false);
    rod.weighted_hessian(x, lambda, Hc);
    rod.jacobian(x, J);
    return smallest_constrained_eigenvalue(H + Hc, J, rod.clamp_fixed());
  };
  // Δθ = a stays below π/2 (the paper's torque GJ sin(a)/l peaks there).
  return find_sign_change(min_eigenvalue, 5.0, std::min(12.0, 0.99 * GJ * kLength / (EI * l)));
}

void quaternion_greenhill_row(const char* model, bool inextensible) {
  const double exact = rod_theory::greenhill_clamped();
  double e[3];
  const int ns[3] = {16, 32, 64};
  for (int k = 0; k < 3; ++k) e[k] = std::abs(quaternion_greenhill(ns[k], inextensible) / exact - 1.0);
  std::printf("ROD-TABLE %s greenhill %.3e %.3e %.3e %.2f %.2f\n", model, e[0], e[1], e[2],
              std::log2(e[0] / e[1]), std::log2(e[1] / e[2]));
  EXPECT_LE(e[1], 2.5e-2) << model;
  EXPECT_GT(std::log2(e[1] / e[2]), 1.8) << model;
}

TEST(Greenhill, CordeTwistBucklingOfAClampedRod) { quaternion_greenhill_row("CORDE", true); }

TEST(Greenhill, XpbdEnergyTwistBucklingOfAClampedRod) { quaternion_greenhill_row("XPBD", false); }

TEST(Greenhill, DerTwistBucklingOfAClampedRod) {
  const double exact = rod_theory::greenhill_clamped();
  double e[3];
  const int ns[3] = {16, 32, 64};
  for (int k = 0; k < 3; ++k) e[k] = std::abs(der_greenhill(ns[k]) / exact - 1.0);
  std::printf("ROD-TABLE DER greenhill %.3e %.3e %.3e %.2f %.2f\n", e[0], e[1], e[2],
              std::log2(e[0] / e[1]), std::log2(e[1] / e[2]));
  // No target in the issue; DER gives 2.3e-2 at N = 16, converging at second order.
  EXPECT_LE(e[0], 2.5e-2);
  EXPECT_GT(std::log2(e[1] / e[2]), 1.8);
}

}  // namespace
}  // namespace vessel::msm::rods::test
