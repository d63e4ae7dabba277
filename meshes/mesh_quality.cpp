#include "meshes/mesh_quality.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>

namespace vessel {

namespace {

/// Streaming min/max/mean/std (Welford).
class Accumulator {
 public:
  void add(double x) {
    ++n_;
    const double d = x - mean_;
    mean_ += d / static_cast<double>(n_);
    m2_ += d * (x - mean_);
    min_ = std::min(min_, x);
    max_ = std::max(max_, x);
  }
  [[nodiscard]] Stats stats() const {
    if (n_ == 0) return {};
    return {min_, max_, mean_, std::sqrt(m2_ / static_cast<double>(n_)), n_};
  }

 private:
  std::size_t n_ = 0;
  double mean_ = 0.0;
  double m2_ = 0.0;
  double min_ = std::numeric_limits<double>::infinity();
  double max_ = -std::numeric_limits<double>::infinity();
};

constexpr std::array<std::array<int, 4>, 6> kEdgesWithOpposite{
    {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}}};

}  // namespace

std::array<double, 6> dihedral_angles_deg(const Vec3& a, const Vec3& b, const Vec3& c,
                                          const Vec3& d) {
  const std::array<const Vec3*, 4> p{&a, &b, &c, &d};
  // Interior dihedral angle at edge (i, j): angle between the components of (p_k − p_i) and
  // (p_l − p_i) orthogonal to the edge, via (e × u)·(e × v) = |e|² u⊥·v⊥.
  std::array<double, 6> out{};
  for (std::size_t n = 0; n < 6; ++n) {
    const auto& [i, j, k, l] = kEdgesWithOpposite[n];
    const Vec3 e = *p[j] - *p[i];
    const Vec3 u = e.cross(*p[k] - *p[i]);
    const Vec3 v = e.cross(*p[l] - *p[i]);
    const double denom = u.norm() * v.norm();
    out[n] = denom > 0 ? std::acos(std::clamp(u.dot(v) / denom, -1.0, 1.0)) * 180.0 /
                             std::numbers::pi
                       : 0.0;
  }
  return out;
}

TetQuality tet_quality(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  TetQuality q;
  q.volume = signed_volume(a, b, c, d);
  const auto angles = dihedral_angles_deg(a, b, c, d);
  q.min_dihedral_deg = *std::min_element(angles.begin(), angles.end());
  q.max_dihedral_deg = *std::max_element(angles.begin(), angles.end());
  // Inradius r = 3|V|/ΣA; circumradius R = |a²(b×c) + b²(c×a) + c²(a×b)| / (12|V|) with edge
  // vectors from vertex 0; radius ratio 3r/R is 1 for the regular tet.
  const double area = triangle_area(b, c, d) + triangle_area(a, c, d) + triangle_area(a, b, d) +
                      triangle_area(a, b, c);
  const Vec3 e1 = b - a;
  const Vec3 e2 = c - a;
  const Vec3 e3 = d - a;
  const double vol = std::abs(q.volume);
  if (vol > 0 && area > 0) {
    const double r_in = 3.0 * vol / area;
    const double r_circ = (e1.squaredNorm() * e2.cross(e3) + e2.squaredNorm() * e3.cross(e1) +
                           e3.squaredNorm() * e1.cross(e2))
                              .norm() /
                          (12.0 * vol);
    q.radius_ratio = 3.0 * r_in / r_circ;
  }
  return q;
}

MeshQuality compute_quality(const TetMesh& mesh) {
  Accumulator dihedral;
  Accumulator ratio;
  Accumulator volume;
  Accumulator edge;
  MeshQuality q;
  std::vector<std::pair<int, int>> edges;
  edges.reserve(mesh.tets.size() * 6);
  for (const auto& t : mesh.tets) {
    const auto& a = mesh.nodes[t[0]];
    const auto& b = mesh.nodes[t[1]];
    const auto& c = mesh.nodes[t[2]];
    const auto& d = mesh.nodes[t[3]];
    const TetQuality tq = tet_quality(a, b, c, d);
    for (double angle : dihedral_angles_deg(a, b, c, d)) dihedral.add(angle);
    ratio.add(tq.radius_ratio);
    volume.add(tq.volume);
    q.total_volume += tq.volume;
    double mean_edge = 0.0;
    for (const auto& [i, j, k, l] : kEdgesWithOpposite) {
      mean_edge += (mesh.nodes[t[j]] - mesh.nodes[t[i]]).norm() / 6.0;
      edges.emplace_back(std::min(t[i], t[j]), std::max(t[i], t[j]));
    }
    if (tq.volume < 0) ++q.inverted;
    if (std::abs(tq.volume) < 1e-8 * mean_edge * mean_edge * mean_edge) ++q.degenerate;
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [i, j] : edges) edge.add((mesh.nodes[j] - mesh.nodes[i]).norm());
  q.dihedral_deg = dihedral.stats();
  q.radius_ratio = ratio.stats();
  q.volume = volume.stats();
  q.edge_length = edge.stats();
  return q;
}

std::string format_quality(const MeshQuality& q) {
  std::ostringstream s;
  s << std::setprecision(4);
  s << "  dihedral angle   min " << q.dihedral_deg.min << "°, max " << q.dihedral_deg.max
    << "°\n";
  s << "  radius ratio     min " << q.radius_ratio.min << ", mean " << q.radius_ratio.mean
    << " (1 = regular tet)\n";
  s << "  edge length      min " << q.edge_length.min * 1e3 << " mm, max "
    << q.edge_length.max * 1e3 << " mm, mean " << q.edge_length.mean * 1e3 << " mm, std "
    << q.edge_length.stddev * 1e3 << " mm (" << q.edge_length.count << " edges)\n";
  s << "  tet volume       min " << q.volume.min * 1e9 << " mm³, max " << q.volume.max * 1e9
    << " mm³, total " << q.total_volume * 1e9 << " mm³\n";
  s << "  inverted tets    " << q.inverted << (q.inverted ? "  <-- INVERTED ELEMENTS" : "")
    << "\n";
  s << "  degenerate tets  " << q.degenerate << (q.degenerate ? "  <-- ZERO-VOLUME ELEMENTS" : "")
    << "\n";
  return s.str();
}

SliverReport find_slivers(const TetMesh& mesh) {
  SliverReport r;
  for (const Tet& t : mesh.tets) {
    const auto angles = dihedral_angles_deg(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]],
                                            mesh.nodes[t[3]]);
    const double lo = *std::min_element(angles.begin(), angles.end());
    const double hi = *std::max_element(angles.begin(), angles.end());
    r.min_dihedral_deg = std::min(r.min_dihedral_deg, lo);
    r.max_dihedral_deg = std::max(r.max_dihedral_deg, hi);
    if (lo >= kSliverMinDihedralDeg && hi <= kSliverMaxDihedralDeg) continue;
    ++r.count;
    if (lo < r.worst_min_dihedral_deg) {
      r.worst_min_dihedral_deg = lo;
      r.worst_max_dihedral_deg = hi;
      r.worst_centroid = 0.25 * (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]] +
                                 mesh.nodes[t[3]]);
    }
  }
  return r;
}

std::string sliver_warning(const SliverReport& r) {
  if (r.count == 0) return "";
  std::ostringstream s;
  s << std::setprecision(4) << "WARNING: " << r.count
    << " sliver tets (a dihedral angle below " << kSliverMinDihedralDeg << "° or above "
    << kSliverMaxDihedralDeg << "°); the worst, at (" << r.worst_centroid.x() * 1e3 << ", "
    << r.worst_centroid.y() * 1e3 << ", " << r.worst_centroid.z() * 1e3 << ") mm, has angles "
    << r.worst_min_dihedral_deg << "° to " << r.worst_max_dihedral_deg
    << "°: results on this mesh include the mesh's error (P1 elements there can be far from P2)";
  return s.str();
}

}  // namespace vessel
