#include "meshes/tet_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <unordered_map>

#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

/// The four faces of a tet, each listed so that its normal points away from the opposite vertex
/// when the tet is positively oriented.
constexpr std::array<std::array<int, 3>, 4> kTetFaces{{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

std::array<int, 3> sorted(Triangle t) {
  std::sort(t.begin(), t.end());
  return t;
}

struct TriangleKeyHash {
  std::size_t operator()(const std::array<int, 3>& k) const {
    std::size_t h = static_cast<std::size_t>(k[0]);
    h = h * 1000003u ^ static_cast<std::size_t>(k[1]);
    h = h * 1000003u ^ static_cast<std::size_t>(k[2]);
    return h;
  }
};

}  // namespace

const PhysicalGroup* TetMesh::find_group(std::string_view name, int dim) const {
  for (const auto& g : groups) {
    if (g.name == name && g.dim == dim) return &g;
  }
  return nullptr;
}

const PhysicalGroup& TetMesh::require_group(std::string_view name, int dim,
                                            std::string_view source) const {
  if (const auto* g = find_group(name, dim)) {
    if (g->elements.empty()) {
      throw InputError(std::string(source) + ": physical group '" + std::string(name) +
                       "' is empty; expected at least one " +
                       (dim == 3 ? "tetrahedron" : "triangle"));
    }
    return *g;
  }
  std::string present;
  for (const auto& g : groups) {
    present += (present.empty() ? "" : ", ") + g.name + " (dim " + std::to_string(g.dim) + ")";
  }
  throw InputError(std::string(source) + ": missing physical group '" + std::string(name) +
                   "' of dimension " + std::to_string(dim) + "; the mesh has " +
                   (present.empty() ? std::string("no physical groups") : present) +
                   ". A vessel mesh needs inlet, outlet, inner_wall, outer_wall (surfaces) and "
                   "wall (volume)");
}

void require_vessel_groups(const TetMesh& mesh, std::string_view source) {
  for (const auto& spec : kVesselGroups) (void)mesh.require_group(spec.name, spec.dim, source);
}

std::vector<int> TetMesh::group_nodes(const PhysicalGroup& group) const {
  std::vector<int> out;
  for (int e : group.elements) {
    if (group.dim == 3) {
      out.insert(out.end(), tets[e].begin(), tets[e].end());
    } else {
      out.insert(out.end(), triangles[e].begin(), triangles[e].end());
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<Triangle> TetMesh::group_triangles(const PhysicalGroup& group) const {
  if (group.dim != 2) {
    throw std::invalid_argument("group_triangles: group '" + group.name + "' has dimension " +
                                std::to_string(group.dim) + ", expected 2");
  }
  std::vector<Triangle> out;
  out.reserve(group.elements.size());
  for (int e : group.elements) out.push_back(triangles[e]);
  return out;
}

double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

std::size_t inverted_tets(const TetMesh& mesh, const std::vector<Vec3>& x) {
  std::size_t n = 0;
  for (const Tet& t : mesh.tets) {
    if (!(signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) > 0)) ++n;
  }
  return n;
}

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

namespace {
Vec3 closest_point_on_segment(const Vec3& a, const Vec3& b, const Vec3& x) {
  const Vec3 d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((x - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return a + t * d;
}
}  // namespace

Vec3 closest_point_on_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& x) {
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0.0) {
    const Vec3 p = x - (x - a).dot(n) / n2 * n;
    // Inside when p is on the inner side of all three edges.
    if ((b - a).cross(p - a).dot(n) >= 0.0 && (c - b).cross(p - b).dot(n) >= 0.0 &&
        (a - c).cross(p - c).dot(n) >= 0.0)
      return p;
  }
  Vec3 best = closest_point_on_segment(a, b, x);
  for (const Vec3& q : {closest_point_on_segment(b, c, x), closest_point_on_segment(c, a, x)})
    if ((q - x).squaredNorm() < (best - x).squaredNorm()) best = q;
  return best;
}

std::vector<std::array<int, 2>> unique_edges(const TetMesh& mesh) {
  std::vector<std::array<int, 2>> edges;
  edges.reserve(6 * mesh.tets.size());
  for (const Tet& t : mesh.tets) {
    for (std::size_t i = 0; i < 4; ++i) {
      for (std::size_t j = i + 1; j < 4; ++j)
        edges.push_back({std::min(t[i], t[j]), std::max(t[i], t[j])});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

double mesh_volume(const TetMesh& mesh) {
  double v = 0.0;
  for (const auto& t : mesh.tets) {
    v += signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
  }
  return v;
}

double group_area(const TetMesh& mesh, const PhysicalGroup& group) {
  double a = 0.0;
  for (const auto& t : mesh.group_triangles(group)) {
    a += triangle_area(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]);
  }
  return a;
}

namespace {
/// Maps each sorted face to (count, the outward-oriented face of the last tet that had it).
std::unordered_map<std::array<int, 3>, std::pair<int, Triangle>, TriangleKeyHash> face_map(
    const TetMesh& mesh) {
  std::unordered_map<std::array<int, 3>, std::pair<int, Triangle>, TriangleKeyHash> faces;
  faces.reserve(mesh.tets.size() * 3);
  for (const auto& t : mesh.tets) {
    const bool positive =
        signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]) >= 0;
    for (const auto& f : kTetFaces) {
      Triangle tri{t[f[0]], t[f[1]], t[f[2]]};
      if (!positive) std::swap(tri[1], tri[2]);
      auto& entry = faces[sorted(tri)];
      ++entry.first;
      entry.second = tri;
    }
  }
  return faces;
}
}  // namespace

std::vector<Triangle> boundary_faces(const TetMesh& mesh) {
  std::vector<Triangle> out;
  for (const auto& [key, entry] : face_map(mesh)) {
    if (entry.first == 1) out.push_back(entry.second);
  }
  return out;
}

bool orient_tets(TetMesh& mesh) {
  std::size_t negative = 0;
  std::size_t positive = 0;
  for (const Tet& t : mesh.tets) {
    const double v =
        signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
    if (v < 0) ++negative;
    if (v > 0) ++positive;
  }
  if (negative <= positive) return false;
  for (auto& t : mesh.tets) std::swap(t[2], t[3]);
  return true;
}

namespace {

std::string sci(double x, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}

/// One tet's volume test: signed volume V, longest edge ℓ, and whether it is inverted or flat.
struct VolumeCheck {
  double volume = 0;
  double longest_edge = 0;
  bool zero = false;
  bool inverted = false;
};

VolumeCheck check_volume(const TetMesh& mesh, const Tet& t) {
  VolumeCheck c;
  c.volume = signed_volume(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]);
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      c.longest_edge = std::max(c.longest_edge, (mesh.nodes[t[i]] - mesh.nodes[t[j]]).norm());
    }
  }
  const double l3 = c.longest_edge * c.longest_edge * c.longest_edge;
  c.zero = !(std::abs(c.volume) > kZeroVolumeTolerance * l3);  // NaN counts as zero
  c.inverted = !c.zero && c.volume < 0;
  return c;
}

}  // namespace

void require_positive_volumes(const TetMesh& mesh, std::string_view source,
                              const std::vector<ElementOrigin>& origins, bool file_flipped) {
  const bool have_origins = origins.size() == mesh.tets.size();
  std::vector<std::size_t> bad;
  double total = 0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const VolumeCheck c = check_volume(mesh, mesh.tets[e]);
    total += std::abs(c.volume);
    if (c.zero || c.inverted) bad.push_back(e);
  }
  if (bad.empty()) return;
  const double mean = total / static_cast<double>(mesh.tets.size());
  const double sign = file_flipped ? -1.0 : 1.0;  // volumes as the file's node order gives them
  const std::string expected = file_flipped ? "negative" : "positive";
  auto where = [&](std::size_t e) {
    std::string s;
    if (have_origins) {
      s = std::string(source) + ":" + std::to_string(origins[e].line) + ": element " +
          std::to_string(origins[e].tag);
    } else {
      s = std::string(source) + ": tetrahedron " + std::to_string(e) + " (0-based, of " +
          std::to_string(mesh.tets.size()) + ")";
    }
    return s;
  };
  auto node_name = [&](std::size_t e, int k) {
    return have_origins ? "node " + std::to_string(origins[e].node_tags[k])
                        : "node " + std::to_string(mesh.tets[e][k]);
  };

  const std::size_t e = bad.front();
  const Tet& t = mesh.tets[e];
  const VolumeCheck c = check_volume(mesh, t);
  std::ostringstream msg;
  msg << where(e);
  if (have_origins) msg << " (tetrahedron " << e + 1 << " of " << mesh.tets.size() << ")";
  msg << " ";
  if (c.zero) {
    std::string why;
    for (int i = 0; i < 4 && why.empty(); ++i) {
      for (int j = i + 1; j < 4 && why.empty(); ++j) {
        const Vec3& p = mesh.nodes[t[i]];
        if (t[i] == t[j]) {
          why = "it lists its " + node_name(e, i) + " twice";
        } else if ((p - mesh.nodes[t[j]]).norm() <= 1e-9 * c.longest_edge) {
          why = "its " + node_name(e, i) + " and " + node_name(e, j) + " coincide at (" +
                sci(p.x(), 6) + ", " + sci(p.y(), 6) + ", " + sci(p.z(), 6) + ") m";
        }
      }
    }
    if (why.empty()) why = "its four nodes are (nearly) coplanar: a flat tet";
    msg << "has zero volume: signed volume " << sci(sign * c.volume) << " m³, |V| ≤ "
        << sci(kZeroVolumeTolerance, 1) << " ℓ³ with ℓ = " << sci(c.longest_edge)
        << " m its longest edge; " << why << "; expected a " << expected << " volume";
  } else {
    msg << "is inverted: signed volume " << sci(sign * c.volume) << " m³ ("
        << sci(sign * c.volume / mean, 3) << " × the mean tet volume); expected a " << expected
        << " volume like the mesh's other tets (its node order is reversed, or a node is on the "
           "wrong side of its opposite face)";
  }
  msg << ". " << bad.size() << " of " << mesh.tets.size()
      << " tets are inverted or have zero volume";
  if (bad.size() > 1) {
    msg << "; the next: ";
    const std::size_t shown = std::min<std::size_t>(bad.size(), 6);
    for (std::size_t i = 1; i < shown; ++i) {
      const std::size_t b = bad[i];
      msg << (i > 1 ? ", " : "");
      if (have_origins) {
        msg << "element " << origins[b].tag << " (line " << origins[b].line << ")";
      } else {
        msg << "tetrahedron " << b;
      }
      msg << " V = " << sci(sign * check_volume(mesh, mesh.tets[b]).volume) << " m³";
    }
    if (bad.size() > shown) msg << ", ...";
  }
  msg << ". Fix the mesh (re-mesh, or merge coincident nodes) and try again.";
  throw InputError(msg.str());
}

void orient_boundary_outward(TetMesh& mesh) {
  const auto faces = face_map(mesh);
  for (auto& tri : mesh.triangles) {
    const auto it = faces.find(sorted(tri));
    if (it != faces.end() && it->second.first == 1) tri = it->second.second;
  }
}

namespace {
/// The element's nodes in ascending order up to an even permutation (so orientation is kept):
/// sorted, with the last two swapped if sorting took an odd number of transpositions.
template <std::size_t N>
std::array<int, N> canonical_nodes(std::array<int, N> e) {
  bool odd = false;
  for (std::size_t i = 0; i < N; ++i) {  // selection sort, counting swaps
    std::size_t m = i;
    for (std::size_t j = i + 1; j < N; ++j) {
      if (e[j] < e[m]) m = j;
    }
    if (m != i) {
      std::swap(e[i], e[m]);
      odd = !odd;
    }
  }
  if (odd) std::swap(e[N - 2], e[N - 1]);
  return e;
}

/// Puts each element in canonical node order and reorders `elements` by sorted node indices;
/// returns new_index[old] for the remap.
template <std::size_t N>
std::vector<int> sort_by_sorted_nodes(std::vector<std::array<int, N>>& elements) {
  std::vector<std::pair<std::array<int, N>, int>> keyed;
  keyed.reserve(elements.size());
  for (std::size_t i = 0; i < elements.size(); ++i) {
    elements[i] = canonical_nodes(elements[i]);
    auto key = elements[i];
    std::sort(key.begin(), key.end());
    keyed.emplace_back(key, static_cast<int>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::array<int, N>> sorted_elements;
  sorted_elements.reserve(elements.size());
  std::vector<int> new_index(elements.size());
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    new_index[keyed[i].second] = static_cast<int>(i);
    sorted_elements.push_back(elements[keyed[i].second]);
  }
  elements = std::move(sorted_elements);
  return new_index;
}
}  // namespace

void sort_elements(TetMesh& mesh) {
  const auto tet_index = sort_by_sorted_nodes(mesh.tets);
  const auto tri_index = sort_by_sorted_nodes(mesh.triangles);
  for (auto& g : mesh.groups) {
    for (int& e : g.elements) e = (g.dim == 3 ? tet_index : tri_index)[e];
    std::sort(g.elements.begin(), g.elements.end());
  }
}

void remove_unused_nodes(TetMesh& mesh) {
  std::vector<int> new_index(mesh.nodes.size(), -1);
  for (const auto& t : mesh.tets) {
    for (int n : t) new_index[n] = 0;
  }
  for (const auto& t : mesh.triangles) {
    for (int n : t) new_index[n] = 0;
  }
  std::vector<Vec3> nodes;
  nodes.reserve(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (new_index[i] == 0) {
      new_index[i] = static_cast<int>(nodes.size());
      nodes.push_back(mesh.nodes[i]);
    }
  }
  for (auto& t : mesh.tets) {
    for (int& n : t) n = new_index[n];
  }
  for (auto& t : mesh.triangles) {
    for (int& n : t) n = new_index[n];
  }
  mesh.nodes = std::move(nodes);
}

SurfaceTopology surface_topology(const std::vector<Triangle>& triangles) {
  // For each undirected edge: how many triangles use it, and how many traverse it low→high.
  std::map<std::pair<int, int>, std::pair<int, int>> edges;
  for (const auto& t : triangles) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[i];
      const int b = t[(i + 1) % 3];
      auto& e = edges[{std::min(a, b), std::max(a, b)}];
      ++e.first;
      if (a < b) ++e.second;
    }
  }
  SurfaceTopology topo;
  for (const auto& [edge, use] : edges) {
    if (use.first == 1) {
      ++topo.boundary_edges;
    } else if (use.first > 2) {
      ++topo.non_manifold_edges;
    } else if (use.second != 1) {
      ++topo.inconsistent_edges;
    }
  }
  return topo;
}

double enclosed_volume(const std::vector<Vec3>& nodes, const std::vector<Triangle>& triangles) {
  // Divergence theorem: V = Σ (a · (b × c)) / 6 over outward triangles.
  double v = 0.0;
  for (const auto& t : triangles) {
    v += nodes[t[0]].dot(nodes[t[1]].cross(nodes[t[2]])) / 6.0;
  }
  return v;
}

Vec3 nearest_point_on_group(const TetMesh& mesh, std::string_view group, const Vec3& x,
                            std::string_view source) {
  const PhysicalGroup& g = mesh.require_group(group, 2, source);
  if (g.elements.empty()) {
    throw InputError(std::string(source) + ": group '" + std::string(group) + "' has no triangles");
  }
  Vec3 best = Vec3::Zero();
  double d = std::numeric_limits<double>::infinity();
  for (const int e : g.elements) {
    const Triangle& t = mesh.triangles[e];
    const Vec3 p = closest_point_on_triangle(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], x);
    if ((p - x).squaredNorm() < d) {
      d = (p - x).squaredNorm();
      best = p;
    }
  }
  return best;
}

double estimate_wall_thickness(const TetMesh& mesh, std::string_view source) {
  const std::vector<int> outer =
      mesh.group_nodes(mesh.require_group(group_names::outer_wall, 2, source));
  if (outer.empty()) throw InputError(std::string(source) + ": group 'outer_wall' has no nodes");
  const std::size_t stride = std::max<std::size_t>(1, outer.size() / 400);
  std::vector<double> d;
  for (std::size_t i = 0; i < outer.size(); i += stride) {
    const Vec3& x = mesh.nodes[outer[i]];
    d.push_back((nearest_point_on_group(mesh, group_names::inner_wall, x, source) - x).norm());
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

}  // namespace vessel
