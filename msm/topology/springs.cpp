#include "msm/topology/springs.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

std::string to_string(SpringFamily family) {
  switch (family) {
    case SpringFamily::structural:
      return "structural";
    case SpringFamily::shear:
      return "shear";
    case SpringFamily::bend:
      return "bend";
    case SpringFamily::two_ring:
      return "two_ring";
    case SpringFamily::volume:
      return "volume";
  }
  return "unknown";
}

std::size_t SpringNetwork::count(SpringFamily family) const {
  return static_cast<std::size_t>(std::count_if(
      springs.begin(), springs.end(), [&](const Spring& s) { return s.family == family; }));
}

namespace {

using Edge = std::pair<int, int>;
Edge make_edge(int a, int b) { return a < b ? Edge{a, b} : Edge{b, a}; }

Spring make_spring(const std::vector<Vec3>& nodes, int a, int b, SpringFamily family) {
  Spring s;
  s.a = a;
  s.b = b;
  s.rest_length = (nodes[a] - nodes[b]).norm();
  s.family = family;
  return s;
}

}  // namespace

SpringNetwork build_volume_network(const TetMesh& mesh) {
  SpringNetwork net;
  net.nodes = mesh.nodes;
  net.source_node.resize(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) net.source_node[i] = static_cast<int>(i);
  net.tets = mesh.tets;
  // seed 001 §1 (Mollemans): "each vertex corresponds to each particle and each edge
  // corresponds to each spring".
  const std::vector<std::array<int, 2>> edges = unique_edges(mesh);
  net.springs.reserve(edges.size());
  for (const auto& [a, b] : edges) {
    net.springs.push_back(make_spring(net.nodes, a, b, SpringFamily::volume));
  }
  return net;
}

namespace {
/// A surface network's nodes, source nodes, triangles and thickness, without springs yet.
SpringNetwork surface_network(const TriangleSurface& surface, double thickness) {
  SpringNetwork net;
  net.nodes = surface.nodes;
  net.source_node = surface.source_node;
  if (net.source_node.size() != net.nodes.size()) net.source_node.assign(net.nodes.size(), -1);
  net.triangles = surface.triangles;
  net.thickness = thickness;
  return net;
}
}  // namespace

SpringNetwork build_triangle_network(const TriangleSurface& surface, double thickness,
                                     bool two_ring) {
  SpringNetwork net = surface_network(surface, thickness);
  // Edge → opposite vertices of the triangles sharing it.
  std::map<Edge, std::vector<int>> opposite;
  for (const Triangle& t : surface.triangles) {
    for (int k = 0; k < 3; ++k) {
      opposite[make_edge(t[k], t[(k + 1) % 3])].push_back(t[(k + 2) % 3]);
    }
  }
  std::set<Edge> connected;
  for (const auto& [e, opp] : opposite) {
    net.springs.push_back(make_spring(net.nodes, e.first, e.second, SpringFamily::structural));
    connected.insert(e);
  }
  for (const auto& [e, opp] : opposite) {
    if (opp.size() != 2) continue;  // boundary (or non-manifold) edge: no bend spring
    const Edge b = make_edge(opp[0], opp[1]);
    if (b.first == b.second || !connected.insert(b).second) continue;
    net.springs.push_back(make_spring(net.nodes, b.first, b.second, SpringFamily::bend));
  }
  if (two_ring) {
    std::vector<std::vector<int>> adjacency(net.nodes.size());
    for (const auto& [e, opp] : opposite) {
      adjacency[e.first].push_back(e.second);
      adjacency[e.second].push_back(e.first);
    }
    for (std::size_t i = 0; i < adjacency.size(); ++i) {
      for (int j : adjacency[i]) {
        for (int k : adjacency[j]) {
          if (k <= static_cast<int>(i)) continue;
          if (connected.insert(make_edge(static_cast<int>(i), k)).second) {
            net.springs.push_back(
                make_spring(net.nodes, static_cast<int>(i), k, SpringFamily::two_ring));
          }
        }
      }
    }
  }
  return net;
}

TubeCoordinates tube_coordinates(const VesselParams& params, const Vec3& p) {
  TubeCoordinates c;
  if (params.kind == VesselKind::straight) {
    // The section lies in z = 0 around the z axis and is extruded along z.
    c.axial = p.z();
    c.centre = Vec3(0.0, 0.0, p.z());
    c.theta = std::atan2(p.y(), p.x());
  } else {
    // The section lies in y = 0 around (R, 0, 0) and is revolved about the z axis.
    const double alpha = std::atan2(p.y(), p.x());
    const Vec3 er(std::cos(alpha), std::sin(alpha), 0.0);
    c.axial = params.bend_radius * alpha;
    c.centre = params.bend_radius * er;
    c.theta = std::atan2(p.z(), p.dot(er) - params.bend_radius);
  }
  const Vec3 r = p - c.centre;
  c.rho = r.norm();
  c.radial = c.rho > 0 ? Vec3(r / c.rho) : Vec3::Zero();
  return c;
}

std::vector<GridIndex> recover_tube_grid(const std::vector<Vec3>& nodes, const VesselParams& params,
                                         int n_circ, int n_axial) {
  if (nodes.empty() || n_circ < 3 || n_axial < 1) {
    throw InputError("structured tube grid: need nodes, n_circ ≥ 3 and n_axial ≥ 1");
  }
  const double dtheta = 2.0 * std::numbers::pi / n_circ;
  const double ds = params.centreline_length() / n_axial;
  const double theta0 = tube_coordinates(params, nodes[0]).theta;
  std::vector<GridIndex> grid(nodes.size());
  std::vector<int> seen(static_cast<std::size_t>(n_circ) * (n_axial + 1), 0);
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const TubeCoordinates c = tube_coordinates(params, nodes[n]);
    const double fi = (c.theta - theta0) / dtheta;  // may be negative: wrapped below
    const double fj = c.axial / ds;
    const long i = std::lround(fi);
    const long j = std::lround(fj);
    if (std::abs(fi - static_cast<double>(i)) > 0.25 ||
        std::abs(fj - static_cast<double>(j)) > 0.25 || j < 0 || j > n_axial) {
      throw InputError("structured tube grid: node " + std::to_string(n) +
                       " is not on the expected " + std::to_string(n_circ) + " × " +
                       std::to_string(n_axial + 1) +
                       " grid (use a --structured mesh, or the triangle-mesh families)");
    }
    GridIndex g{static_cast<int>(((i % n_circ) + n_circ) % n_circ), static_cast<int>(j)};
    grid[n] = g;
    if (seen[static_cast<std::size_t>(g.j) * n_circ + g.i]++) {
      throw InputError("structured tube grid: two nodes at grid position (" + std::to_string(g.i) +
                       ", " + std::to_string(g.j) + ")");
    }
  }
  if (nodes.size() != seen.size()) {
    throw InputError("structured tube grid: " + std::to_string(nodes.size()) + " nodes, expected " +
                     std::to_string(seen.size()));
  }
  return grid;
}

SpringNetwork build_tube_grid_network(const TriangleSurface& surface, const VesselParams& params,
                                      double thickness) {
  const StructuredCounts counts = structured_counts(params);
  const int nc = counts.circumferential;
  const int na = counts.axial;
  const std::vector<GridIndex> grid = recover_tube_grid(surface.nodes, params, nc, na);
  std::vector<int> at(static_cast<std::size_t>(nc) * (na + 1), -1);
  for (std::size_t n = 0; n < grid.size(); ++n) {
    at[static_cast<std::size_t>(grid[n].j) * nc + grid[n].i] = static_cast<int>(n);
  }
  auto node = [&](int i, int j) -> int {
    if (j < 0 || j > na) return -1;
    return at[static_cast<std::size_t>(j) * nc + ((i % nc) + nc) % nc];
  };
  SpringNetwork net = surface_network(surface, thickness);
  auto add = [&](int a, int b, SpringFamily f) {
    if (a >= 0 && b >= 0 && a != b) net.springs.push_back(make_spring(net.nodes, a, b, f));
  };
  // seed 000 §II.B: (a) structural springs between horizontal and vertical neighbours,
  // (b) twisted (shear) springs between diagonal neighbours, (c) stretch (bend) springs between
  // two particles separated by one particle, in both directions.
  for (int j = 0; j <= na; ++j) {
    for (int i = 0; i < nc; ++i) {
      add(node(i, j), node(i + 1, j), SpringFamily::structural);
      add(node(i, j), node(i, j + 1), SpringFamily::structural);
      add(node(i, j), node(i + 1, j + 1), SpringFamily::shear);
      add(node(i + 1, j), node(i, j + 1), SpringFamily::shear);
      add(node(i, j), node(i + 2, j), SpringFamily::bend);
      add(node(i, j), node(i, j + 2), SpringFamily::bend);
    }
  }
  return net;
}

WallSurface parse_wall_surface(const std::string& name) {
  if (name == "inner") return WallSurface::inner;
  if (name == "outer") return WallSurface::outer;
  if (name == "mid") return WallSurface::mid;
  throw InputError("surface: expected 'inner', 'outer' or 'mid', got '" + name + "'");
}

std::string to_string(WallSurface surface) {
  switch (surface) {
    case WallSurface::inner: return "inner";
    case WallSurface::outer: return "outer";
    case WallSurface::mid: return "mid";
  }
  return "?";
}

TriangleSurface wall_surface(const TetMesh& mesh, const VesselParams& params, WallSurface which) {
  const std::string group(which == WallSurface::outer ? group_names::outer_wall
                                                      : group_names::inner_wall);
  TriangleSurface s = extract_surface(mesh, {group}, "mesh");
  if (which == WallSurface::mid) {
    const double mid = params.inner_radius + 0.5 * params.wall_thickness;
    for (Vec3& x : s.nodes) {
      const TubeCoordinates c = tube_coordinates(params, x);
      x = c.centre + mid * c.radial;
    }
  }
  return s;
}

}  // namespace vessel::msm
