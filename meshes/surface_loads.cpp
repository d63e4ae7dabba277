#include "meshes/surface_loads.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "meshes/disc_quadrature.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

/// Area-weighted normal (|n| = 2A) of a triangle, outward when the triangle is oriented outward.
Vec3 area_normal(const TetMesh& mesh, const Triangle& t) {
  return (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]);
}

/// Distance from x to the triangle's nearest point.
double distance_to_triangle(const TetMesh& mesh, const Triangle& t, const Vec3& x) {
  return (closest_point_on_triangle(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], x) - x)
      .norm();
}

std::string mm_text(const Vec3& x) {
  std::ostringstream m;
  m << "(" << x.x() * 1e3 << ", " << x.y() * 1e3 << ", " << x.z() * 1e3 << ")";
  return m.str();
}

/// The point of the group's surface nearest spec.point; InputError if it is farther than r_c.
Vec3 nearest_wall_point(const TetMesh& mesh, const PhysicalGroup& group,
                        const ContactPatchSpec& spec, double r) {
  Vec3 best = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (int e : group.elements) {
    const Triangle& t = mesh.triangles[e];
    const Vec3 p =
        closest_point_on_triangle(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], spec.point);
    if ((p - spec.point).squaredNorm() < (best - spec.point).squaredNorm()) best = p;
  }
  const double distance = (best - spec.point).norm();
  if (!(distance <= r)) {
    std::ostringstream m;
    m << "contact point " << mm_text(spec.point) << " mm is off the wall: the nearest point of '"
      << spec.surface_group << "' is " << distance * 1e3 << " mm away, more than the patch radius "
      << r * 1e3 << " mm; expected a point on that surface";
    throw InputError(m.str());
  }
  return best;
}

/// Barycentric coordinates of x with respect to the plane triangle t.
Vec3 barycentric(const std::array<Vec2, 3>& t, const Vec2& x) {
  const auto cross2 = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double total = cross2(t[1] - t[0], t[2] - t[0]);
  const double l1 = cross2(x - t[0], t[2] - t[0]) / total;
  const double l2 = cross2(t[1] - t[0], x - t[0]) / total;
  return {1.0 - l1 - l2, l1, l2};
}

/// Triangles more steeply inclined to the contact's tangent plane than this are not loaded: they
/// would cover a sliver of the disc with a weight 1/cos that grows without bound.
constexpr double kMinFacingCosine = 1e-3;

void validate(const ContactPatchSpec& spec) {
  if (!std::isfinite(spec.radius) || spec.radius <= 0.0) {
    std::ostringstream m;
    m << "contact patch radius = " << spec.radius << " m is invalid: expected a finite value > 0";
    throw InputError(m.str());
  }
  if (!std::isfinite(spec.force) || !spec.point.allFinite() || !spec.direction.allFinite()) {
    throw InputError("contact force, point and direction must be finite numbers");
  }
}

/// The wall's tangent plane at the contact: its normal is the mean outward normal of the
/// triangles within r_c of the centre; (e1, e2) span it.
struct TangentPlane {
  Vec3 centre, normal, e1, e2;
  TangentPlane(const TetMesh& mesh, const PhysicalGroup& group, const Vec3& c, double r)
      : centre(c) {
    Vec3 sum = Vec3::Zero();
    for (int e : group.elements) {
      const Triangle& t = mesh.triangles[e];
      if (distance_to_triangle(mesh, t, centre) <= r) sum += area_normal(mesh, t);
    }
    normal = sum.normalized();
    e1 = normal.unitOrthogonal();
    e2 = normal.cross(e1);
  }
  [[nodiscard]] Vec2 of(const Vec3& x) const { return {(x - centre).dot(e1), (x - centre).dot(e2)}; }
};

/// Adds to the patch the disc's quadrature points on triangle e (none if it does not face the
/// plane or lies outside the disc): clipped in the plane, carried back with weight / cos.
void add_disc_points(const TetMesh& mesh, int e, const TangentPlane& plane, double r,
                     TractionPatch& patch, Vec3& weighted_normal) {
  const Triangle& t = mesh.triangles[e];
  const Vec3 n = area_normal(mesh, t).normalized();
  const double cosine = n.dot(plane.normal);
  // Only triangles facing the plane can lie under the disc; a triangle within the disc is
  // nearer than r_c·(1 + curvature), so 2 r_c keeps every candidate and drops the far wall.
  if (cosine <= kMinFacingCosine || distance_to_triangle(mesh, t, plane.centre) > 2.0 * r) return;
  const std::array<Vec2, 3> flat{plane.of(mesh.nodes[t[0]]), plane.of(mesh.nodes[t[1]]),
                                 plane.of(mesh.nodes[t[2]])};
  const auto points = triangle_disc_quadrature(flat, Vec2::Zero(), r);
  if (points.empty()) return;
  patch.triangles.push_back(e);
  for (const PlanePoint& q : points) {
    const double weight = q.weight / cosine;  // the plane's area element back on the triangle
    patch.points.push_back({e, barycentric(flat, q.x), weight});
    patch.area += weight;
    patch.projected_area += q.weight;
    weighted_normal += weight * n;
  }
}

}  // namespace

TractionPatch contact_patch(const TetMesh& mesh, const ContactPatchSpec& spec) {
  validate(spec);
  const auto& group = mesh.require_group(spec.surface_group, 2, "contact patch");
  const double r = spec.radius;
  const TangentPlane plane(mesh, group, nearest_wall_point(mesh, group, spec, r), r);
  TractionPatch patch;
  patch.centre = plane.centre;
  Vec3 weighted_normal = Vec3::Zero();
  for (int e : group.elements) add_disc_points(mesh, e, plane, r, patch, weighted_normal);
  const double disc_area = std::numbers::pi * r * r;
  if (patch.projected_area > disc_area * (1.0 + 1e-9)) {
    std::ostringstream m;
    m << "contact patch of radius " << r * 1e3 << " mm at " << mm_text(plane.centre)
      << " mm covers " << patch.projected_area / disc_area << " times its disc on '"
      << spec.surface_group << "': the wall folds back within the radius; expected a smaller radius";
    throw InputError(m.str());
  }
  patch.outward_normal = weighted_normal.normalized();
  if (spec.direction.isZero(0.0)) {
    patch.traction = -spec.force / patch.area * patch.outward_normal;
    return patch;
  }
  const Vec3 d = spec.direction.normalized();
  if (d.dot(patch.outward_normal) > -0.5) {
    std::ostringstream m;
    m << "contact direction (" << d.x() << ", " << d.y() << ", " << d.z() << ") at "
      << mm_text(plane.centre) << " mm is not into the wall '" << spec.surface_group
      << "' (its inward normal there is (" << -patch.outward_normal.x() << ", "
      << -patch.outward_normal.y() << ", " << -patch.outward_normal.z()
      << ")); expected one within 60 degrees of it";
    throw InputError(m.str());
  }
  patch.traction = spec.force / patch.area * d;
  return patch;
}

std::vector<SurfacePoint> whole_triangle_points(int triangle, double area) {
  std::vector<SurfacePoint> points;
  for (int k = 0; k < 3; ++k) {
    Vec3 bary = Vec3::Constant(1.0 / 6.0);
    bary[k] = 2.0 / 3.0;
    points.push_back({triangle, bary, area / 3.0});
  }
  return points;
}

std::vector<int> pressure_triangles(const TetMesh& mesh, const std::string& group) {
  return mesh.require_group(group, 2, "pressure load").elements;
}

std::vector<Vec3> traction_nodal_loads(const TetMesh& mesh, const TractionPatch& patch) {
  std::vector<Vec3> f(mesh.nodes.size(), Vec3::Zero());
  for (const SurfacePoint& q : patch.points) {
    const Triangle& t = mesh.triangles[q.triangle];
    for (int k = 0; k < 3; ++k) f[t[k]] += patch.traction * (q.weight * q.barycentric[k]);
  }
  return f;
}

std::vector<Vec3> pressure_nodal_loads(const TetMesh& mesh, const std::string& group, double p) {
  std::vector<Vec3> f(mesh.nodes.size(), Vec3::Zero());
  for (int e : pressure_triangles(mesh, group)) {
    const Triangle& t = mesh.triangles[e];
    const Vec3 load = -p * 0.5 * area_normal(mesh, t) / 3.0;  // −p n A / 3
    for (int n : t) f[n] += load;
  }
  return f;
}

std::vector<Vec3> body_force_nodal_loads(const TetMesh& mesh, const Vec3& force_density) {
  std::vector<Vec3> f(mesh.nodes.size(), Vec3::Zero());
  for (const auto& t : mesh.tets) {
    const double v = std::abs(
        signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]));
    for (int n : t) f[n] += force_density * v / 4.0;
  }
  return f;
}

Vec3 total_load(const std::vector<Vec3>& loads) {
  Vec3 s = Vec3::Zero();
  for (const auto& f : loads) s += f;
  return s;
}

}  // namespace vessel
