#include "verification/contact/wall_crossing.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace vessel::contact {

std::optional<double> segment_triangle_crossing(const Vec3& a, const Vec3& b, const Vec3& p,
                                                const Vec3& q, const Vec3& r) {
  const Vec3 d = b - a, e1 = q - p, e2 = r - p;
  const Vec3 h = d.cross(e2);
  const double det = e1.dot(h);
  // In (or parallel to) the plane, relative to the edges' and the segment's lengths.
  if (std::abs(det) <= 1e-12 * e1.norm() * e2.norm() * d.norm()) return std::nullopt;
  const Vec3 w = a - p;
  const double u = w.dot(h) / det;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const Vec3 c = w.cross(e1);
  const double v = d.dot(c) / det;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double s = e2.dot(c) / det;
  if (s < 0.0 || s > 1.0) return std::nullopt;
  return s;
}

std::optional<WallCrossing> first_wall_crossing(const TetMesh& mesh,
                                                const std::vector<Triangle>& triangles,
                                                const std::vector<Vec3>& displacement,
                                                const std::vector<Vec3>& centreline) {
  auto at = [&](int n) {
    return Vec3(mesh.nodes[static_cast<std::size_t>(n)] +
                displacement[static_cast<std::size_t>(n)]);
  };
  for (std::size_t i = 0; i + 1 < centreline.size(); ++i) {
    const Vec3& a = centreline[i];
    const Vec3& b = centreline[i + 1];
    const Vec3 lo = a.cwiseMin(b), hi = a.cwiseMax(b);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const Vec3 p = at(triangles[t][0]), q = at(triangles[t][1]), r = at(triangles[t][2]);
      if ((p.cwiseMax(q).cwiseMax(r).array() < lo.array()).any() ||
          (p.cwiseMin(q).cwiseMin(r).array() > hi.array()).any())
        continue;
      if (const auto s = segment_triangle_crossing(a, b, p, q, r)) {
        const double longest = std::max({(q - p).norm(), (r - q).norm(), (p - r).norm()});
        return WallCrossing{static_cast<int>(i), static_cast<int>(t), a + *s * (b - a), longest};
      }
    }
  }
  return std::nullopt;
}

std::optional<std::string> describe_wall_crossing(const TetMesh& mesh,
                                                  const std::vector<Vec3>& displacement,
                                                  const std::vector<Vec3>& centreline) {
  const PhysicalGroup& inner = mesh.require_group("inner_wall", 2, "vessel");
  const auto c = first_wall_crossing(mesh, mesh.group_triangles(inner), displacement, centreline);
  if (!c) return std::nullopt;
  return describe(*c) + ": " + kPassedBetweenNodes;
}

std::string describe(const WallCrossing& c) {
  std::ostringstream m;
  m.precision(3);
  m << "the wire's centreline crosses the wall at (" << c.point.x() * 1e3 << ", "
    << c.point.y() * 1e3 << ", " << c.point.z() * 1e3 << ") mm (segment " << c.segment
    << "), through a triangle whose longest edge is " << c.longest_edge * 1e3 << " mm as deformed";
  return m.str();
}

}  // namespace vessel::contact
