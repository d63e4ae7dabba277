// Every stiffness rule on single elements against values derived by hand (independent of the
// code: each expected value below is a closed form worked out in the comment beside it).
//
// Notation: g_e = (+d at node a, −d at node b) for edge e = (a, b), d the unit edge vector. The
// least-squares fit solves Σ_f (g_eᵀg_f)² k_f = g_eᵀ K g_e; g_eᵀKg_e = 2·V·W(ε) with ε the strain
// of the displacement g_e, ε = sym(d ⊗ (∇N_a − ∇N_b)), W = ½λ(tr ε)² + μ ε:ε.
#include <gtest/gtest.h>

#include <cmath>

#include "meshes/foundation/errors.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/topology/springs.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kE = 14.24e3;  // Pa

double lame_lambda(double nu) { return kE * nu / ((1 + nu) * (1 - 2 * nu)); }
double lame_mu(double nu) { return kE / (2 * (1 + nu)); }

/// k of the spring between nodes a and b after assigning `rule` on a one-tet network.
double k_of(const SpringNetwork& net, int a, int b) {
  for (const Spring& s : net.springs) {
    if (std::minmax(s.a, s.b) == std::minmax(a, b)) return s.law.k1;
  }
  ADD_FAILURE() << "no spring " << a << "-" << b;
  return 0.0;
}

SpringNetwork tet_network(const std::array<Vec3, 4>& x, StiffnessRule rule, double nu) {
  TetMesh m;
  m.nodes.assign(x.begin(), x.end());
  m.tets = {{0, 1, 2, 3}};
  SpringNetwork net = build_volume_network(m);
  StiffnessParams p;
  p.youngs_modulus = kE;
  p.poisson_ratio = nu;
  assign_stiffness(net, rule, p);
  return net;
}

SpringNetwork triangle_network(const std::array<Vec3, 3>& x, StiffnessRule rule, double nu,
                               double t) {
  TriangleSurface s;
  s.nodes.assign(x.begin(), x.end());
  s.triangles = {{0, 1, 2}};
  SpringNetwork net = build_triangle_network(s, t);
  StiffnessParams p;
  p.youngs_modulus = kE;
  p.poisson_ratio = nu;
  assign_stiffness(net, rule, p);
  return net;
}

std::array<Vec3, 4> regular_tet(double l) {
  return {Vec3(0, 0, 0), Vec3(l, 0, 0), Vec3(l / 2, l * std::sqrt(3.0) / 2, 0),
          Vec3(l / 2, l * std::sqrt(3.0) / 6, l * std::sqrt(2.0 / 3.0))};
}
/// The corner tet: origin and a·e_x, a·e_y, a·e_z. Three axis edges of length a, three diagonal
/// edges of length a√2, V = a³/6.
std::array<Vec3, 4> corner_tet(double a) {
  return {Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(0, a, 0), Vec3(0, 0, a)};
}

}  // namespace

TEST(StiffnessRulesByHand, RegularTetEveryRule) {
  // Edge l, V = l³/(6√2).
  //   seed000:    k = E·A/h0 with A = h0² → E·l
  //   seed001:    k = E·(V/3)/l² = E·l/(18√2)
  //   van-gelder: k = E·V/l² = E·l/(6√2)
  //   lloyd:      k = (2√2/25)·E·l (the published constant); (24/25)·E·V/l² is the same number,
  //               so the per-element V/L² form and the "regular tet of equal volume" form agree
  //   uniform:    41.106 N/m
  const double l = 1.5e-3;
  const auto x = regular_tet(l);
  const double rt2 = std::sqrt(2.0);
  const double tol = 1e-12 * kE * l;
  for (int a = 0; a < 4; ++a) {
    for (int b = a + 1; b < 4; ++b) {
      EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::seed000, 0.25), a, b), kE * l, tol);
      EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::seed001, 0.25), a, b), kE * l / (18 * rt2),
                  tol);
      EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::van_gelder, 0.25), a, b), kE * l / (6 * rt2),
                  tol);
      EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::lloyd, 0.25), a, b), 2 * rt2 / 25 * kE * l,
                  tol);
      EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::uniform, 0.25), a, b), 41.106, 0.0);
    }
  }
  // The equal-volume alternative, by hand: l_eq = (6√2·V)^{1/3} = l here.
  const double V = std::abs(signed_volume(x[0], x[1], x[2], x[3]));
  EXPECT_NEAR(std::cbrt(6 * rt2 * V), l, 1e-12 * l);
  EXPECT_NEAR(lloyd_tet_edge_stiffness(kE, V, l), 2 * rt2 / 25 * kE * std::cbrt(6 * rt2 * V), tol);
}

TEST(StiffnessRulesByHand, LloydDoesNotReadPoissonsRatio) {
  const double l = 1e-3;
  for (const auto& x : {regular_tet(l), corner_tet(l)}) {
    const SpringNetwork ref = tet_network(x, StiffnessRule::lloyd, 0.25);
    for (double nu : {0.0, 0.3, 0.45, 0.49, 0.5}) {
      const SpringNetwork net = tet_network(x, StiffnessRule::lloyd, nu);
      for (std::size_t i = 0; i < net.springs.size(); ++i) {
        EXPECT_EQ(net.springs[i].law.k1, ref.springs[i].law.k1) << "ν = " << nu;
      }
    }
  }
}

TEST(StiffnessRulesByHand, RegularTetLeastSquaresFitAtAnyNu) {
  // Regular tet: every edge meets four others at 60° ((g_eᵀg_f)² = 1/4) and is opposite one
  // (0), |g_e|⁴ = 4, so by symmetry one k with 5k = g_eᵀKg_e. For the regular simplex
  // ∇N_a − ∇N_b = (2/l)·d, so ε = (2/l) d⊗d: tr ε = 2/l, ε:ε = 4/l², W = (2λ + 4μ)/l², and
  // g_eᵀKg_e = 2V·W = 4V(λ + 2μ)/l² = (√2/3)(λ + 2μ)·l (4V/l² = 4l/(6√2)) → k = (√2/15)(λ + 2μ)·l.
  // At ν = 1/4 (λ = μ = 0.4E): k = (√2/15)·1.2E·l = (2√2/25)·E·l, Lloyd's constant.
  const double l = 2e-3;
  const auto x = regular_tet(l);
  for (double nu : {0.0, 0.25, 0.3, 0.45, 0.49}) {
    const double expected = std::sqrt(2.0) / 15 * (lame_lambda(nu) + 2 * lame_mu(nu)) * l;
    const SpringNetwork net = tet_network(x, StiffnessRule::least_squares_fit, nu);
    for (const Spring& s : net.springs) EXPECT_NEAR(s.law.k1, expected, 1e-9 * expected) << nu;
  }
  const double at_quarter = k_of(tet_network(x, StiffnessRule::least_squares_fit, 0.25), 0, 1);
  EXPECT_NEAR(at_quarter, 2 * std::sqrt(2.0) / 25 * kE * l, 1e-9 * kE * l);
  // The figures: ratio (λ + 2μ)/(1.2E) = (1 − ν)/(1.2(1 + ν)(1 − 2ν)): 3.161× Lloyd's at
  // ν = 0.45 and 14.26× at 0.49.
  const double lloyd = 2 * std::sqrt(2.0) / 25 * kE * l;
  EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::least_squares_fit, 0.45), 0, 1) / lloyd, 3.161,
              1e-3);
  EXPECT_NEAR(k_of(tet_network(x, StiffnessRule::least_squares_fit, 0.49), 0, 1) / lloyd, 14.262,
              1e-3);
  EXPECT_THROW((void)tet_network(x, StiffnessRule::least_squares_fit, 0.5), InputError);
}

TEST(StiffnessRulesByHand, CornerTetIrregularValues) {
  // Corner tet, a = 1 mm, V = a³/6; axis edges (0, i) of length a, diagonals (i, j) of a√2.
  //   van-gelder: axis E·V/a² = E·a/6, diagonal E·V/(2a²) = E·a/12
  //   seed001:    a third of those, E·a/18 and E·a/36
  //   lloyd:      24/25 of van-gelder, 4E·a/25 and 2E·a/25
  //   seed000:    E·L: E·a and E·a√2
  const double a = 1e-3;
  const auto x = corner_tet(a);
  const double tol = 1e-12 * kE * a;
  auto check = [&](StiffnessRule rule, double axis, double diagonal) {
    const SpringNetwork net = tet_network(x, rule, 0.25);
    for (int i = 1; i < 4; ++i) EXPECT_NEAR(k_of(net, 0, i), axis, tol) << to_string(rule);
    for (auto [i, j] : {std::pair{1, 2}, {1, 3}, {2, 3}}) {
      EXPECT_NEAR(k_of(net, i, j), diagonal, tol) << to_string(rule);
    }
  };
  check(StiffnessRule::van_gelder, kE * a / 6, kE * a / 12);
  check(StiffnessRule::seed001, kE * a / 18, kE * a / 36);
  check(StiffnessRule::lloyd, 4 * kE * a / 25, 2 * kE * a / 25);
  check(StiffnessRule::seed000, kE * a, kE * a * std::sqrt(2.0));
  // least-squares fit at ν = 1/4, by hand. ∇N_0 = −(1,1,1)/a, ∇N_i = e_i/a.
  //   Overlaps: two axis edges meet at 90° (0); an axis edge and a diagonal through its end at
  //   45° (½); two diagonals at 60° (¼); disjoint edges 0. So, with k_A axis, k_D diagonal:
  //     axis (0,1):    4k_A + 2·½·k_D             = g Kg_A
  //     diag (1,2):    4k_D + 2·½·k_A + 2·¼·k_D   = g Kg_D
  //   axis (0,1): d = −e_x, ∇N_0 − ∇N_1 = −(2,1,1)/a: ε_xx = 2/a, ε_xy = ε_xz = 1/(2a):
  //     tr ε = 2/a, ε:ε = 5/a², g Kg_A = 2V(2λ + 5μ)/a² = a(2λ + 5μ)/3.
  //   diag (1,2): d = (e_x − e_y)/√2, ∇N_1 − ∇N_2 = (e_x − e_y)/a: ε = (e_x−e_y)⊗(e_x−e_y)/(√2a):
  //     tr ε = √2/a, ε:ε = 2/a², g Kg_D = a(λ + 2μ)/3.
  //   At λ = μ = 2E/5: 4k_A + k_D = (14/15)E·a, k_A + (9/2)k_D = (2/5)E·a
  //     → k_D = 2E·a/51, k_A = 19E·a/85.
  check(StiffnessRule::least_squares_fit, 19 * kE * a / 85, 2 * kE * a / 51);
}

TEST(StiffnessRulesByHand, TrianglesEveryRule) {
  // Equilateral triangle of side l, thickness t, A = (√3/4)l²:
  //   van-gelder and lloyd: E·t·A/l² = (√3/4)·E·t; seed001: a third; seed000: E·t (A = t·h0).
  //   least-squares fit: each edge meets two at 60°: 4k + 2·¼k = 4.5k = g Kg; ε = (2/l) d⊗d,
  //   plane stress λ* + 2μ = E/(1 − ν²): g Kg = 2tA(2λ* + 4μ)/l² = √3·t·E/(1 − ν²),
  //   k = (2√3/9)·E·t/(1 − ν²), which at ν = 1/3 is (√3/4)·E·t.
  const double l = 1e-3, t = 1e-3;
  const std::array<Vec3, 3> eq{Vec3(0, 0, 0), Vec3(l, 0, 0),
                               Vec3(l / 2, l * std::sqrt(3.0) / 2, 0)};
  const double tol = 1e-12 * kE * t;
  for (auto [a, b] : {std::pair{0, 1}, {0, 2}, {1, 2}}) {
    EXPECT_NEAR(k_of(triangle_network(eq, StiffnessRule::van_gelder, 0.3, t), a, b),
                std::sqrt(3.0) / 4 * kE * t, tol);
    EXPECT_NEAR(k_of(triangle_network(eq, StiffnessRule::lloyd, 0.3, t), a, b),
                std::sqrt(3.0) / 4 * kE * t, tol);
    EXPECT_NEAR(k_of(triangle_network(eq, StiffnessRule::seed001, 0.3, t), a, b),
                std::sqrt(3.0) / 12 * kE * t, tol);
    EXPECT_NEAR(k_of(triangle_network(eq, StiffnessRule::seed000, 0.3, t), a, b), kE * t, tol);
    for (double nu : {0.0, 1.0 / 3.0, 0.45}) {
      EXPECT_NEAR(k_of(triangle_network(eq, StiffnessRule::least_squares_fit, nu, t), a, b),
                  2 * std::sqrt(3.0) / 9 * kE * t / (1 - nu * nu), 1e-9 * kE * t);
    }
  }
  // Irregular: right isosceles triangle with legs a: A = a²/2; lloyd = van-gelder:
  // legs E·t·(a²/2)/a² = E·t/2, hypotenuse E·t·(a²/2)/(2a²) = E·t/4.
  const double a = 1e-3;
  const std::array<Vec3, 3> right{Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(0, a, 0)};
  const SpringNetwork net = triangle_network(right, StiffnessRule::lloyd, 0.3, t);
  EXPECT_NEAR(k_of(net, 0, 1), kE * t / 2, tol);
  EXPECT_NEAR(k_of(net, 0, 2), kE * t / 2, tol);
  EXPECT_NEAR(k_of(net, 1, 2), kE * t / 4, tol);
}
