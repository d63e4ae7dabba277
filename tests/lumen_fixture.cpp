#include "lumen_fixture.hpp"

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

namespace vessel::test {

namespace {

/// The point of the torus segment's centreline circle (radius R about z, in z = 0) nearest p.
Vec3 on_centreline(double R, const Vec3& p) {
  const Vec3 planar(p.x(), p.y(), 0.0);
  return planar.norm() > 0.0 ? Vec3(R * planar.normalized()) : Vec3(R, 0.0, 0.0);
}

/// The 3-node triangles of gmsh surface `tag`, their nodes added to `s` once each (`index` maps
/// gmsh's node tags to `s`'s indices across faces).
std::vector<Triangle> face_triangles(int tag, std::map<std::size_t, int>& index, TriangleSurface& s) {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> elements, nodes;
  gmsh::model::mesh::getElements(types, elements, nodes, 2, tag);
  std::vector<Triangle> face;
  for (std::size_t k = 0; k < types.size(); ++k) {
    if (types[k] != 2) continue;  // 3-node triangles
    for (std::size_t e = 0; e + 2 < nodes[k].size(); e += 3) {
      Triangle t{};
      for (int c = 0; c < 3; ++c) {
        const std::size_t node = nodes[k][e + c];
        auto [it, inserted] = index.emplace(node, static_cast<int>(s.nodes.size()));
        if (inserted) {
          std::vector<double> x, param;
          gmsh::model::mesh::getNode(node, x, param);
          s.nodes.emplace_back(x[0], x[1], x[2]);
          s.source_node.push_back(-1);
        }
        t[c] = it->second;
      }
      face.push_back(t);
    }
  }
  return face;
}

}  // namespace

TriangleSurface bifurcation_lumen(const BifurcationSpec& b) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.NumThreads", 1);
  gmsh::model::add("bifurcation");
  namespace occ = gmsh::model::occ;
  const int torus = occ::addTorus(0, 0, 0, b.bend_radius, b.radius, -1, b.angle);
  const double phi = 0.5 * b.angle;
  const Vec3 dir(std::cos(phi), std::sin(phi), 0.0);
  const Vec3 start = b.bend_radius * dir;  // on the centreline: the cylinder's cap lies inside
  const Vec3 axis = (b.radius + b.branch_length) * dir;
  const int branch = occ::addCylinder(start.x(), start.y(), start.z(), axis.x(), axis.y(),
                                      axis.z(), b.branch_radius);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> out_map;
  occ::fuse({{3, torus}}, {{3, branch}}, out, out_map);
  occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", b.mesh_size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * b.mesh_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::model::mesh::generate(2);

  TriangleSurface s;
  std::map<std::size_t, int> index;
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  for (const auto& [dim, tag] : faces) {
    std::string type;
    gmsh::model::getType(dim, tag, type);
    if (type == "Plane") continue;  // the three caps: the ends stay open
    const std::vector<Triangle> face = face_triangles(tag, index, s);
    // A face lies on the torus or on the branch's cylinder: whichever its triangles are nearer.
    double to_torus = 0.0, to_branch = 0.0;
    for (const Triangle& t : face) {
      const Vec3 c = (s.nodes[t[0]] + s.nodes[t[1]] + s.nodes[t[2]]) / 3.0;
      to_torus += std::abs((c - on_centreline(b.bend_radius, c)).norm() - b.radius);
      to_branch += std::abs((c - (start + (c - start).dot(dir) * dir)).norm() - b.branch_radius);
    }
    const bool on_branch = to_branch < to_torus;
    for (Triangle t : face) {
      // Outward: away from the axis of the part the triangle lies on.
      const Vec3 c = (s.nodes[t[0]] + s.nodes[t[1]] + s.nodes[t[2]]) / 3.0;
      const Vec3 outward = on_branch ? Vec3(c - (start + (c - start).dot(dir) * dir))
                                     : Vec3(c - on_centreline(b.bend_radius, c));
      const Vec3 n = (s.nodes[t[1]] - s.nodes[t[0]]).cross(s.nodes[t[2]] - s.nodes[t[0]]);
      if (n.dot(outward) < 0.0) std::swap(t[1], t[2]);
      s.triangles.push_back(t);
    }
  }
  gmsh::finalize();
  return s;
}

TriangleSurface y_bifurcation_lumen(const YBifurcationSpec& y) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.NumThreads", 1);
  gmsh::model::add("y_bifurcation");
  namespace occ = gmsh::model::occ;
  const double L = y.length;
  const Vec3 left(-std::sin(y.half_angle), 0.0, std::cos(y.half_angle));
  const Vec3 right(std::sin(y.half_angle), 0.0, std::cos(y.half_angle));
  const int parent = occ::addCylinder(0, 0, -L, 0, 0, L, y.parent_radius);
  const int ball = occ::addSphere(0, 0, 0, y.junction_radius);
  const int d1 = occ::addCylinder(0, 0, 0, L * left.x(), 0, L * left.z(), y.daughter_radius);
  const int d2 = occ::addCylinder(0, 0, 0, L * right.x(), 0, L * right.z(), y.daughter_radius);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> out_map;
  occ::fuse({{3, parent}}, {{3, ball}, {3, d1}, {3, d2}}, out, out_map);
  if (y.holes) {
    const double cut =
        std::sqrt(y.junction_radius * y.junction_radius - y.hole_radius * y.hole_radius);
    const double w = 2.0 * y.hole_radius, depth = y.junction_radius;
    const int above = occ::addBox(-w, cut, -w, 2 * w, depth, 2 * w);
    const int below = occ::addBox(-w, -cut - depth, -w, 2 * w, depth, 2 * w);
    gmsh::vectorpair cut_out;
    occ::cut(out, {{3, above}, {3, below}}, cut_out, out_map);
    out = cut_out;
  }
  occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", y.mesh_size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.5 * y.mesh_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::model::mesh::generate(2);

  // Each part: the distance of a point from its surface, and its outward direction there.
  const auto from_axis = [](const Vec3& p, const Vec3& dir) { return Vec3(p - p.dot(dir) * dir); };
  const std::array<Vec3, 3> axes{Vec3(0, 0, 1), left, right};
  const std::array<double, 3> radii{y.parent_radius, y.daughter_radius, y.daughter_radius};
  const auto residual = [&](int part, const Vec3& p) {
    if (part == 3) return std::abs(p.norm() - y.junction_radius);
    return std::abs(from_axis(p, axes[part]).norm() - radii[part]);
  };
  const auto outward = [&](int part, const Vec3& p) {
    return part == 3 ? p : from_axis(p, axes[part]);
  };

  TriangleSurface s;
  std::map<std::size_t, int> index;
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  for (const auto& [dim, tag] : faces) {
    std::string type;
    gmsh::model::getType(dim, tag, type);
    if (type == "Plane") continue;  // the end caps and the holes' discs: left open
    const std::vector<Triangle> face = face_triangles(tag, index, s);
    std::array<double, 4> sum{};
    for (const Triangle& t : face) {
      const Vec3 c = (s.nodes[t[0]] + s.nodes[t[1]] + s.nodes[t[2]]) / 3.0;
      for (int part = 0; part < 4; ++part) sum[part] += residual(part, c);
    }
    const int part = static_cast<int>(std::min_element(sum.begin(), sum.end()) - sum.begin());
    for (Triangle t : face) {
      const Vec3 c = (s.nodes[t[0]] + s.nodes[t[1]] + s.nodes[t[2]]) / 3.0;
      const Vec3 n = (s.nodes[t[1]] - s.nodes[t[0]]).cross(s.nodes[t[2]] - s.nodes[t[0]]);
      if (n.dot(outward(part, c)) < 0.0) std::swap(t[1], t[2]);
      s.triangles.push_back(t);
    }
  }
  gmsh::finalize();
  return s;
}

void write_bifurcation_stl(const std::filesystem::path& path, const BifurcationSpec& spec) {
  write_stl(path, bifurcation_lumen(spec), StlFormat::binary);
}

TriangleSurface polygon_tube(double radius, double length, int sides, int rings) {
  TriangleSurface s;
  for (int j = 0; j <= rings; ++j) {
    for (int i = 0; i < sides; ++i) {
      const double th = 2.0 * std::numbers::pi * i / sides;
      s.nodes.emplace_back(radius * std::cos(th), radius * std::sin(th), length * j / rings);
      s.source_node.push_back(-1);
    }
  }
  const auto id = [sides](int i, int j) { return j * sides + (i % sides); };
  for (int j = 0; j < rings; ++j) {
    for (int i = 0; i < sides; ++i) {
      // Counter-clockwise seen from outside: (i, j), (i+1, j), (i+1, j+1) has normal +radial.
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return s;
}

}  // namespace vessel::test
