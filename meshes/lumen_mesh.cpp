#include "meshes/lumen_mesh.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <unordered_map>

#include "meshes/foundation/errors.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel {

namespace {

/// v rounded to 1e-6, so that round-off prints as 0.
double cleaned(double v) { return std::round(v * 1e6) / 1e6 + 0.0; }

/// "(x, y, z) mm", for messages.
std::string mm(const Vec3& p) {
  std::ostringstream s;
  s.precision(4);
  s << "(" << cleaned(p.x() * 1e3) << ", " << cleaned(p.y() * 1e3) << ", " << cleaned(p.z() * 1e3)
    << ") mm";
  return s.str();
}

std::string num(double v, int precision = 4) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

using Edge = std::pair<int, int>;

struct EdgeUse {
  int triangle = -1;
  bool forward = true;  ///< the triangle traverses it from .first to .second
};

std::map<Edge, std::vector<EdgeUse>> edge_uses(const std::vector<Triangle>& triangles) {
  std::map<Edge, std::vector<EdgeUse>> uses;
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      uses[{std::min(a, b), std::max(a, b)}].push_back({t, a < b});
    }
  }
  return uses;
}

/// (b − a) × (c − a) · (d − a): six times the signed volume of (a, b, c, d).
double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a);
}

/// Whether segment pq passes strictly through the interior of triangle abc. `eps` (m³) treats
/// near-zero orientations as touching, not crossing.
bool segment_crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c,
                     double eps) {
  const double d1 = orient(a, b, c, p), d2 = orient(a, b, c, q);
  if (!((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps))) return false;
  const double s1 = orient(p, q, a, b), s2 = orient(p, q, b, c), s3 = orient(p, q, c, a);
  return (s1 > eps && s2 > eps && s3 > eps) || (s1 < -eps && s2 < -eps && s3 < -eps);
}

bool triangles_cross(const std::vector<Vec3>& x, const Triangle& s, const Triangle& t, double eps) {
  for (int k = 0; k < 3; ++k) {
    if (segment_crosses(x[s[k]], x[s[(k + 1) % 3]], x[t[0]], x[t[1]], x[t[2]], eps)) return true;
    if (segment_crosses(x[t[k]], x[t[(k + 1) % 3]], x[s[0]], x[s[1]], x[s[2]], eps)) return true;
  }
  return false;
}

/// Angle-weighted vertex normals (Thürmer & Wüthrich 1998) of an outward-oriented surface.
std::vector<Vec3> vertex_normals(const std::vector<Vec3>& x, const std::vector<Triangle>& tris) {
  std::vector<Vec3> n(x.size(), Vec3::Zero());
  for (const Triangle& t : tris) {
    const Vec3 face = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).normalized();
    for (int k = 0; k < 3; ++k) {
      const Vec3 e1 = (x[t[(k + 1) % 3]] - x[t[k]]).normalized();
      const Vec3 e2 = (x[t[(k + 2) % 3]] - x[t[k]]).normalized();
      n[t[k]] += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * face;
    }
  }
  for (Vec3& v : n) v.normalize();
  return n;
}

/// Dompierre et al. 1999 (Table 2): the prism's rotations/reflections bringing slot k to slot 0.
constexpr std::array<std::array<int, 6>, 6> kPrismIndirection{{{0, 1, 2, 3, 4, 5},
                                                               {1, 2, 0, 4, 5, 3},
                                                               {2, 0, 1, 5, 3, 4},
                                                               {3, 5, 4, 0, 2, 1},
                                                               {4, 3, 5, 1, 0, 2},
                                                               {5, 4, 3, 2, 1, 0}}};

/// The three tets of a prism (slots 0–2 bottom, 3–5 top, slot k+3 above slot k) as slots, chosen
/// by the smallest global index so that neighbouring prisms split their shared quads alike; each
/// oriented positively in the reference prism (bottom (0,0,0), (1,0,0), (0,1,0), top at z = 1).
std::array<std::array<int, 4>, 3> prism_tets(const std::array<int, 6>& global) {
  const int k = static_cast<int>(std::min_element(global.begin(), global.end()) - global.begin());
  std::array<int, 6> s{};
  for (int j = 0; j < 6; ++j) s[j] = kPrismIndirection[k][j];
  std::array<std::array<int, 4>, 3> tets;
  if (std::min(global[s[1]], global[s[5]]) < std::min(global[s[2]], global[s[4]])) {
    tets = {{{s[0], s[1], s[2], s[5]}, {s[0], s[1], s[5], s[4]}, {s[0], s[4], s[5], s[3]}}};
  } else {
    tets = {{{s[0], s[1], s[2], s[4]}, {s[0], s[4], s[2], s[5]}, {s[0], s[4], s[5], s[3]}}};
  }
  static const std::array<Vec3, 6> ref{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                                       Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1)};
  for (auto& t : tets) {
    if (signed_volume(ref[t[0]], ref[t[1]], ref[t[2]], ref[t[3]]) < 0.0) std::swap(t[2], t[3]);
  }
  return tets;
}

}  // namespace

std::vector<std::vector<int>> boundary_loops(const TriangleSurface& surface,
                                             std::string_view source) {
  std::map<int, int> next;  // boundary edge u → v, in the direction its triangle traverses it
  for (const auto& [edge, uses] : edge_uses(surface.triangles)) {
    if (uses.size() != 1) continue;
    const auto [u, v] = uses[0].forward ? edge : Edge{edge.second, edge.first};
    if (!next.emplace(u, v).second) {
      throw InputError(std::string(source) + ": the surface is not manifold at node " +
                       mm(surface.nodes[u]) +
                       ": two boundary loops touch there (a vertex with four open edges); "
                       "expected each open end to be a separate loop");
    }
  }
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    const int start = next.begin()->first;  // the smallest remaining node
    std::vector<int> loop;
    int u = start;
    do {
      loop.push_back(u);
      const auto it = next.find(u);
      if (it == next.end()) {
        throw InputError(std::string(source) + ": the open edges at " + mm(surface.nodes[u]) +
                         " do not close into a loop; expected every open end to be a closed "
                         "loop of edges");
      }
      const int v = it->second;
      next.erase(it);
      u = v;
    } while (u != start);
    loops.push_back(std::move(loop));
  }
  return loops;
}

LumenEnd describe_end(const std::vector<Vec3>& nodes, std::vector<int> loop,
                      const std::vector<Triangle>* triangles) {
  LumenEnd e;
  for (const int i : loop) e.centre += nodes[i];
  e.centre /= static_cast<double>(loop.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  Vec3 area2 = Vec3::Zero();
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Vec3 d = nodes[loop[k]] - e.centre;
    cov += d * d.transpose();
    e.radius += d.norm();
    area2 += d.cross(nodes[loop[(k + 1) % loop.size()]] - e.centre);
  }
  e.radius /= static_cast<double>(loop.size());
  e.area = 0.5 * area2.norm();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  e.normal = eig.eigenvectors().col(0);  // the smallest spread: across the plane
  if (e.normal.dot(area2) < 0.0) e.normal = -e.normal;
  for (const int i : loop) {
    e.planarity = std::max(e.planarity, std::abs((nodes[i] - e.centre).dot(e.normal)));
  }
  if (e.radius > 0.0) e.planarity /= e.radius;
  if (triangles) {
    // The third node of the triangle on each loop edge (u → v, as the triangle traverses it).
    std::map<Edge, int> third;
    for (const Triangle& t : *triangles) {
      for (int k = 0; k < 3; ++k) third[{t[k], t[(k + 1) % 3]}] = t[(k + 2) % 3];
    }
    double weighted = 0.0, length = 0.0;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const int u = loop[k], v = loop[(k + 1) % loop.size()];
      const auto it = third.find({u, v});
      if (it == third.end()) continue;
      const Vec3 edge = nodes[v] - nodes[u];
      const Vec3 along = edge.normalized();
      Vec3 across = nodes[it->second] - 0.5 * (nodes[u] + nodes[v]);
      across -= across.dot(along) * along;
      if (across.norm() == 0.0) continue;
      weighted += edge.norm() * std::abs(across.normalized().dot(e.normal));
      length += edge.norm();
    }
    if (length > 0.0) e.steepness = weighted / length;
  }
  e.loop = std::move(loop);
  return e;
}

std::string format_end(const LumenEnd& e) {
  std::ostringstream s;
  s.precision(4);
  s << mm(e.centre) << ", radius " << e.radius * 1e3 << " mm, normal (" << cleaned(e.normal.x())
    << ", " << cleaned(e.normal.y()) << ", " << cleaned(e.normal.z()) << "), area " << e.area * 1e6
    << " mm²";
  return s.str();
}

std::vector<std::pair<int, int>> crossing_triangles(const std::vector<Vec3>& x,
                                                    const std::vector<Triangle>& tris,
                                                    std::size_t limit) {
  std::vector<std::pair<int, int>> found;
  if (tris.empty()) return found;
  Eigen::AlignedBox3d box;
  double edge_sum = 0.0;
  for (const Triangle& t : tris) {
    for (int k = 0; k < 3; ++k) {
      box.extend(x[t[k]]);
      edge_sum += (x[t[k]] - x[t[(k + 1) % 3]]).norm();
    }
  }
  const double h = std::max(2.0 * edge_sum / (3.0 * static_cast<double>(tris.size())),
                            box.diagonal().norm() * 1e-6);
  const double scale = box.diagonal().norm();
  const double eps = 1e-12 * scale * scale * scale;
  auto cell_of = [&](const Vec3& p) {
    const Vec3 c = ((p - box.min()) / h).array().floor();
    return Eigen::Vector3i(static_cast<int>(c.x()), static_cast<int>(c.y()),
                           static_cast<int>(c.z()));
  };
  std::vector<Eigen::Vector3i> lo(tris.size()), hi(tris.size());
  std::unordered_map<long long, std::vector<int>> grid;
  const auto key = [](int i, int j, int k) {
    return (static_cast<long long>(i) << 42) ^ (static_cast<long long>(j) << 21) ^ k;
  };
  for (std::size_t t = 0; t < tris.size(); ++t) {
    Eigen::AlignedBox3d b;
    for (int k = 0; k < 3; ++k) b.extend(x[tris[t][k]]);
    lo[t] = cell_of(b.min());
    hi[t] = cell_of(b.max());
    for (int i = lo[t].x(); i <= hi[t].x(); ++i) {
      for (int j = lo[t].y(); j <= hi[t].y(); ++j) {
        for (int k = lo[t].z(); k <= hi[t].z(); ++k)
          grid[key(i, j, k)].push_back(static_cast<int>(t));
      }
    }
  }
  for (std::size_t t = 0; t < tris.size() && found.size() < limit; ++t) {
    for (int i = lo[t].x(); i <= hi[t].x(); ++i) {
      for (int j = lo[t].y(); j <= hi[t].y(); ++j) {
        for (int k = lo[t].z(); k <= hi[t].z(); ++k) {
          for (const int u : grid[key(i, j, k)]) {
            if (u <= static_cast<int>(t)) continue;
            // Test each pair once: in the first cell both boxes share.
            const Eigen::Vector3i first = lo[t].cwiseMax(lo[u]);
            if (first != Eigen::Vector3i(i, j, k)) continue;
            const Triangle& a = tris[t];
            const Triangle& b = tris[u];
            bool shared = false;
            for (const int p : a) shared = shared || std::find(b.begin(), b.end(), p) != b.end();
            if (shared || !triangles_cross(x, a, b, eps)) continue;
            found.emplace_back(static_cast<int>(t), u);
            if (found.size() >= limit) return found;
          }
        }
      }
    }
  }
  return found;
}

namespace {

/// InputError unless the lumen's bounding box is the size of a vessel in metres (a file in
/// millimetres read as metres, or the reverse, is off by 1e3).
void check_lumen_size(const TriangleSurface& lumen, const std::string& source) {
  Eigen::AlignedBox3d box;
  for (const Vec3& p : lumen.nodes) box.extend(p);
  const Vec3 size = box.sizes();
  const double diagonal = size.norm();
  const std::string extent = num(size.x()) + " × " + num(size.y()) + " × " + num(size.z()) +
                             " m (diagonal " + num(diagonal) + " m)";
  if (diagonal > kMaxVesselSize) {
    throw InputError(source + ": the lumen's bounding box is " + extent +
                     ", larger than a vessel (expected a diagonal under " + num(kMaxVesselSize) +
                     " m; coordinates are read as metres): looks like millimetres; scale by 1e-3 "
                     "or set units = \"mm\" in the scene's [vessel] table (--units mm)");
  }
  if (diagonal < kMinVesselSize) {
    throw InputError(source + ": the lumen's bounding box is " + extent +
                     ", smaller than a vessel (expected a diagonal of at least " +
                     num(kMinVesselSize) +
                     " m): is the file in metres but read with units = \"mm\"?");
  }
}

/// InputError unless the surface is edge manifold and consistently oriented.
void check_lumen_edges(const TriangleSurface& lumen, const std::string& source) {
  for (const auto& [edge, uses] : edge_uses(lumen.triangles)) {
    if (uses.size() > 2) {
      std::string facets;
      for (const auto& u : uses)
        facets += (facets.empty() ? "" : ", ") + std::to_string(u.triangle + 1);
      throw InputError(source + ": the surface is not manifold: the edge from " +
                       mm(lumen.nodes[edge.first]) + " to " + mm(lumen.nodes[edge.second]) +
                       " is shared by " + std::to_string(uses.size()) + " facets (" + facets +
                       "); expected at most two");
    }
    if (uses.size() == 2 && uses[0].forward == uses[1].forward) {
      throw InputError(source + ": facets " + std::to_string(uses[0].triangle + 1) + " and " +
                       std::to_string(uses[1].triangle + 1) +
                       " are oriented inconsistently (both traverse their shared edge at " +
                       mm(lumen.nodes[edge.first]) +
                       " the same way); expected every normal on the same side of the surface");
    }
  }
}

}  // namespace

namespace {

/// With ends listed: every loop is one of them and each listed centre is one loop's, else an
/// InputError naming what is unmatched (the criteria of the unlisted case are not applied).
void match_listed_ends(const std::vector<LumenEnd>& ends, const ListedEnds& listed,
                       const std::string& source) {
  std::vector<int> loops_of(listed.outlets.size() + 1, 0);
  std::vector<std::string> problems;
  for (const LumenEnd& e : ends) {
    const int k = listed_end(e, listed);
    if (k < 0) {
      problems.push_back("the open loop around " + mm(e.centre) + ", radius " +
                         num(e.radius * 1e3) + " mm, is none of the listed ends");
    } else {
      ++loops_of[static_cast<std::size_t>(k)];
    }
  }
  for (std::size_t k = 0; k < loops_of.size(); ++k) {
    if (loops_of[k] == 1) continue;
    const Vec3& c = k == 0 ? listed.inlet : listed.outlets[k - 1];
    const std::string name =
        k == 0 ? "inlet_centre " : "outlet_centres[" + std::to_string(k - 1) + "] ";
    problems.push_back(name + mm(c) +
                       (loops_of[k] == 0
                            ? " is the centre of no open loop"
                            : " matches " + std::to_string(loops_of[k]) + " open loops"));
  }
  if (!problems.empty()) {
    std::string message = source + ": the ends listed in the scene ([vessel] inlet_centre, " +
                          "outlet_centres) do not match the lumen's open loops: ";
    for (std::size_t p = 0; p < problems.size(); ++p) message += (p ? "; " : "") + problems[p];
    throw InputError(message + "; expected each open loop's centre within " +
                     num(100.0 * kListedEndTolerance, 3) +
                     " % of its radius of exactly one listed centre (`vesselverify mesh --lumen` "
                     "lists the loops it finds)");
  }
}

}  // namespace

std::vector<LumenEnd> check_lumen(const TriangleSurface& lumen, std::string_view source_view,
                                  const ListedEnds& listed) {
  const std::string source(source_view);
  if (lumen.triangles.empty()) throw InputError(source + ": the lumen surface has no triangles");
  check_lumen_size(lumen, source);
  check_lumen_edges(lumen, source);

  // Ends: every boundary loop must look like a cut end of the vessel.
  const std::vector<std::vector<int>> loops = boundary_loops(lumen, source);
  if (loops.empty()) {
    throw InputError(source +
                     ": the lumen surface is closed (no open end); expected it open "
                     "at its inlet and outlets (remove the caps, so each end is a loop of edges)");
  }
  std::vector<LumenEnd> ends;
  double largest = 0.0;
  for (const auto& loop : loops) {
    ends.push_back(describe_end(lumen.nodes, loop, &lumen.triangles));
    largest = std::max(largest, ends.back().radius);
  }
  if (listed.given()) match_listed_ends(ends, listed, source);
  // Every loop that is not an end is named (a segmentation often leaves more than one hole).
  std::vector<std::string> holes;
  bool in_wall = false;  // a loop that fails the steepness criterion alone
  // Listed ends replace the criteria: then no loop is judged by them.
  for (const LumenEnd& e : listed.given() ? std::vector<LumenEnd>{} : ends) {
    const int edges = static_cast<int>(e.loop.size());
    if (edges < kMinEndEdges || e.planarity > kMaxEndPlanarity ||
        e.radius < kMinEndRadiusRatio * largest) {
      holes.push_back("an open loop of " + std::to_string(edges) + " edges around " + mm(e.centre) +
                      ", radius " + num(e.radius * 1e3) + " mm, its nodes up to " +
                      num(100.0 * e.planarity, 3) +
                      " % of its radius off its plane; expected every open "
                      "loop to be an end (at least " +
                      std::to_string(kMinEndEdges) + " edges, within " +
                      num(100.0 * kMaxEndPlanarity, 3) + " % of one plane, radius at least " +
                      num(100.0 * kMinEndRadiusRatio, 3) + " % of the largest end's " +
                      num(largest * 1e3) + " mm): fill the hole or cut the end flat");
    } else if (e.steepness < kMinEndSteepness) {
      const double angle = std::asin(std::clamp(e.steepness, 0.0, 1.0)) * 180.0 / std::numbers::pi;
      holes.push_back("the open loop around " + mm(e.centre) + ", radius " + num(e.radius * 1e3) +
                      " mm, lies in the vessel's wall (the surface meets its plane at " +
                      num(angle, 3) + "°, not across it)");
      in_wall = true;
    }
  }
  if (in_wall) {
    holes.back() +=
        "; an end is a cut across the vessel, which the wall leaves at more than 45°: "
        "expected every open loop to be an end of the vessel: fill the hole in the "
        "surface, or, if it is an end, cut it square to the vessel";
  }
  if (!holes.empty()) {
    std::string message =
        source + ": " +
        (holes.size() == 1 ? std::string("a hole") : std::to_string(holes.size()) + " holes") +
        " where no end should be: ";
    for (std::size_t h = 0; h < holes.size(); ++h) message += (h ? "; " : "") + holes[h];
    throw InputError(message);
  }
  if (ends.size() < 2) {
    throw InputError(source + ": the lumen has one open end (around " + mm(ends[0].centre) +
                     "); expected an inlet and at least one outlet");
  }

  // Orientation: the volume enclosed with each end closed by a fan must be positive.
  double volume6 = 0.0;
  for (const Triangle& t : lumen.triangles) {
    volume6 += lumen.nodes[t[0]].dot(lumen.nodes[t[1]].cross(lumen.nodes[t[2]]));
  }
  for (const LumenEnd& e : ends) {
    for (std::size_t k = 0; k < e.loop.size(); ++k) {
      const Vec3& u = lumen.nodes[e.loop[k]];
      const Vec3& v = lumen.nodes[e.loop[(k + 1) % e.loop.size()]];
      volume6 += v.dot(u.cross(e.centre));  // cap triangle (v, u, centre)
    }
  }
  if (volume6 < 0.0) {
    throw InputError(source +
                     ": the lumen is inside out: its facet normals point into the lumen "
                     "(the volume it encloses, ends closed, is " +
                     num(volume6 / 6.0 * 1e9) +
                     " mm³); expected them outward, away from the blood and into the wall: "
                     "reverse every facet's vertex order");
  }

  const auto crossing = crossing_triangles(lumen.nodes, lumen.triangles, 1);
  if (!crossing.empty()) {
    const auto [a, b] = crossing.front();
    Vec3 c = Vec3::Zero();
    for (const int i : lumen.triangles[a]) c += lumen.nodes[i] / 3.0;
    throw InputError(source + ": the surface intersects itself: facets " + std::to_string(a + 1) +
                     " and " + std::to_string(b + 1) + " cross near " + mm(c) +
                     "; expected a surface that touches itself nowhere");
  }
  return ends;
}

TriangleSurface subdivide_surface(const TriangleSurface& surface, int times) {
  TriangleSurface s = surface;
  for (int pass = 0; pass < times; ++pass) {
    std::map<Edge, int> midpoint;
    const auto mid = [&](int a, int b) {
      const Edge e{std::min(a, b), std::max(a, b)};
      const auto [it, inserted] = midpoint.emplace(e, static_cast<int>(s.nodes.size()));
      if (inserted) {
        s.nodes.push_back(0.5 * (s.nodes[a] + s.nodes[b]));
        s.source_node.push_back(-1);
      }
      return it->second;
    };
    std::vector<Triangle> out;
    out.reserve(4 * s.triangles.size());
    for (const Triangle& t : s.triangles) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      out.push_back({t[0], ab, ca});
      out.push_back({ab, t[1], bc});
      out.push_back({ca, bc, t[2]});
      out.push_back({ab, bc, ca});
    }
    s.triangles = std::move(out);
  }
  return s;
}

int listed_end(const LumenEnd& end, const ListedEnds& listed) {
  if (!listed.given()) return -1;
  const double within = kListedEndTolerance * end.radius;
  if ((listed.inlet - end.centre).norm() <= within) return 0;
  for (std::size_t k = 0; k < listed.outlets.size(); ++k) {
    if ((listed.outlets[k] - end.centre).norm() <= within) return static_cast<int>(k) + 1;
  }
  return -1;
}

int inlet_end(const std::vector<LumenEnd>& ends, const ListedEnds& listed) {
  if (listed.given()) {
    for (int e = 0; e < static_cast<int>(ends.size()); ++e) {
      if (listed_end(ends[e], listed) == 0) return e;
    }
    throw std::logic_error(
        "inlet_end: no loop matches the listed inlet (check_lumen refuses that)");
  }
  int inlet = 0;
  for (int e = 1; e < static_cast<int>(ends.size()); ++e) {
    if (ends[e].area > kInletAreaTie * ends[inlet].area) inlet = e;
  }
  return inlet;
}

namespace {

/// Each lumen node's end (its index in `ends`), −1 for a node on no end's loop.
std::vector<int> end_of_nodes(int n, const std::vector<LumenEnd>& ends) {
  std::vector<int> end_of(n, -1);
  for (int e = 0; e < static_cast<int>(ends.size()); ++e) {
    for (const int i : ends[e].loop) end_of[i] = e;
  }
  return end_of;
}

/// The directions the lumen's nodes are extruded along: the vertex normals, those on an end's
/// loop turned into the end's plane so that the end stays flat.
std::vector<Vec3> extrusion_normals(const TriangleSurface& lumen,
                                    const std::vector<LumenEnd>& ends) {
  std::vector<Vec3> normal = vertex_normals(lumen.nodes, lumen.triangles);
  for (const LumenEnd& end : ends) {
    for (const int i : end.loop) {
      normal[i] -= normal[i].dot(end.normal) * end.normal;  // stay in the end's plane
      normal[i].normalize();
    }
  }
  return normal;
}

/// Lumen neighbours of each node (for smoothing the normals at a crease).
std::vector<std::vector<int>> lumen_neighbours(const TriangleSurface& lumen, int n) {
  std::vector<std::vector<int>> neighbours(n);
  for (const Triangle& t : lumen.triangles) {
    for (int k = 0; k < 3; ++k) {
      neighbours[t[k]].push_back(t[(k + 1) % 3]);
      neighbours[t[k]].push_back(t[(k + 2) % 3]);
    }
  }
  return neighbours;
}

/// A wall extruded along given normals, and what its tets say about them.
struct Extrusion {
  TetMesh mesh;
  std::size_t inverted = 0;            ///< tets of (near) zero or negative volume
  Vec3 first_inverted = Vec3::Zero();  ///< the first one's centroid
  std::vector<char> near_flat;         ///< per lumen node: in a prism with a near-flat tet
};

/// The wall as `layers` layers of prisms (three tets each) between the lumen and its offset by
/// `thickness` along `normal`; node (layer k, lumen node i) is k·n + i.
Extrusion extrude_along(const TriangleSurface& lumen, const std::vector<Vec3>& normal,
                        double thickness, int layers) {
  const int n = static_cast<int>(lumen.nodes.size());
  const auto id = [n](int layer, int i) { return layer * n + i; };
  Extrusion x;
  TetMesh& mesh = x.mesh;
  mesh.nodes.reserve(static_cast<std::size_t>(n) * (layers + 1));
  for (int k = 0; k <= layers; ++k) {
    const double offset = thickness * k / layers;
    for (int i = 0; i < n; ++i) mesh.nodes.push_back(lumen.nodes[i] + offset * normal[i]);
  }
  x.near_flat.assign(n, 0);
  for (int k = 0; k < layers; ++k) {
    for (const Triangle& t : lumen.triangles) {
      const std::array<int, 6> g{id(k, t[0]),     id(k, t[1]),     id(k, t[2]),
                                 id(k + 1, t[0]), id(k + 1, t[1]), id(k + 1, t[2])};
      for (const auto& slots : prism_tets(g)) {
        const Tet tet{g[slots[0]], g[slots[1]], g[slots[2]], g[slots[3]]};
        const Vec3 &a = mesh.nodes[tet[0]], &b = mesh.nodes[tet[1]], &c = mesh.nodes[tet[2]],
                   &d = mesh.nodes[tet[3]];
        double longest = 0.0;
        for (const auto& [p, q] :
             {std::pair{&a, &b}, {&a, &c}, {&a, &d}, {&b, &c}, {&b, &d}, {&c, &d}}) {
          longest = std::max(longest, (*p - *q).norm());
        }
        const double v = signed_volume(a, b, c, d), l3 = longest * longest * longest;
        if (v <= kZeroVolumeTolerance * l3 && x.inverted++ == 0) {
          x.first_inverted = 0.25 * (a + b + c + d);
        }
        if (v <= kNearFlatPrismTet * l3) {
          for (const int i : t) x.near_flat[i] = 1;
        }
        mesh.tets.push_back(tet);
      }
    }
  }
  return x;
}

/// A crease (where a branch leaves) turns the normals faster than the wall is thick: the
/// normals at near-flat prisms and around them averaged with their neighbours', keeping the
/// ends' in their planes.
std::vector<Vec3> smoothed_at_creases(const std::vector<Vec3>& normal,
                                      const std::vector<char>& near_flat,
                                      const std::vector<std::vector<int>>& neighbours,
                                      const std::vector<int>& end_of,
                                      const std::vector<LumenEnd>& ends) {
  const int n = static_cast<int>(normal.size());
  std::vector<char> smooth = near_flat;
  for (int i = 0; i < n; ++i) {
    if (near_flat[i]) {
      for (const int j : neighbours[i]) smooth[j] = 1;
    }
  }
  std::vector<Vec3> averaged = normal;
  for (int i = 0; i < n; ++i) {
    if (!smooth[i]) continue;
    for (const int j : neighbours[i]) averaged[i] += normal[j];
    if (end_of[i] >= 0) {
      const Vec3& e = ends[end_of[i]].normal;
      averaged[i] -= averaged[i].dot(e) * e;
    }
    averaged[i].normalize();
  }
  return averaged;
}

/// InputError if the outer wall (the last layer) crosses itself: two parts of the vessel closer
/// than twice the wall's thickness.
void check_outer_wall(const TetMesh& mesh, const TriangleSurface& lumen, int layers,
                      double thickness, const std::string& source) {
  const int n = static_cast<int>(lumen.nodes.size());
  const auto id = [n](int layer, int i) { return layer * n + i; };
  std::vector<Triangle> outer;
  for (const Triangle& t : lumen.triangles)
    outer.push_back({id(layers, t[0]), id(layers, t[1]), id(layers, t[2])});
  const auto crossing = crossing_triangles(mesh.nodes, outer, 1);
  if (!crossing.empty()) {
    Vec3 c = Vec3::Zero();
    for (const int i : outer[crossing.front().first]) c += mesh.nodes[i] / 3.0;
    throw InputError(source + ": with wall_thickness = " + num(thickness * 1e3) +
                     " mm the outer wall crosses itself near " + mm(c) +
                     ": two parts of the vessel are closer than twice the wall's thickness; "
                     "expected a thinner wall");
  }
}

/// Boundary groups: lumen layer → inner wall, last layer → outer wall, else the end of its loop
/// (the inlet or an outlet); every tet in the wall.
void add_vessel_groups(TetMesh& mesh, const std::vector<LumenEnd>& ends,
                       const std::vector<int>& end_of, int layers, const ListedEnds& listed) {
  const int n = static_cast<int>(end_of.size());
  const int inlet = inlet_end(ends, listed);
  std::map<std::string_view, PhysicalGroup> groups;
  for (const auto& spec : kVesselGroups) {
    groups[spec.name] = PhysicalGroup{std::string(spec.name), spec.dim, spec.tag, {}};
  }
  for (const Triangle& f : boundary_faces(mesh)) {
    int lo = layers, hi = 0, lumen_node = -1;
    for (const int v : f) {
      lo = std::min(lo, v / n);
      hi = std::max(hi, v / n);
      lumen_node = v % n;
    }
    std::string_view name = group_names::inner_wall;
    if (lo == layers) {
      name = group_names::outer_wall;
    } else if (hi > 0) {
      const int e = end_of[lumen_node];
      if (e < 0) throw std::logic_error("extrude_lumen: a side face off every end");
      name = e == inlet ? group_names::inlet : group_names::outlet;
    }
    groups[name].elements.push_back(static_cast<int>(mesh.triangles.size()));
    mesh.triangles.push_back(f);
  }
  for (int t = 0; t < static_cast<int>(mesh.tets.size()); ++t) {
    groups[group_names::wall].elements.push_back(t);
  }
  for (const auto& spec : kVesselGroups) mesh.groups.push_back(std::move(groups[spec.name]));
}

}  // namespace

TetMesh extrude_lumen(const TriangleSurface& lumen, const std::vector<LumenEnd>& ends,
                      double thickness, int layers, std::string_view source_view,
                      const ListedEnds& listed) {
  const std::string source(source_view);
  if (!(thickness > 0.0) || !std::isfinite(thickness)) {
    throw InputError(source + ": wall_thickness: expected a finite value > 0 m, got " +
                     num(thickness));
  }
  if (layers < 1) throw InputError(source + ": expected at least one layer through the wall");
  const int n = static_cast<int>(lumen.nodes.size());
  std::vector<Vec3> normal = extrusion_normals(lumen, ends);
  const std::vector<int> end_of = end_of_nodes(n, ends);
  const std::vector<std::vector<int>> neighbours = lumen_neighbours(lumen, n);
  // Extruded again with the normals smoothed at creases while a prism has a near-flat tet.
  Extrusion x;
  for (int pass = 0;; ++pass) {
    x = extrude_along(lumen, normal, thickness, layers);
    if (std::find(x.near_flat.begin(), x.near_flat.end(), 1) == x.near_flat.end() ||
        pass == kMaxNormalSmoothingPasses) {
      break;
    }
    normal = smoothed_at_creases(normal, x.near_flat, neighbours, end_of, ends);
  }
  if (x.inverted > 0) {
    throw InputError(source + ": extruding the lumen outward by wall_thickness = " +
                     num(thickness * 1e3) + " mm folds the wall over itself near " +
                     mm(x.first_inverted) + " (" + std::to_string(x.inverted) +
                     " inverted or flat tets, after " + std::to_string(kMaxNormalSmoothingPasses) +
                     " passes of smoothing the normals there): the lumen curves more tightly "
                     "than the wall is thick there; expected a thinner wall or a smoother lumen");
  }
  TetMesh mesh = std::move(x.mesh);
  check_outer_wall(mesh, lumen, layers, thickness, source);
  add_vessel_groups(mesh, ends, end_of, layers, listed);
  sort_elements(mesh);
  orient_boundary_outward(mesh);
  require_vessel_groups(mesh, source);
  return mesh;
}

std::vector<std::pair<std::string, LumenEnd>> lumen_file_ends(const std::filesystem::path& file,
                                                              double scale,
                                                              const ListedEnds& listed) {
  TriangleSurface lumen = read_stl(file);
  for (Vec3& x : lumen.nodes) x *= scale;
  const std::vector<LumenEnd> ends = check_lumen(lumen, file.string(), listed);
  const int inlet = inlet_end(ends, listed);
  std::vector<std::pair<std::string, LumenEnd>> named;
  for (int e = 0; e < static_cast<int>(ends.size()); ++e) {
    named.emplace_back(std::string(e == inlet ? group_names::inlet : group_names::outlet), ends[e]);
  }
  return named;
}

int lumen_wall_layers(int level) { return 2 << level; }

TetMesh lumen_wall_mesh(const LumenWallParams& p) {
  const std::string source = p.file.string();
  if (!(p.scale > 0.0) || !std::isfinite(p.scale)) {
    throw InputError(source + ": units scale: expected a finite value > 0, got " + num(p.scale));
  }
  if (p.level < 0 || p.level > kMaxMeshLevel) {
    throw InputError(source + ": mesh level " + std::to_string(p.level) +
                     " is out of range: expected 0.." + std::to_string(kMaxMeshLevel));
  }
  TriangleSurface lumen = read_stl(p.file);
  for (Vec3& x : lumen.nodes) x *= p.scale;
  check_lumen(lumen, source, p.listed);
  const TriangleSurface fine = subdivide_surface(lumen, p.level);
  std::vector<LumenEnd> ends;
  for (auto& loop : boundary_loops(fine, source)) ends.push_back(describe_end(fine.nodes, loop));
  return extrude_lumen(fine, ends, p.thickness, lumen_wall_layers(p.level), source, p.listed);
}

}  // namespace vessel
