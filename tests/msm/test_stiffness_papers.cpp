// Van Gelder (1998) and Lloyd, Székely & Harders (2007) spring constants on one element, checked
// against hand-derived values: the energy of the element's springs under a uniform strain ε,
// Σ ½ k (dᵀεd · l)², against the continuum's ½ V (λ (tr ε)² + 2μ ε:ε) (plane stress for a
// triangle: λ* = Eν/(1 − ν²), V = t·A). The FEM element matrices of the least-squares-fit rule are checked
// against the same closed form, so nothing here compares the code with itself.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "msm/kernels/spring_kernels.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/topology/springs.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kE = 14.24e3;  // Pa

/// Continuum strain energy of volume V under uniform strain eps (3D isotropic), J.
double continuum_energy(const Eigen::Matrix3d& eps, double E, double nu, double V) {
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double mu = E / (2 * (1 + nu));
  return 0.5 * V * (lambda * std::pow(eps.trace(), 2) + 2 * mu * (eps.array().square().sum()));
}

/// Plane-stress energy of a membrane of area A, thickness t under in-plane strain eps (xy).
double plane_stress_energy(const Eigen::Matrix3d& eps, double E, double nu, double A, double t) {
  const double lambda = E * nu / (1 - nu * nu);
  const double mu = E / (2 * (1 + nu));
  return 0.5 * t * A * (lambda * std::pow(eps.trace(), 2) + 2 * mu * (eps.array().square().sum()));
}

/// Energy of springs k on the edges (a, b) of points x under uniform strain eps (small strain:
/// elongation dᵀεd·l).
template <std::size_t N, std::size_t M>
double spring_energy(const std::array<Vec3, N>& x, const std::array<std::pair<int, int>, M>& edges,
                     const std::array<double, M>& k, const Eigen::Matrix3d& eps) {
  double e = 0.0;
  for (std::size_t i = 0; i < M; ++i) {
    const Vec3 c = x[edges[i].first] - x[edges[i].second];
    const double l = c.norm();
    const Vec3 d = c / l;
    e += 0.5 * k[i] * std::pow(d.dot(eps * d) * l, 2);
  }
  return e;
}

/// ½ uᵀ K u for the linear displacement u = ε x at the element's nodes.
double matrix_energy(const Eigen::MatrixXd& K, const std::vector<Vec3>& x,
                     const Eigen::Matrix3d& eps) {
  Eigen::VectorXd u(3 * x.size());
  for (std::size_t i = 0; i < x.size(); ++i) u.segment<3>(3 * i) = eps * x[i];
  return 0.5 * u.dot(K * u);
}

Eigen::Matrix3d strain(double xx, double yy, double zz, double xy, double xz, double yz) {
  Eigen::Matrix3d e;
  e << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  return e;
}

constexpr std::array<std::pair<int, int>, 3> kTri{{{0, 1}, {0, 2}, {1, 2}}};
constexpr std::array<std::pair<int, int>, 6> kTet{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

std::array<Vec3, 3> equilateral(double l) {
  return {Vec3(0, 0, 0), Vec3(l, 0, 0), Vec3(l / 2, l * std::sqrt(3.0) / 2, 0)};
}
/// Regular tetrahedron of edge l·√2 whose edges are the face diagonals of a cube of side l:
/// edge directions (±1, ±1, 0)/√2 and permutations (used for the hand-derived shear values).
std::array<Vec3, 4> cube_tet(double l) {
  return {Vec3(0, 0, 0), Vec3(l, l, 0), Vec3(l, 0, l), Vec3(0, l, l)};
}

/// The network's k for one element (springs in kTri / kTet order).
std::array<double, 3> rule_on_triangle(const std::array<Vec3, 3>& x, StiffnessRule rule, double nu,
                                       double t) {
  TriangleSurface s;
  s.nodes.assign(x.begin(), x.end());
  s.triangles = {{0, 1, 2}};
  SpringNetwork net = build_triangle_network(s, t);
  StiffnessParams p;
  p.youngs_modulus = kE;
  p.poisson_ratio = nu;
  assign_stiffness(net, rule, p);
  std::array<double, 3> k{};
  for (const Spring& sp : net.springs) {
    for (int e = 0; e < 3; ++e) {
      if (std::minmax(sp.a, sp.b) == std::minmax(kTri[e].first, kTri[e].second)) k[e] = sp.law.k1;
    }
  }
  return k;
}
std::array<double, 6> rule_on_tet(const std::array<Vec3, 4>& x, StiffnessRule rule, double nu) {
  TetMesh m;
  m.nodes.assign(x.begin(), x.end());
  m.tets = {{0, 1, 2, 3}};
  SpringNetwork net = build_volume_network(m);
  StiffnessParams p;
  p.youngs_modulus = kE;
  p.poisson_ratio = nu;
  assign_stiffness(net, rule, p);
  std::array<double, 6> k{};
  for (const Spring& sp : net.springs) {
    for (int e = 0; e < 6; ++e) {
      if (std::minmax(sp.a, sp.b) == std::minmax(kTet[e].first, kTet[e].second)) k[e] = sp.law.k1;
    }
  }
  return k;
}

}  // namespace

TEST(StiffnessPapers, FemElementMatricesGiveTheClosedFormEnergyUnderUniformStrain) {
  // Any linear field u = εx is represented exactly by P1 elements: ½uᵀKu must equal the closed
  // form, for a distorted tet and a distorted triangle tilted out of the xy plane.
  const std::array<Vec3, 4> tet{Vec3(0.1e-3, 0, 0), Vec3(1.3e-3, 0.2e-3, 0.1e-3),
                                Vec3(0.4e-3, 1.1e-3, -0.2e-3), Vec3(0.3e-3, 0.5e-3, 0.9e-3)};
  const double V = std::abs(signed_volume(tet[0], tet[1], tet[2], tet[3]));
  const Eigen::Matrix3d e3 = strain(1e-3, -4e-4, 2e-4, 3e-4, -1e-4, 5e-4);
  for (double nu : {0.0, 0.25, 0.45}) {
    const double w = continuum_energy(e3, kE, nu, V);
    EXPECT_NEAR(matrix_energy(fem_tet_stiffness(tet, kE, nu), {tet.begin(), tet.end()}, e3), w,
                1e-12 * w);
  }
  // Triangle in the xy plane (plane stress, in-plane strain only).
  const std::array<Vec3, 3> tri{Vec3(0, 0, 0), Vec3(1.2e-3, 0.1e-3, 0), Vec3(0.3e-3, 0.8e-3, 0)};
  const double A = triangle_area(tri[0], tri[1], tri[2]), t = 1e-3;
  const Eigen::Matrix3d e2 = strain(1e-3, -4e-4, 0, 3e-4, 0, 0);
  for (double nu : {0.0, 1.0 / 3.0, 0.45}) {
    const double w = plane_stress_energy(e2, kE, nu, A, t);
    EXPECT_NEAR(matrix_energy(fem_triangle_stiffness(tri, kE, nu, t), {tri.begin(), tri.end()}, e2),
                w, 1e-12 * w);
  }
}

TEST(StiffnessPapers, EquilateralTriangleReproducesThePlaneStressContinuumAtNuOneThird) {
  // Van Gelder's k = E·t·A/l² and Lloyd et al.'s k = (√3/4)·E·t coincide on one equilateral
  // triangle (A/l² = √3/4); at ν = 1/3 (the only ν a spring triangle can have) its springs store
  // exactly the plane-stress energy under every uniform in-plane strain (three independent ones).
  const double l = 0.8e-3, t = 1e-3, A = std::sqrt(3.0) / 4 * l * l;
  const auto x = equilateral(l);
  for (StiffnessRule rule :
       {StiffnessRule::van_gelder, StiffnessRule::lloyd, StiffnessRule::least_squares_fit}) {
    const auto k = rule_on_triangle(x, rule, 1.0 / 3.0, t);
    for (double ki : k) EXPECT_NEAR(ki, std::sqrt(3.0) / 4 * kE * t, 1e-12 * kE * t);
    for (const Eigen::Matrix3d& eps :
         {strain(1e-3, 0, 0, 0, 0, 0), strain(0, 1e-3, 0, 0, 0, 0), strain(0, 0, 0, 1e-3, 0, 0),
          strain(7e-4, -2e-4, 0, 3e-4, 0, 0)}) {
      const double w = plane_stress_energy(eps, kE, 1.0 / 3.0, A, t);
      EXPECT_NEAR(spring_energy(x, kTri, k, eps), w, 1e-12 * w) << to_string(rule);
    }
  }
  // At ν = 0 the least-squares-fit rule gives, by symmetry, one k for the three edges; by hand
  // it matches the uniaxial energy (edges at 0°, 60°, 120°: dᵀεd = e, e/4, e/4, so ½kl²e²·9/8 =
  // ½tAEe², k = (8/9)(√3/4)Et = (2√3/9)Et), and then the equibiaxial energy (each edge e·l:
  // 3·½kl²e²) is 4/3 of the continuum's tAEe²: no k is exact away from ν = 1/3.
  const auto k0 = rule_on_triangle(x, StiffnessRule::least_squares_fit, 0.0, t);
  for (double ki : k0) EXPECT_NEAR(ki, 2 * std::sqrt(3.0) / 9 * kE * t, 1e-12 * kE * t);
  const Eigen::Matrix3d uni = strain(1e-3, 0, 0, 0, 0, 0), bi = strain(1e-3, 1e-3, 0, 0, 0, 0);
  EXPECT_NEAR(spring_energy(x, kTri, k0, uni) / plane_stress_energy(uni, kE, 0.0, A, t), 1.0, 1e-12);
  EXPECT_NEAR(spring_energy(x, kTri, k0, bi) / plane_stress_energy(bi, kE, 0.0, A, t), 4.0 / 3.0,
              1e-12);
}

TEST(StiffnessPapers, RegularTetrahedronHandValuesUnderDilationAndShear) {
  // Regular tet with edges along the cube face diagonals (±1, ±1, 0)/√2 …, edge L = l√2,
  // V = l³/3. Van Gelder (3D): k = E·V/L² = E·l/6 on every edge. Lloyd et al. (2007):
  // k = (2√2/25)·E·L = (24/25)·E·V/L² at ν = 1/4.
  // Spring energy Σ ½ k (dᵀεd)² L², by hand:
  //   dilation ε = e I:          6 · ½ k e² L²  = 3 k L² e²  → VG: 3 E V e²   (continuum at ν = 1/4:
  //                                                              ½ V (9λ + 6μ) e² = 3 E V e²)
  //   shear εxy = γ/2:           two edges with dᵀεd = ±γ/2: ¼ k L² γ² → VG: ¼ E V γ²
  //                                                              (continuum: ½ V 2μ γ²/2 = 0.2 E V γ²)
  //   shear εxx = −εyy = γ/2:    four edges with ±γ/4: ⅛ k L² γ² → VG: ⅛ E V γ²  (continuum 0.2 E V γ²)
  // So Van Gelder's tet is exact in dilation at ν = 1/4 and 1.25× / 0.625× the continuum in the
  // two shears (a single tet is cubic, not isotropic); Lloyd's is 24/25 of each.
  const double l = 1e-3, L = l * std::sqrt(2.0), V = l * l * l / 3.0;
  const auto x = cube_tet(l);
  ASSERT_NEAR(std::abs(signed_volume(x[0], x[1], x[2], x[3])), V, 1e-24);
  const double e = 1e-3, g = 1e-3;
  const Eigen::Matrix3d dil = strain(e, e, e, 0, 0, 0), s1 = strain(0, 0, 0, g / 2, 0, 0),
                        s2 = strain(g / 2, -g / 2, 0, 0, 0, 0);
  const auto vg = rule_on_tet(x, StiffnessRule::van_gelder, 0.25);
  const auto ll = rule_on_tet(x, StiffnessRule::lloyd, 0.25);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(vg[i], kE * V / (L * L), 1e-12 * kE * l);
    EXPECT_NEAR(ll[i], 2 * std::sqrt(2.0) / 25 * kE * L, 1e-9 * kE * l);
  }
  const double c_dil = continuum_energy(dil, kE, 0.25, V);
  EXPECT_NEAR(c_dil, 3 * kE * V * e * e, 1e-12 * c_dil);
  EXPECT_NEAR(continuum_energy(s1, kE, 0.25, V), 0.2 * kE * V * g * g, 1e-12 * c_dil);
  EXPECT_NEAR(continuum_energy(s2, kE, 0.25, V), 0.2 * kE * V * g * g, 1e-12 * c_dil);
  const double tol = 1e-12 * c_dil;
  EXPECT_NEAR(spring_energy(x, kTet, vg, dil), 3 * kE * V * e * e, tol);
  EXPECT_NEAR(spring_energy(x, kTet, vg, s1), 0.25 * kE * V * g * g, tol);
  EXPECT_NEAR(spring_energy(x, kTet, vg, s2), 0.125 * kE * V * g * g, tol);
  EXPECT_NEAR(spring_energy(x, kTet, ll, dil), 0.96 * 3 * kE * V * e * e, tol);
  EXPECT_NEAR(spring_energy(x, kTet, ll, s1), 0.96 * 0.25 * kE * V * g * g, tol);
  EXPECT_NEAR(spring_energy(x, kTet, ll, s2), 0.96 * 0.125 * kE * V * g * g, tol);
}

TEST(StiffnessPapers, LeastSquaresFitIsTheLeastSquaresMatchOfTheFemMatrixOnAnyElement) {
  // The least-squares-fit rule minimises ‖Σ k_e g_e g_eᵀ − K_FEM‖_F: on a distorted tet and triangle, any
  // perturbation of one k raises the misfit (first-order optimality, checked by hand: the misfit
  // is quadratic in k, so f(k ± h e_i) − f(k) = h²‖g_i g_iᵀ‖² > 0 exactly).
  const std::array<Vec3, 4> tet{Vec3(0, 0, 0), Vec3(1.3e-3, 0.2e-3, 0.1e-3),
                                Vec3(0.4e-3, 1.1e-3, -0.2e-3), Vec3(0.3e-3, 0.5e-3, 0.9e-3)};
  const Eigen::MatrixXd K = fem_tet_stiffness(tet, kE, 0.3);
  const auto k = least_squares_fit_tet_stiffness(tet, kE, 0.3);
  auto misfit = [&](const std::array<double, 6>& kk) {
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(12, 12);
    for (int e = 0; e < 6; ++e) {
      Eigen::VectorXd gv = Eigen::VectorXd::Zero(12);
      const Vec3 d = (tet[kTet[e].first] - tet[kTet[e].second]).normalized();
      gv.segment<3>(3 * kTet[e].first) = d;
      gv.segment<3>(3 * kTet[e].second) = -d;
      S += kk[e] * gv * gv.transpose();
    }
    return (S - K).squaredNorm();
  };
  const double f0 = misfit(k);
  for (int i = 0; i < 6; ++i) {
    for (double h : {1e-3, -1e-3}) {
      auto kp = k;
      kp[i] += h * k[i];
      // ‖g_i g_iᵀ‖_F² = ‖g_i‖⁴ = 4 (two unit blocks): the exact quadratic increase.
      EXPECT_NEAR(misfit(kp) - f0, 4 * std::pow(h * k[i], 2), 1e-6 * 4 * std::pow(h * k[i], 2));
    }
  }
}
