// Quadrature over triangle ∩ disc against closed forms: a disc's area π r², first moment
// (centre · π r²) and polar second moment (π r⁴ / 2), and a half disc's, summed over a grid of
// triangles that the circle cuts in every way (vertices inside, edges crossing, arcs).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "meshes/disc_quadrature.hpp"

using namespace vessel;

namespace {

constexpr double kPi = std::numbers::pi;

/// The triangles of an n × n grid of squares on [x0, x0 + w] × [y0, y0 + w], two per square,
/// alternately counter-clockwise and clockwise (the quadrature must not depend on orientation).
std::vector<std::array<Vec2, 3>> grid_triangles(double x0, double y0, double w, int n) {
  std::vector<std::array<Vec2, 3>> tris;
  const double h = w / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec2 a(x0 + i * h, y0 + j * h), b = a + Vec2(h, 0), c = a + Vec2(h, h), d = a + Vec2(0, h);
      tris.push_back({a, b, c});
      tris.push_back({a, d, c});  // clockwise
    }
  return tris;
}

struct Moments {
  double area = 0.0;
  Vec2 first = Vec2::Zero();
  double polar = 0.0;  ///< ∫ |x − centre|² dA
};

Moments moments(const std::vector<std::array<Vec2, 3>>& tris, const Vec2& c, double r) {
  Moments m;
  for (const auto& t : tris)
    for (const PlanePoint& q : triangle_disc_quadrature(t, c, r)) {
      EXPECT_GT(q.weight, 0.0);
      EXPECT_LE((q.x - c).norm(), r * (1 + 1e-12));
      m.area += q.weight;
      m.first += q.weight * q.x;
      m.polar += q.weight * (q.x - c).squaredNorm();
    }
  return m;
}

}  // namespace

TEST(DiscQuadrature, GaussLegendreIsExactToDegreeTwoNMinusOne) {
  for (int n : {1, 3, 6}) {
    const auto rule = gauss_legendre_01(n);
    for (int p = 0; p <= 2 * n - 1; ++p) {
      double s = 0.0;
      for (const auto& q : rule) s += q.weight * std::pow(q.x.x(), p);
      EXPECT_NEAR(s, 1.0 / (p + 1), 1e-15) << "n " << n << " degree " << p;
    }
  }
}

TEST(DiscQuadrature, DiscInsideOneTriangle) {
  const std::array<Vec2, 3> big{Vec2(-10, -10), Vec2(10, -10), Vec2(0, 10)};
  const Vec2 c(0.3, -0.2);
  const double r = 1.5;
  const Moments m = moments({big}, c, r);
  EXPECT_NEAR(m.area / (kPi * r * r), 1.0, 1e-13);
  EXPECT_NEAR((m.first / m.area - c).norm(), 0.0, 1e-13);
  EXPECT_NEAR(m.polar / (kPi * std::pow(r, 4) / 2), 1.0, 1e-13);
}

TEST(DiscQuadrature, TriangleInsideTheDiscIsTheWholeTriangle) {
  const std::array<Vec2, 3> t{Vec2(0.1, 0.1), Vec2(0.5, 0.2), Vec2(0.2, 0.6)};
  const Moments m = moments({t}, Vec2(0.3, 0.3), 5.0);
  const double area = 0.5 * ((t[1] - t[0]).x() * (t[2] - t[0]).y() - (t[1] - t[0]).y() * (t[2] - t[0]).x());
  EXPECT_NEAR(m.area / area, 1.0, 1e-14);
  EXPECT_NEAR((m.first / m.area - (t[0] + t[1] + t[2]) / 3).norm(), 0.0, 1e-14);
}

TEST(DiscQuadrature, DiscOverAGridOfTrianglesHasTheDiscsMoments) {
  // The circle cuts many triangles: some in one arc, some with a vertex inside, some in two arcs.
  for (int n : {3, 7, 20}) {
    const Vec2 c(0.137, -0.071);
    const double r = 0.61;
    const Moments m = moments(grid_triangles(-1.0, -1.0, 2.0, n), c, r);
    EXPECT_NEAR(m.area / (kPi * r * r), 1.0, 1e-12) << n;
    EXPECT_NEAR((m.first / m.area - c).norm(), 0.0, 1e-12) << n;
    EXPECT_NEAR(m.polar / (kPi * std::pow(r, 4) / 2), 1.0, 1e-12) << n;
  }
}

TEST(DiscQuadrature, HalfDiscOnTheGridsEdge) {
  // Centre on the edge y = 0 of a grid covering y ≥ 0: area π r²/2, ∫ y dA = 2 r³/3.
  const double r = 0.4;
  const Vec2 c(0.05, 0.0);
  const Moments m = moments(grid_triangles(-1.0, 0.0, 2.0, 9), c, r);
  EXPECT_NEAR(m.area / (kPi * r * r / 2), 1.0, 1e-12);
  EXPECT_NEAR(m.first.y() / (2 * r * r * r / 3), 1.0, 1e-12);
  EXPECT_NEAR(m.first.x() / m.area, c.x(), 1e-12);
}

TEST(DiscQuadrature, ApartOrTouchingGivesNothing) {
  const std::array<Vec2, 3> t{Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  EXPECT_TRUE(triangle_disc_quadrature(t, Vec2(3, 3), 1.0).empty());
  EXPECT_TRUE(triangle_disc_quadrature(t, Vec2(0.5, -1.0), 1.0).empty());  // tangent to an edge
}
