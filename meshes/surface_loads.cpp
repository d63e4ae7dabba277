#include "meshes/surface_loads.hpp"

#include <cmath>
#include <sstream>

#include "meshes/errors.hpp"

namespace vessel {

namespace {

/// Area-weighted normal (|n| = 2A) of a triangle, outward when the triangle is oriented outward.
Vec3 area_normal(const TetMesh& mesh, const Triangle& t) {
  return (mesh.nodes[t[1]] - mesh.nodes[t[0]]).cross(mesh.nodes[t[2]] - mesh.nodes[t[0]]);
}

}  // namespace

TractionPatch contact_patch(const TetMesh& mesh, const ContactPatchSpec& spec) {
  if (!std::isfinite(spec.radius) || spec.radius <= 0.0) {
    std::ostringstream m;
    m << "contact patch radius = " << spec.radius << " m is invalid: expected a finite value > 0";
    throw InputError(m.str());
  }
  if (!std::isfinite(spec.force) || !spec.point.allFinite()) {
    throw InputError("contact force and point must be finite numbers");
  }
  const auto& group = mesh.require_group(spec.surface_group, 2, "contact patch");
  TractionPatch patch;
  Vec3 normal_sum = Vec3::Zero();
  for (int e : group.elements) {
    const Triangle& t = mesh.triangles[e];
    const Vec3 centroid = (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]]) / 3.0;
    if ((centroid - spec.point).norm() > spec.radius) continue;
    patch.triangles.push_back(e);
    const Vec3 n2a = area_normal(mesh, t);
    patch.area += 0.5 * n2a.norm();
    normal_sum += n2a;
    for (const SurfacePoint& q : whole_triangle_points(e, 0.5 * n2a.norm()))
      patch.points.push_back(q);
  }
  if (patch.triangles.empty()) {
    std::ostringstream m;
    m << "contact point (" << spec.point.x() * 1e3 << ", " << spec.point.y() * 1e3 << ", "
      << spec.point.z() * 1e3 << ") mm is off the wall: no triangle of '" << spec.surface_group
      << "' has its centroid within the patch radius " << spec.radius * 1e3
      << " mm; expected a point on that surface (or a larger radius than the local element size)";
    throw InputError(m.str());
  }
  patch.outward_normal = normal_sum.normalized();
  patch.traction = -spec.force / patch.area * patch.outward_normal;
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
