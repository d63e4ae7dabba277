#include "meshes/supports.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "meshes/foundation/errors.hpp"

namespace vessel {

std::string to_string(EndCondition condition) {
  switch (condition) {
    case EndCondition::clamped: return "clamped";
    case EndCondition::roller: return "roller";
    case EndCondition::free: return "free";
  }
  return "?";
}

EndCondition parse_end_condition(const std::string& name) {
  for (const auto c : {EndCondition::clamped, EndCondition::roller, EndCondition::free}) {
    if (name == to_string(c)) return c;
  }
  throw InputError("end condition: expected one of clamped, roller, free; got '" + name + "'");
}

std::vector<Pin> tube_in_plane_pins(double a, double z) {
  return {{Vec3(a, 0.0, z), 1}, {Vec3(-a, 0.0, z), 1}, {Vec3(0.0, a, z), 0}};
}

Supports end_supports(const VesselParams& vessel, const std::map<std::string, EndCondition>& ends,
                      const std::string& where) {
  Supports s;
  for (const auto& [group, condition] : ends) {
    if (condition == EndCondition::clamped) s.clamped.push_back(group);
    if (condition == EndCondition::roller) s.rollers.push_back(group);
  }
  const std::string prefix = where.empty() ? "" : where + ": ";
  if (!s.rollers.empty() && vessel.kind != VesselKind::straight) {
    throw InputError(prefix +
                     "roller ends (u_z = 0 on the end faces) need the straight tube; the " +
                     std::string(vessel.parametric() ? "arch's ends are" : "file vessel's ends may be") +
                     " not normal to z: clamp them");
  }
  if (s.clamped.empty() && !s.rollers.empty()) {
    s.pins = tube_in_plane_pins(vessel.inner_radius, 0.0);
  }
  return s;
}

namespace {

/// Nodes (indices into `nodes`) whose mesh node lies in one of the groups.
std::vector<char> in_groups(const TetMesh& mesh, const std::vector<int>& source_node,
                            const std::vector<std::string>& groups) {
  std::set<int> mesh_nodes;
  for (const auto& name : groups) {
    for (int v : mesh.group_nodes(mesh.require_group(name, 2, "support"))) mesh_nodes.insert(v);
  }
  std::vector<char> member(source_node.size(), 0);
  for (std::size_t i = 0; i < source_node.size(); ++i) {
    member[i] = source_node[i] >= 0 && mesh_nodes.count(source_node[i]) ? 1 : 0;
  }
  return member;
}

}  // namespace

namespace {

/// Nodes within `tolerance` (m) of one of the groups' triangles.
std::vector<char> on_groups(const TetMesh& mesh, const std::vector<Vec3>& nodes,
                            const std::vector<std::string>& groups, double tolerance) {
  std::vector<char> member(nodes.size(), 0);
  for (const auto& name : groups) {
    const std::vector<Triangle> tris = mesh.group_triangles(mesh.require_group(name, 2, "support"));
    if (tris.empty()) continue;
    Vec3 lo = mesh.nodes[static_cast<std::size_t>(tris[0][0])], hi = lo;
    for (const Triangle& t : tris) {
      for (const int v : t) {
        lo = lo.cwiseMin(mesh.nodes[static_cast<std::size_t>(v)]);
        hi = hi.cwiseMax(mesh.nodes[static_cast<std::size_t>(v)]);
      }
    }
    lo -= Vec3::Constant(tolerance);
    hi += Vec3::Constant(tolerance);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const Vec3& x = nodes[i];
      if (member[i] || (x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
      for (const Triangle& t : tris) {
        const Vec3 c = closest_point_on_triangle(mesh.nodes[static_cast<std::size_t>(t[0])],
                                                 mesh.nodes[static_cast<std::size_t>(t[1])],
                                                 mesh.nodes[static_cast<std::size_t>(t[2])], x);
        if ((c - x).norm() <= tolerance) {
          member[i] = 1;
          break;
        }
      }
    }
  }
  return member;
}

/// Held dofs from group membership: clamped nodes in every component, roller nodes in z, each pin
/// at the roller node nearest its point.
std::vector<char> held_from(const std::vector<Vec3>& nodes, const std::vector<char>& clamped,
                            const std::vector<char>& rollers, const Supports& supports) {
  std::vector<char> held(3 * nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (clamped[i]) held[3 * i] = held[3 * i + 1] = held[3 * i + 2] = 1;
    if (rollers[i]) held[3 * i + Supports::kRollerComponent] = 1;
  }
  for (const Pin& pin : supports.pins) {
    std::size_t best = nodes.size();
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const double d = (nodes[i] - pin.point).squaredNorm();
      if (rollers[i] && d < best_d) best_d = d, best = i;
    }
    if (best == nodes.size()) {
      std::ostringstream m;
      m << "supports: no node on a roller end to pin at (" << pin.point.x() * 1e3 << ", "
        << pin.point.y() * 1e3 << ", " << pin.point.z() * 1e3 << ") mm";
      throw InputError(m.str());
    }
    held[3 * best + static_cast<std::size_t>(pin.component)] = 1;
  }
  return held;
}

}  // namespace

std::vector<char> held_dofs(const TetMesh& mesh, const std::vector<Vec3>& nodes,
                            const std::vector<int>& source_node, const Supports& supports) {
  if (source_node.size() != nodes.size()) {
    throw InputError("supports: one source node per node expected (" +
                     std::to_string(source_node.size()) + " for " + std::to_string(nodes.size()) +
                     " nodes)");
  }
  return held_from(nodes, in_groups(mesh, source_node, supports.clamped),
                   in_groups(mesh, source_node, supports.rollers), supports);
}

std::vector<char> held_dofs_by_position(const TetMesh& mesh, const std::vector<Vec3>& nodes,
                                        const Supports& supports, double tolerance) {
  return held_from(nodes, on_groups(mesh, nodes, supports.clamped, tolerance),
                   on_groups(mesh, nodes, supports.rollers, tolerance), supports);
}

std::vector<std::size_t> nodes_beyond_plane_z(const std::vector<Vec3>& nodes, double z,
                                              bool below) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (below ? nodes[i].z() <= z : nodes[i].z() >= z) out.push_back(i);
  }
  return out;
}

std::vector<std::size_t> open_boundary_nodes(const std::vector<Triangle>& triangles) {
  std::map<std::pair<int, int>, int> edges;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::set<std::size_t> nodes;
  for (const auto& [e, count] : edges) {
    if (count == 1) nodes.insert({static_cast<std::size_t>(e.first), static_cast<std::size_t>(e.second)});
  }
  return {nodes.begin(), nodes.end()};
}

}  // namespace vessel
