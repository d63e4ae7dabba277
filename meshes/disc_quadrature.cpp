#include "meshes/disc_quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vessel {

namespace {

double cross2(const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); }

/// A piece of the region's boundary, counter-clockwise: a straight segment from → to, or an arc
/// of the disc's circle from angle phi0 to phi1 > phi0 (about the disc's centre).
struct BoundaryPiece {
  bool arc = false;
  Vec2 from = Vec2::Zero(), to = Vec2::Zero();
  double phi0 = 0.0, phi1 = 0.0;
};

/// The part of edge p → q inside the disc, as parameters [lo, hi] ⊂ [0, 1] of p + t (q − p);
/// false if it is empty or a single point (the edge misses or only touches the circle).
bool edge_inside_disc(const Vec2& p, const Vec2& q, const Vec2& c, double r, double& lo,
                      double& hi) {
  const Vec2 d = q - p, f = p - c;
  const double a = d.squaredNorm(), b = 2.0 * f.dot(d), cc = f.squaredNorm() - r * r;
  const double disc = b * b - 4.0 * a * cc;
  if (a <= 0.0 || disc <= 0.0) return false;
  const double s = std::sqrt(disc);
  lo = std::max(0.0, (-b - s) / (2.0 * a));
  hi = std::min(1.0, (-b + s) / (2.0 * a));
  return hi - lo > 1e-14;
}

/// The boundary of T ∩ D counter-clockwise: the inside parts of the edges, joined by arcs where
/// the boundary leaves one edge on the circle and meets the next edge on the circle.
std::vector<BoundaryPiece> clipped_boundary(const std::array<Vec2, 3>& t, const Vec2& c,
                                            double r) {
  std::vector<BoundaryPiece> segments;
  for (int e = 0; e < 3; ++e) {
    const Vec2& p = t[e];
    const Vec2& q = t[(e + 1) % 3];
    double lo = 0.0, hi = 0.0;
    if (!edge_inside_disc(p, q, c, r, lo, hi)) continue;
    segments.push_back({false, p + lo * (q - p), p + hi * (q - p), 0.0, 0.0});
  }
  std::vector<BoundaryPiece> pieces;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    pieces.push_back(segments[k]);
    const Vec2& end = segments[k].to;
    const Vec2& next = segments[(k + 1) % segments.size()].from;
    if ((next - end).norm() <= 1e-12 * r) continue;  // through a vertex inside the disc
    BoundaryPiece arc{true, end, next, std::atan2(end.y() - c.y(), end.x() - c.x()),
                      std::atan2(next.y() - c.y(), next.x() - c.x())};
    while (arc.phi1 <= arc.phi0) arc.phi1 += 2.0 * std::numbers::pi;
    pieces.push_back(arc);
  }
  return pieces;
}

bool contains(const std::array<Vec2, 3>& t, const Vec2& x) {
  return cross2(t[1] - t[0], x - t[0]) >= 0.0 && cross2(t[2] - t[1], x - t[1]) >= 0.0 &&
         cross2(t[0] - t[2], x - t[2]) >= 0.0;
}

/// The 3-point rule (degree 2) on the triangle (o, u, v), counter-clockwise.
void add_triangle(const Vec2& o, const Vec2& u, const Vec2& v, std::vector<PlanePoint>& out) {
  const double area = 0.5 * cross2(u - o, v - o);
  if (area <= 0.0) return;
  const std::array<Vec2, 3> p{o, u, v};
  for (int k = 0; k < 3; ++k) {
    const Vec2 x = (p[0] + p[1] + p[2]) / 6.0 + 0.5 * p[k];  // barycentric 2/3 at p[k], 1/6 else
    out.push_back({x, area / 3.0});
  }
}

/// The curved triangle between o and the arc φ ∈ [phi0, phi1] of the circle (c, r): the points
/// o + s (γ(φ) − o), s ∈ [0, 1], whose area element is s · (γ − o) × γ′(φ) ds dφ.
void add_curved_triangle(const Vec2& o, const Vec2& c, double r, double phi0, double phi1,
                         std::vector<PlanePoint>& out) {
  static const std::vector<PlanePoint> along_fan = gauss_legendre_01(3);
  static const std::vector<PlanePoint> along_arc = gauss_legendre_01(6);
  const int sub_arcs = std::max(1, static_cast<int>(std::ceil((phi1 - phi0) / (std::numbers::pi / 4))));
  const double h = (phi1 - phi0) / sub_arcs;
  for (int k = 0; k < sub_arcs; ++k) {
    for (const PlanePoint& a : along_arc) {
      const double phi = phi0 + h * (k + a.x.x());
      const Vec2 gamma = c + r * Vec2(std::cos(phi), std::sin(phi));
      const Vec2 tangent = r * Vec2(-std::sin(phi), std::cos(phi));
      const double sweep = cross2(gamma - o, tangent);
      for (const PlanePoint& s : along_fan) {
        const double si = s.x.x();
        out.push_back({o + si * (gamma - o), s.weight * a.weight * h * si * sweep});
      }
    }
  }
}

}  // namespace

std::vector<PlanePoint> gauss_legendre_01(int n) {
  std::vector<PlanePoint> rule(static_cast<std::size_t>(n));
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));  // initial guess for root i
    double dp = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0, p1 = 0.0;  // Bonnet's recurrence up to P_n(z)
      for (int j = 1; j <= n; ++j) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
        if (j == n) dp = n * (z * p0 - p1) / (z * z - 1.0);
      }
      const double step = p0 / dp;
      z -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const double w = 1.0 / ((1.0 - z * z) * dp * dp);  // 2/((1−z²)P'²) on [−1, 1], halved
    rule[static_cast<std::size_t>(i)] = {Vec2(0.5 * (1.0 - z), 0.0), w};
    rule[static_cast<std::size_t>(n - 1 - i)] = {Vec2(0.5 * (1.0 + z), 0.0), w};
  }
  return rule;
}

std::vector<PlanePoint> triangle_disc_quadrature(const std::array<Vec2, 3>& triangle,
                                                 const Vec2& centre, double radius) {
  std::array<Vec2, 3> t = triangle;
  if (cross2(t[1] - t[0], t[2] - t[0]) < 0.0) std::swap(t[1], t[2]);
  std::vector<PlanePoint> out;
  const std::vector<BoundaryPiece> pieces = clipped_boundary(t, centre, radius);
  if (pieces.empty()) {
    // No edge enters the disc: the disc lies inside the triangle, or they are apart.
    if (contains(t, centre)) add_curved_triangle(centre, centre, radius, 0.0, 2.0 * std::numbers::pi, out);
    return out;
  }
  // The region is convex: the mean of its boundary's corners lies inside it, and every piece seen
  // from there sweeps a positive area.
  Vec2 o = Vec2::Zero();
  for (const auto& p : pieces) o += p.from;
  o /= static_cast<double>(pieces.size());
  for (const auto& p : pieces) {
    if (p.arc) add_curved_triangle(o, centre, radius, p.phi0, p.phi1, out);
    else add_triangle(o, p.from, p.to, out);
  }
  return out;
}

}  // namespace vessel
