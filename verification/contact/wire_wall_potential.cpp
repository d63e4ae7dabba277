#include "verification/contact/wire_wall_potential.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "meshes/foundation/errors.hpp"
#include "msm/linalg/linear_solver.hpp"
#include "msm/linalg/low_rank_update.hpp"
#include "msm/solvers/exact_backoff.hpp"
#include "msm/solvers/steihaug.hpp"
#include "verification/contact/condensed_wall.hpp"
#include "verification/contact/point_segment_distance.hpp"
#include "verification/contact/point_triangle_distance.hpp"
#include "verification/contact/wall_crossing.hpp"

namespace vessel::contact {

using Eigen::VectorXd;
using Triplets = std::vector<Eigen::Triplet<double>>;

std::vector<Vec3> WallPotential::nodal(const VectorXd& u) const { return per_node(node_rows(), u); }

std::optional<std::size_t> WallPotential::inverted_tets(const TetMesh& mesh,
                                                        const VectorXd& u) const {
  std::vector<Vec3> x = nodal(u);
  for (std::size_t n = 0; n < x.size(); ++n) x[n] += mesh.nodes[n];
  return vessel::inverted_tets(mesh, x);
}

WireThroughWall with_inverted_tets(const WireThroughWall& crossing, const WallPotential& wall,
                                   const TetMesh& mesh) {
  std::string what = crossing.what();
  const std::optional<std::size_t> inverted = crossing.wall_rows.size() == wall.num_dofs()
                                                  ? wall.inverted_tets(mesh, crossing.wall_rows)
                                                  : std::nullopt;
  if (inverted && *inverted > 0) {
    what += " (" + std::to_string(*inverted) + " of the wall's tets inverted: it had folded)";
  }
  return {what, crossing.centreline, crossing.point, crossing.triangle, crossing.wall_rows};
}

double WallPotential::evaluate_both(const VectorXd& u, VectorXd* gradient,
                                    Eigen::SparseMatrix<double>& exact,
                                    Eigen::SparseMatrix<double>& projected) const {
  (void)evaluate(u, nullptr, &exact, false);
  return evaluate(u, gradient, &projected, true);
}

double LinearWall::evaluate(const VectorXd& u, VectorXd* gradient,
                            Eigen::SparseMatrix<double>* hessian, bool /*project_psd*/) const {
  const VectorXd Ku = s_.K * u;
  if (gradient) *gradient = Ku - s_.f;
  if (hessian) *hessian = s_.K;
  return 0.5 * u.dot(Ku) - s_.f.dot(u);
}

std::vector<EdgeNode> LinearWall::edge_nodes(const TetMesh& mesh,
                                             const std::vector<std::array<int, 2>>& edges) const {
  if (s_.free_index.size() == 3 * s_.node_rows.size()) return {};  // a DoF per vertex: P1
  return mid_edge_nodes(s_, mesh, edges);
}

double LinearWall::largest_strain(const TetMesh& mesh, const VectorXd& u) const {
  return contact::largest_strain(mesh, nodal(u)).small;
}

NeoHookeanWall::NeoHookeanWall(const TetMesh& mesh, fem::ElasticityProblem problem)
    : degree_(problem.options.degree),
      solver_(std::make_unique<fem::HyperelasticSolver>(mesh, std::move(problem))),
      dofs_(solver_->free_dofs()) {
  n_ = static_cast<int>(std::count_if(dofs_.free_index.begin(), dofs_.free_index.end(),
                                      [](int r) { return r >= 0; }));
}

std::vector<EdgeNode> NeoHookeanWall::edge_nodes(
    const TetMesh& mesh, const std::vector<std::array<int, 2>>& edges) const {
  if (degree_ < 2) return {};
  return mid_edge_nodes(dofs_, mesh, edges);
}

Eigen::VectorXd linear_field_rows(const WallPotential& wall, const TetMesh& mesh,
                                  const std::vector<Vec3>& nodal) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(wall.num_dofs());
  std::vector<char> set(static_cast<std::size_t>(wall.num_dofs()), 0);
  const auto put = [&](int row, double value) {
    if (row < 0) return;
    u[row] = value;
    set[static_cast<std::size_t>(row)] = 1;
  };
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    for (int c = 0; c < 3; ++c) put(wall.node_rows()[n][static_cast<std::size_t>(c)], nodal[n][c]);
  }
  for (const EdgeNode& e : wall.edge_nodes(mesh, unique_edges(mesh))) {
    const Vec3 middle =
        0.5 * (nodal[static_cast<std::size_t>(e.a)] + nodal[static_cast<std::size_t>(e.b)]);
    for (int c = 0; c < 3; ++c) put(e.rows[static_cast<std::size_t>(c)], middle[c]);
  }
  if (std::find(set.begin(), set.end(), 0) != set.end()) {
    throw std::logic_error(
        "linear_field_rows: a row of the wall is at no vertex and no edge middle");
  }
  return u;
}

std::vector<EdgeNode> mid_edge_nodes(const fem::FreeDisplacementSystem& system, const TetMesh& mesh,
                                     const std::vector<std::array<int, 2>>& edges) {
  const auto free_rows = static_cast<std::size_t>(std::count_if(
      system.free_index.begin(), system.free_index.end(), [](int r) { return r >= 0; }));
  if (system.row_points.size() != free_rows || system.row_components.size() != free_rows) {
    throw std::logic_error("mid_edge_nodes: the system's row points are not filled");
  }
  // The support points, each with its rows, sorted by x for a slab search.
  std::vector<int> order(system.row_points.size());
  std::iota(order.begin(), order.end(), 0);
  const auto lexicographic = [&](int i, int j) {
    const Vec3& p = system.row_points[static_cast<std::size_t>(i)];
    const Vec3& q = system.row_points[static_cast<std::size_t>(j)];
    return std::tie(p[0], p[1], p[2]) < std::tie(q[0], q[1], q[2]);
  };
  std::sort(order.begin(), order.end(), lexicographic);
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> rows;
  for (const int r : order) {
    const Vec3& p = system.row_points[static_cast<std::size_t>(r)];
    if (points.empty() || points.back() != p) {
      points.push_back(p);
      rows.push_back({-1, -1, -1});
    }
    rows.back()[static_cast<std::size_t>(system.row_components[static_cast<std::size_t>(r)])] = r;
  }
  std::vector<EdgeNode> out;
  for (const auto& [a, b] : edges) {
    const Vec3& pa = mesh.nodes[static_cast<std::size_t>(a)];
    const Vec3& pb = mesh.nodes[static_cast<std::size_t>(b)];
    const Vec3 middle = 0.5 * (pa + pb);
    const double reach = 0.25 * (pb - pa).norm();
    auto it = std::lower_bound(points.begin(), points.end(), middle[0] - reach,
                               [](const Vec3& p, double x) { return p[0] < x; });
    double best = reach;
    std::ptrdiff_t found = -1;
    for (; it != points.end() && (*it)[0] <= middle[0] + reach; ++it) {
      const double d = (*it - middle).norm();
      if (d < best) {
        best = d;
        found = it - points.begin();
      }
    }
    if (found < 0) continue;
    out.push_back(
        {a, b, points[static_cast<std::size_t>(found)], rows[static_cast<std::size_t>(found)]});
  }
  return out;
}

double NeoHookeanWall::evaluate(const VectorXd& u, VectorXd* gradient,
                                Eigen::SparseMatrix<double>* hessian, bool project_psd) const {
  using fem::FreeTangents;
  fem::FreeHyperelasticState s = solver_->free_state(u, !hessian      ? FreeTangents::none
                                                        : project_psd ? FreeTangents::projected
                                                                      : FreeTangents::exact);
  if (gradient) *gradient = std::move(s.gradient);
  if (hessian) *hessian = std::move(project_psd ? s.projected_tangent : s.tangent);
  return s.admissible ? s.energy : std::numeric_limits<double>::infinity();
}

double NeoHookeanWall::evaluate_both(const VectorXd& u, VectorXd* gradient,
                                     Eigen::SparseMatrix<double>& exact,
                                     Eigen::SparseMatrix<double>& projected) const {
  fem::FreeHyperelasticState s = solver_->free_state(u, fem::FreeTangents::both);
  if (gradient) *gradient = std::move(s.gradient);
  exact = std::move(s.tangent);
  projected = std::move(s.projected_tangent);
  return s.admissible ? s.energy : std::numeric_limits<double>::infinity();
}

double NeoHookeanWall::largest_strain(const TetMesh& /*mesh*/, const VectorXd& u) const {
  return solver_->free_state(u, fem::FreeTangents::none, true).max_abs_principal_strain;
}

namespace {

/// Per row, the rows of the same displacement component that share a cell with it.
std::vector<std::vector<int>> row_neighbours(const std::vector<std::vector<int>>& cells,
                                             const std::vector<int>& components, int rows) {
  std::vector<std::vector<int>> out(static_cast<std::size_t>(rows));
  for (const std::vector<int>& cell : cells) {
    for (const int a : cell) {
      for (const int b : cell) {
        if (a != b && components[a] == components[b]) out[a].push_back(b);
      }
    }
  }
  for (std::vector<int>& n : out) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return out;
}

/// Marks the unmarked neighbours of the marked rows.
void mark_one_ring(const std::vector<std::vector<int>>& neighbours, std::vector<char>& marked) {
  std::vector<int> ring;
  for (std::size_t r = 0; r < marked.size(); ++r) {
    if (!marked[r]) continue;
    for (const int b : neighbours[r]) {
      if (!marked[b]) ring.push_back(b);
    }
  }
  for (const int b : ring) marked[b] = 1;
}

}  // namespace

std::optional<VectorXd> NeoHookeanWall::untangled(const VectorXd& u, int max_passes) const {
  std::vector<int> bad = solver_->inverted_cells(u);
  if (bad.empty()) return u;
  const std::vector<std::vector<int>> cells = solver_->free_rows_per_cell();
  const std::vector<std::vector<int>> neighbours = row_neighbours(cells, dofs_.row_components, n_);
  constexpr int kSweeps = 10;  // Jacobi sweeps per pass
  VectorXd out = u;
  std::vector<char> smoothed(static_cast<std::size_t>(n_), 0);
  for (int pass = 0; pass < max_passes && !bad.empty(); ++pass) {
    for (const int c : bad) {
      for (const int r : cells[static_cast<std::size_t>(c)]) smoothed[r] = 1;
    }
    if (pass > 0) mark_one_ring(neighbours, smoothed);
    std::vector<int> region;
    for (std::size_t r = 0; r < smoothed.size(); ++r) {
      if (smoothed[r] && !neighbours[r].empty()) region.push_back(static_cast<int>(r));
    }
    for (int sweep = 0; sweep < kSweeps; ++sweep) {
      const VectorXd before = out;
      for (const int r : region) {
        double sum = 0.0;
        for (const int b : neighbours[r]) sum += before[b];
        out[r] = sum / static_cast<double>(neighbours[r].size());
      }
    }
    bad = solver_->inverted_cells(out);
  }
  if (!bad.empty()) return std::nullopt;
  return out;
}

Vec3 NeoHookeanWall::support_reaction(const VectorXd& u) const {
  std::vector<double> w(dofs_.free_index.size(), 0.0);
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (dofs_.free_index[i] >= 0) w[i] = u[dofs_.free_index[i]];
  }
  const std::vector<double> f = solver_->residual(w, 0.0);
  const std::vector<unsigned> component = solver_->dof_components();
  Vec3 r = Vec3::Zero();
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (dofs_.free_index[i] < 0 && component[i] < 3) r[component[i]] += f[i];
  }
  return r;
}

FormWall::FormWall(const msm::Form& form, VectorXd rest, std::vector<int> free_index,
                   std::vector<std::array<int, 3>> node_rows)
    : form_(form),
      rest_(std::move(rest)),
      free_index_(std::move(free_index)),
      node_rows_(std::move(node_rows)) {
  for (const int r : free_index_) n_ = std::max(n_, r + 1);
  rest_energy_ = form_.energy(rest_);
}

VectorXd FormWall::positions(const VectorXd& u) const {
  VectorXd x = rest_;
  for (std::size_t d = 0; d < free_index_.size(); ++d) {
    if (free_index_[d] >= 0) x[static_cast<Eigen::Index>(d)] += u[free_index_[d]];
  }
  return x;
}

double FormWall::evaluate(const VectorXd& u, VectorXd* gradient,
                          Eigen::SparseMatrix<double>* hessian, bool project_psd) const {
  const VectorXd x = positions(u);
  if (gradient) {
    VectorXd g;
    form_.gradient(x, g);
    gradient->setZero(n_);
    for (std::size_t d = 0; d < free_index_.size(); ++d) {
      if (free_index_[d] >= 0) (*gradient)[free_index_[d]] = g[static_cast<Eigen::Index>(d)];
    }
  }
  if (hessian) {
    Eigen::SparseMatrix<double> H;
    form_.hessian(x, H, project_psd);
    Triplets t;
    t.reserve(static_cast<std::size_t>(H.nonZeros()));
    for (Eigen::Index c = 0; c < H.outerSize(); ++c) {
      const int fc = free_index_[static_cast<std::size_t>(c)];
      if (fc < 0) continue;
      for (Eigen::SparseMatrix<double>::InnerIterator it(H, c); it; ++it) {
        const int fr = free_index_[static_cast<std::size_t>(it.row())];
        if (fr >= 0) t.emplace_back(fr, fc, it.value());
      }
    }
    hessian->resize(n_, n_);
    hessian->setFromTriplets(t.begin(), t.end());
  }
  return form_.energy(x) - rest_energy_;
}

TetMesh FormWall::carried_tets(const TetMesh& mesh) const {
  TetMesh carried = mesh;
  carried.tets.clear();
  for (const Tet& t : mesh.tets) {
    bool all = true;
    for (const int n : t) all = all && node_rows_[static_cast<std::size_t>(n)][0] >= 0;
    if (all) carried.tets.push_back(t);
  }
  return carried;
}

double FormWall::largest_strain(const TetMesh& mesh, const VectorXd& u) const {
  const TetMesh carried = carried_tets(mesh);
  if (carried.tets.empty()) return std::numeric_limits<double>::quiet_NaN();
  return contact::largest_strain(carried, nodal(u)).small;
}

std::optional<std::size_t> FormWall::inverted_tets(const TetMesh& mesh, const VectorXd& u) const {
  const TetMesh carried = carried_tets(mesh);
  if (carried.tets.empty()) return std::nullopt;
  return WallPotential::inverted_tets(carried, u);
}

Vec3 PotentialContactSolution::total_force_on_wall() const {
  Vec3 f = Vec3::Zero();
  for (std::size_t j = 0; j < force.size(); ++j) f += force[j] * direction[j];
  return f;
}

namespace {

using Clock = std::chrono::steady_clock;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Vec12 = Eigen::Matrix<double, 12, 1>;

/// The rows (in the coupled unknown z = (the rod's free dofs, the wall's rows)) of one contact
/// pair's twelve coordinates (its four points'); −1 where held or unused.
using PairRows = std::array<int, 12>;

/// One point of a contact pair: a wall candidate or a centreline node (−1: unused).
struct PairPoint {
  bool wall = false;
  int index = -1;
};

/// One contact pair and its gap's distance term d (g = d − r_w): a candidate against the nearest
/// segment of the centreline (points: the candidate, the segment's two ends), or the wire's tip
/// against a face of the wall (points: the tip, the face's three candidates).
struct Pair {
  int multiplier = 0;  ///< its λ̂'s index: the candidate's, or past them the face's
  std::array<PairPoint, 4> points;
  double distance = 0.0;
  Vec12 gradient = Vec12::Zero();  ///< ∂d/∂(the points' coordinates)
  Mat12 hessian = Mat12::Zero();   ///< when asked
};

/// The pieces of one Newton model (Coupled::evaluate).
struct Linearisation {
  Triplets base;
  std::vector<PairRows> rows;
  std::vector<Vec12> gap_gradient;
  std::vector<double> c;
  std::vector<int> multiplier;  ///< each pair's multiplier index
  std::vector<double> weight;   ///< each pair's curvature weight in base (curvature_weight)
};

/// a_jᵀ v over pair j's free rows (a_j its gap gradient).
double pair_dot(const Linearisation& lin, std::size_t j, const VectorXd& v) {
  double s = 0.0;
  for (int i = 0; i < 12; ++i) {
    if (lin.rows[j][i] >= 0) s += lin.gap_gradient[j][i] * v[lin.rows[j][i]];
  }
  return s;
}

/// v += s a_j over pair j's free rows.
void add_pair(const Linearisation& lin, std::size_t j, double s, VectorXd& v) {
  for (int i = 0; i < 12; ++i) {
    if (lin.rows[j][i] >= 0) v[lin.rows[j][i]] += s * lin.gap_gradient[j][i];
  }
}

/// The inner wall's triangles whose three nodes are all candidates (none for a mesh without the
/// group).
std::vector<Triangle> candidate_triangles(const TetMesh& mesh, const std::vector<int>& candidates) {
  std::vector<Triangle> out;
  const PhysicalGroup* inner = mesh.find_group(group_names::inner_wall, 2);
  if (inner == nullptr) return out;
  std::vector<char> is_candidate(mesh.nodes.size(), 0);
  for (const int c : candidates) is_candidate[static_cast<std::size_t>(c)] = 1;
  for (const Triangle& t : mesh.group_triangles(*inner)) {
    if (is_candidate[static_cast<std::size_t>(t[0])] &&
        is_candidate[static_cast<std::size_t>(t[1])] &&
        is_candidate[static_cast<std::size_t>(t[2])]) {
      out.push_back(t);
    }
  }
  return out;
}

/// The edges of `triangles`, each once (a < b).
std::vector<std::array<int, 2>> triangle_edges(const std::vector<Triangle>& triangles) {
  std::vector<std::array<int, 2>> edges;
  for (const Triangle& t : triangles) {
    for (int e = 0; e < 3; ++e) {
      const int a = t[static_cast<std::size_t>(e)], b = t[static_cast<std::size_t>((e + 1) % 3)];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

/// The tip's faces as candidate indices: each of `triangles` (mesh nodes; `index` maps a mesh
/// node to its candidate) whole, or split into four at its edges' middle nodes where it has all
/// three (`middle`: per edge (a < b) its middle node's candidate).
std::vector<std::array<int, 3>> candidate_faces(const std::vector<Triangle>& triangles,
                                                const std::vector<int>& index,
                                                const std::map<std::array<int, 2>, int>& middle) {
  std::vector<std::array<int, 3>> faces;
  for (const Triangle& t : triangles) {
    std::array<int, 3> v{}, m{};
    bool split = true;
    for (int e = 0; e < 3; ++e) {
      const int a = t[static_cast<std::size_t>(e)], b = t[static_cast<std::size_t>((e + 1) % 3)];
      v[static_cast<std::size_t>(e)] = index[static_cast<std::size_t>(a)];
      const auto it = middle.find({std::min(a, b), std::max(a, b)});
      split = split && it != middle.end();
      if (it != middle.end()) m[static_cast<std::size_t>(e)] = it->second;
    }
    if (!split) {
      faces.push_back(v);
      continue;
    }
    // m[e] is the middle of edge (v[e], v[e+1]).
    faces.push_back({v[0], m[0], m[2]});
    faces.push_back({m[0], v[1], m[1]});
    faces.push_back({m[2], m[1], v[2]});
    faces.push_back({m[0], m[1], m[2]});
  }
  return faces;
}

/// The coupled problem Π(z) and the bookkeeping between z, the rod's dofs and the wall's rows.
class Coupled {
 public:
  /// `mid_edges`: also the wall's nodes at the middles of the candidate faces' edges (P2). The
  /// contact stiffness k is set before the solve (set_stiffness).
  Coupled(msm::rods::Rod& rod, double radius, const WallPotential& wall, const TetMesh& mesh,
          const std::vector<int>& candidates, const VectorXd& start, bool mid_edges)
      : rod_(rod), r_(radius), wall_(wall), mesh_(mesh), x0_(start) {
    fixed_ = rod.clamp_fixed();
    rod_row_.assign(fixed_.size(), -1);
    for (std::size_t i = 0; i < fixed_.size(); ++i) {
      if (!fixed_[i]) rod_row_[i] = n_rod_++;
    }
    first_ = rod.layout().first_node;
    last_ = rod.layout().tip_node;
    std::vector<int> index(mesh.nodes.size(), -1);
    for (const int c : candidates) {
      if (c < 0 || c >= static_cast<int>(mesh.nodes.size())) {
        throw InputError("the contact candidate " + std::to_string(c) + " is not a mesh node");
      }
      index[static_cast<std::size_t>(c)] = static_cast<int>(rest_.size());
      rest_.push_back(mesh.nodes[static_cast<std::size_t>(c)]);
      rows_.push_back(wall.node_rows()[static_cast<std::size_t>(c)]);
      ends_.push_back({c, -1});
    }
    const std::vector<Triangle> triangles = candidate_triangles(mesh, candidates);
    std::map<std::array<int, 2>, int> middle;
    if (mid_edges) {
      for (const EdgeNode& e : wall.edge_nodes(mesh, triangle_edges(triangles))) {
        middle[{e.a, e.b}] = static_cast<int>(rest_.size());
        rest_.push_back(e.rest);
        rows_.push_back(e.rows);
        ends_.push_back({e.a, e.b});
      }
    }
    faces_ = candidate_faces(triangles, index, middle);
    multiplier_.assign(rest_.size() + faces_.size(), 0.0);
  }

  [[nodiscard]] int size() const { return n_rod_ + wall_.num_dofs(); }
  [[nodiscard]] double radius() const { return r_; }
  [[nodiscard]] double stiffness() const { return k_; }
  void set_stiffness(double k) { k_ = k; }
  /// Per candidate (mesh nodes, then mid-edge nodes) its x, y, z rows in the wall.
  [[nodiscard]] const std::vector<std::array<int, 3>>& candidate_rows() const { return rows_; }

  [[nodiscard]] VectorXd rod_dofs(const VectorXd& z) const {
    VectorXd x = x0_;
    for (std::size_t i = 0; i < rod_row_.size(); ++i) {
      if (rod_row_[i] >= 0) x[static_cast<Eigen::Index>(i)] = z[rod_row_[i]];
    }
    return x;
  }
  [[nodiscard]] VectorXd wall_rows(const VectorXd& z) const { return z.tail(wall_.num_dofs()); }
  [[nodiscard]] VectorXd pack(const VectorXd& x, const VectorXd& u) const {
    VectorXd z(size());
    for (std::size_t i = 0; i < rod_row_.size(); ++i) {
      if (rod_row_[i] >= 0) z[rod_row_[i]] = x[static_cast<Eigen::Index>(i)];
    }
    z.tail(wall_.num_dofs()) = u;
    return z;
  }

  /// Candidate j's position at wall displacement u.
  [[nodiscard]] Eigen::Vector3d position(int j, const VectorXd& u) const {
    Eigen::Vector3d p = rest_[static_cast<std::size_t>(j)];
    for (int c = 0; c < 3; ++c) {
      const int row = rows_[static_cast<std::size_t>(j)][c];
      if (row >= 0) p[c] += u[row];
    }
    return p;
  }

  /// Every pair within `band` of pressing (λ̂ − k(g − band) > 0): each candidate with its nearest
  /// segment, and the tip with each face of the wall (with the distance's Hessian when asked).
  [[nodiscard]] std::vector<Pair> pairs(const VectorXd& x, const VectorXd& u, bool with_hessian,
                                        double band = 0.0) const {
    // A cheap cull: the wire's bounding box grown by the radius and the multipliers' reach.
    Eigen::Vector3d lo = x.segment<3>(3 * first_), hi = lo;
    for (int i = first_; i <= last_; ++i) {
      lo = lo.cwiseMin(x.segment<3>(3 * i));
      hi = hi.cwiseMax(x.segment<3>(3 * i));
    }
    const double reach =
        r_ + band + (*std::max_element(multiplier_.begin(), multiplier_.end())) / k_;
    std::vector<Pair> out;
    for (int j = 0; j < static_cast<int>(rest_.size()); ++j) {
      const Eigen::Vector3d p = position(j, u);
      if ((p.array() < lo.array() - reach).any() || (p.array() > hi.array() + reach).any())
        continue;
      double best = std::numeric_limits<double>::infinity();
      int seg = first_;
      for (int i = first_; i < last_; ++i) {
        const Eigen::Vector3d a = x.segment<3>(3 * i), e = x.segment<3>(3 * (i + 1)) - a;
        const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
        const double d2 = (p - a - t * e).squaredNorm();
        if (d2 < best) {
          best = d2;
          seg = i;
        }
      }
      if (!(best > 0.0)) {
        throw std::runtime_error(
            "a wall node lies on the wire's centreline: the wire passed through the wall");
      }
      const double g = std::sqrt(best) - r_;
      if (!bears(j, g - band)) continue;
      const PointSegmentDistance d =
          point_segment_distance(p, x.segment<3>(3 * seg), x.segment<3>(3 * seg + 3), with_hessian);
      Pair pair{j, {{{true, j}, {false, seg}, {false, seg + 1}, {}}}, d.distance};
      pair.gradient.head<9>() = d.gradient;
      if (with_hessian) pair.hessian.topLeftCorner<9, 9>() = d.hessian;
      out.push_back(pair);
    }
    tip_pairs(x.segment<3>(3 * last_), u, with_hessian, reach, band, out);
    return out;
  }

  /// The tip's hemisphere against each face of the wall within `reach` of its centre, appended
  /// to `out` where within `band` of pressing.
  void tip_pairs(const Eigen::Vector3d& tip, const VectorXd& u, bool with_hessian, double reach,
                 double band, std::vector<Pair>& out) const {
    const auto offset = static_cast<int>(rest_.size());
    for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
      const auto& face = faces_[static_cast<std::size_t>(f)];
      const Eigen::Vector3d a = position(face[0], u), b = position(face[1], u),
                            c = position(face[2], u);
      const Eigen::Vector3d centre = (a + b + c) / 3.0;
      const double size = std::max({(a - centre).norm(), (b - centre).norm(), (c - centre).norm()});
      if ((tip - centre).norm() > size + reach) continue;
      const PointTriangleDistance d = point_triangle_distance(tip, a, b, c, with_hessian);
      if (!bears(offset + f, d.distance - r_ - band)) continue;
      out.push_back({offset + f,
                     {{{false, last_}, {true, face[0]}, {true, face[1]}, {true, face[2]}}},
                     d.distance,
                     d.gradient,
                     d.hessian});
    }
  }

  /// λ = max(0, λ̂ − k g).
  [[nodiscard]] double force_at(int j, double gap) const {
    return std::max(0.0, multiplier_[static_cast<std::size_t>(j)] - k_ * gap);
  }
  /// Whether pair j at `gap` enters Π, the forces and the residuals: where it presses, and
  /// wherever its multiplier is positive while the multipliers lead.
  [[nodiscard]] bool bears(int j, double gap) const {
    return force_at(j, gap) > 0.0 ||
           (multipliers_lead_ && multiplier_[static_cast<std::size_t>(j)] > 0.0);
  }
  /// The weight of pair j's curvature −∇²d in the Newton model: its multiplier while they lead
  /// (the Lagrangian's Hessian), else its force λ at the iterate (Π's Hessian).
  [[nodiscard]] double curvature_weight(int j, double lambda) const {
    return multipliers_lead_ ? multiplier_[static_cast<std::size_t>(j)] : lambda;
  }
  /// ψ(g) + λ̂²/(2k) = λ²/(2k): shifted by a constant so that it vanishes where the candidate
  /// is open (ψ' = −λ unchanged) and Π stays continuous as candidates open and close.
  [[nodiscard]] double contact_energy(int j, double gap) const {
    const double l = force_at(j, gap);
    return l * l / (2.0 * k_);
  }

  [[nodiscard]] PairRows pair_rows(const Pair& p) const {
    PairRows rows;
    rows.fill(-1);
    for (int k = 0; k < 4; ++k) {
      const PairPoint& point = p.points[static_cast<std::size_t>(k)];
      if (point.index < 0) continue;
      for (int c = 0; c < 3; ++c) {
        const auto i = static_cast<std::size_t>(point.index);
        const int wr = point.wall ? rows_[i][c] : -1;
        rows[3 * k + c] = point.wall ? (wr >= 0 ? n_rod_ + wr : -1)
                                     : rod_row_[3 * i + static_cast<std::size_t>(c)];
      }
    }
    return rows;
  }

  /// Π at z (+∞ where the wall is inadmissible).
  [[nodiscard]] double potential(const VectorXd& z) const {
    const VectorXd x = rod_dofs(z), u = wall_rows(z);
    const double w = wall_.evaluate(u, nullptr, nullptr);
    if (!std::isfinite(w)) return w;
    double pi = rod_.energy(x) + w;
    for (const Pair& p : pairs(x, u, false)) pi += contact_energy(p.multiplier, p.distance - r_);
    return pi;
  }

  /// ∇Π at z and, with `lin`, the Newton model's pieces: the rod's and the wall's Hessians and
  /// each bearing pair's curvature −w∇²d (w its curvature_weight; with `project`, the rod's and
  /// the wall's element blocks and those 12 × 12 blocks projected onto the PSD cone), and every
  /// pair within `band` of pressing with its gap's gradient, c = λ̂/k − g (pressed while
  /// c − ∇g·dz > 0 in the model) and its multiplier. With `project` and `exact_lin`, the exact
  /// model's pieces too, from the same pass over the wall's elements and the pairs.
  double evaluate(const VectorXd& z, VectorXd& gradient, Linearisation* lin, bool project,
                  double band = 0.0, Linearisation* exact_lin = nullptr) const {
    const VectorXd x = rod_dofs(z), u = wall_rows(z);
    VectorXd gw;
    Eigen::SparseMatrix<double> hw, hw_exact;
    const bool both = lin && project && exact_lin;
    const double w = both ? wall_.evaluate_both(u, &gw, hw_exact, hw)
                          : wall_.evaluate(u, &gw, lin ? &hw : nullptr, project);
    VectorXd gr;
    rod_.gradient(x, gr);
    gradient.setZero(size());
    for (std::size_t i = 0; i < rod_row_.size(); ++i) {
      if (rod_row_[i] >= 0) gradient[rod_row_[i]] = gr[static_cast<Eigen::Index>(i)];
    }
    gradient.tail(wall_.num_dofs()) = gw;
    if (lin) base_hessians(x, hw, project, *lin);
    if (both) base_hessians(x, hw_exact, false, *exact_lin);
    double pi = rod_.energy(x) + w;
    for (const Pair& p : pairs(x, u, lin != nullptr, lin ? band : 0.0)) {
      const double g = p.distance - r_;
      const double lambda = force_at(p.multiplier, g);
      const PairRows rows = pair_rows(p);
      if (lin) {
        lin->rows.push_back(rows);
        lin->gap_gradient.push_back(p.gradient);
        lin->c.push_back(multiplier_[static_cast<std::size_t>(p.multiplier)] / k_ - g);
        lin->multiplier.push_back(p.multiplier);
        lin->weight.push_back(curvature_weight(p.multiplier, lambda));
      }
      if (lambda > 0.0) {
        pi += contact_energy(p.multiplier, g);
        // ψ'(g) = −λ, ψ''(g) = k while λ > 0 (k∇d∇dᵀ is the model's, added per pair by the step).
        for (int a = 0; a < 12; ++a) {
          if (rows[a] >= 0) gradient[rows[a]] -= lambda * p.gradient[a];
        }
      }
      const double weight = curvature_weight(p.multiplier, lambda);
      if (!lin || weight <= 0.0) continue;
      const Mat12 h = -weight * p.hessian;
      add_block(lin->base, rows, project ? projected(h) : h);
      if (both) add_block(exact_lin->base, rows, h);
    }
    if (both) {  // the pairs' pieces are the same in both; the bases (the Hessians) are not
      Triplets exact_base = std::move(exact_lin->base), projected_base = std::move(lin->base);
      *exact_lin = *lin;
      exact_lin->base = std::move(exact_base);
      lin->base = std::move(projected_base);
    }
    return pi;
  }

  /// lin emptied, its base the rod's Hessian at x (projected with `project`) and the wall's hw.
  void base_hessians(const VectorXd& x, const Eigen::SparseMatrix<double>& hw, bool project,
                     Linearisation& lin) const {
    lin = {};
    Triplets& t = lin.base;
    Eigen::SparseMatrix<double> hr;
    rod_.hessian(x, hr, project);
    t.reserve(static_cast<std::size_t>(hr.nonZeros() + hw.nonZeros()));
    for (int c = 0; c < hr.outerSize(); ++c) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(hr, c); it; ++it) {
        const int a = rod_row_[static_cast<std::size_t>(it.row())];
        const int b = rod_row_[static_cast<std::size_t>(it.col())];
        if (a >= 0 && b >= 0) t.emplace_back(a, b, it.value());
      }
    }
    for (int c = 0; c < hw.outerSize(); ++c) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(hw, c); it; ++it) {
        t.emplace_back(n_rod_ + it.row(), n_rod_ + it.col(), it.value());
      }
    }
  }

  static void add_block(Triplets& t, const PairRows& rows, const Mat12& h) {
    for (int a = 0; a < 12; ++a) {
      for (int b = 0; b < 12; ++b) {
        if (rows[a] >= 0 && rows[b] >= 0) t.emplace_back(rows[a], rows[b], h(a, b));
      }
    }
  }

  /// The contact forces at z: on each pressed candidate (its pairs' shares summed) and on each
  /// centreline node. A point's share of a pair's force is λ ∂d/∂(its position): −ψ'(g)∇g.
  void forces(const VectorXd& z, PotentialContactSolution& out) const {
    const VectorXd x = rod_dofs(z), u = wall_rows(z);
    std::vector<Vec3> on_wall(rest_.size(), Vec3::Zero());
    out.force_on_wire.assign(x.size() / 3, Vec3::Zero());
    out.max_penetration = 0.0;
    for (const Pair& p : pairs(x, u, false)) {
      const double g = p.distance - r_;
      out.max_penetration = std::max(out.max_penetration, -g);
      const double lambda = multipliers_lead_ ? multiplier_[static_cast<std::size_t>(p.multiplier)]
                                              : force_at(p.multiplier, g);
      for (int k = 0; k < 4; ++k) {
        const PairPoint& point = p.points[static_cast<std::size_t>(k)];
        if (point.index < 0) continue;
        const Vec3 f = lambda * p.gradient.segment<3>(3 * k);
        (point.wall ? on_wall : out.force_on_wire)[static_cast<std::size_t>(point.index)] += f;
      }
    }
    // Per mesh node: a vertex candidate's force, and half of each mid-edge node's on its edges.
    std::map<int, Vec3> on_node;
    const auto add = [&on_node](int node, const Vec3& f) {
      on_node.try_emplace(node, Vec3::Zero()).first->second += f;
    };
    out.pressed_edge_nodes = 0;
    for (std::size_t j = 0; j < on_wall.size(); ++j) {
      if (!(on_wall[j].norm() > 0.0)) continue;
      const auto [a, b] = ends_[j];
      if (b < 0) {
        add(a, on_wall[j]);
      } else {
        add(a, 0.5 * on_wall[j]);
        add(b, 0.5 * on_wall[j]);
        ++out.pressed_edge_nodes;
      }
    }
    out.pressed.clear();
    out.force.clear();
    out.direction.clear();
    for (const auto& [node, force] : on_node) {
      const double f = force.norm();
      if (!(f > 0.0)) continue;
      out.pressed.push_back(node);
      out.force.push_back(f);
      out.direction.push_back(force / f);
    }
  }

  /// λ̂ ← λ at z (the augmented Lagrangian's first-order update); returns max |λ − λ̂|/k over
  /// the candidates (m): |g| where pressed, λ̂/k where a candidate opened.
  double update_multipliers(const VectorXd& z) {
    const VectorXd x = rod_dofs(z), u = wall_rows(z);
    std::vector<double> next(multiplier_.size(), 0.0);
    for (const Pair& p : pairs(x, u, false)) {
      next[static_cast<std::size_t>(p.multiplier)] = force_at(p.multiplier, p.distance - r_);
    }
    double change = 0.0;
    for (std::size_t j = 0; j < next.size(); ++j) {
      change = std::max(change, std::abs(next[j] - multiplier_[j]) / k_);
    }
    multiplier_ = std::move(next);
    return change;
  }

  /// Whether the multipliers are the contact forces (Alart–Curnier's steps), or estimates λ̂
  /// that Π's forces max(0, λ̂ − k g) follow (the augmented Lagrangian's).
  void set_multipliers_lead(bool on) { multipliers_lead_ = on; }
  [[nodiscard]] bool multipliers_lead() const { return multipliers_lead_; }

  /// Alart–Curnier's multipliers after a step α dz from the model `lin`: λ ← (1 − α)λ + α λ_model,
  /// λ_model = k max(0, c − a·dz) the model's force (0 for a pair it does not hold).
  void step_multipliers(const Linearisation& lin, const VectorXd& dz, double alpha) {
    std::vector<double> next(multiplier_.size());
    for (std::size_t j = 0; j < next.size(); ++j) next[j] = (1.0 - alpha) * multiplier_[j];
    for (std::size_t j = 0; j < lin.c.size(); ++j) {
      const double model = k_ * std::max(0.0, lin.c[j] - pair_dot(lin, j, dz));
      next[static_cast<std::size_t>(lin.multiplier[j])] += alpha * model;
    }
    multiplier_ = std::move(next);
  }

  /// Alart–Curnier's residuals at (z, λ) from ∇Π at z (`gradient`): the force balance
  /// ‖∇E − Σ λ_j ∇g_j‖ (N) and Signorini's conditions max_j |min(λ_j/k, g_j)| (m: a pressed pair's
  /// gap, a penetration).
  void multiplier_residual(const VectorXd& z, const VectorXd& gradient, double& force,
                           double& complementarity) const {
    const VectorXd x = rod_dofs(z), u = wall_rows(z);
    VectorXd r = gradient;
    complementarity = 0.0;
    std::vector<char> seen(multiplier_.size(), 0);
    for (const Pair& p : pairs(x, u, false)) {
      const double g = p.distance - r_;
      const double l = multiplier_[static_cast<std::size_t>(p.multiplier)];
      seen[static_cast<std::size_t>(p.multiplier)] = 1;
      const double diff = force_at(p.multiplier, g) - l;
      const PairRows rows = pair_rows(p);
      for (int a = 0; a < 12; ++a) {
        if (rows[a] >= 0) r[rows[a]] += diff * p.gradient[a];
      }
      complementarity = std::max(complementarity, std::abs(std::min(l / k_, g)));
    }
    for (std::size_t j = 0; j < multiplier_.size(); ++j) {
      if (!seen[j]) complementarity = std::max(complementarity, multiplier_[j] / k_);
    }
    force = r.norm();
  }

  /// Largest move of a centreline node or a candidate under the step dz.
  [[nodiscard]] double largest_move(const VectorXd& dz) const {
    double m = 0.0;
    for (int i = first_; i <= last_; ++i) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c) {
        const int row = rod_row_[static_cast<std::size_t>(3 * i + c)];
        if (row >= 0) v[c] = dz[row];
      }
      m = std::max(m, v.norm());
    }
    for (const auto& rows : rows_) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c) {
        if (rows[c] >= 0) v[c] = dz[n_rod_ + rows[c]];
      }
      m = std::max(m, v.norm());
    }
    return m;
  }

  void prepare(const VectorXd& z) { rod_.prepare(rod_dofs(z)); }

  /// Throws WireThroughWall ("the wire-wall potential <when>: <where it crosses><why>") if the
  /// centreline at z crosses the wall's inner surface (none for a mesh without that group).
  void require_inside_lumen(const VectorXd& z, const std::string& when,
                            const std::string& why) const {
    const PhysicalGroup* inner = mesh_.find_group(group_names::inner_wall, 2);
    if (inner == nullptr) return;
    const VectorXd x = rod_dofs(z);
    std::vector<Vec3> centreline;
    for (int i = first_; i <= last_; ++i) centreline.emplace_back(x.segment<3>(3 * i));
    const std::vector<Triangle> triangles = mesh_.group_triangles(*inner);
    if (const auto crossing =
            first_wall_crossing(mesh_, triangles, wall_.nodal(wall_rows(z)), centreline)) {
      throw WireThroughWall("the wire-wall potential " + when + ": " + describe(*crossing) + why,
                            std::move(centreline), crossing->point,
                            triangles[static_cast<std::size_t>(crossing->triangle)], wall_rows(z));
    }
  }

 private:
  static Mat12 projected(const Mat12& h) {
    const Eigen::SelfAdjointEigenSolver<Mat12> es(h);
    const Vec12 ev = es.eigenvalues().cwiseMax(0.0);
    return es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  }

  msm::rods::Rod& rod_;
  double r_;
  const WallPotential& wall_;
  const TetMesh& mesh_;
  double k_ = 0.0;
  VectorXd x0_;
  std::vector<char> fixed_;
  std::vector<int> rod_row_;
  int n_rod_ = 0;
  int first_ = 0, last_ = 0;
  /// Per candidate its mesh node {n, −1}, or a mid-edge node's edge {a, b}.
  std::vector<std::array<int, 2>> ends_;
  std::vector<Eigen::Vector3d> rest_;
  std::vector<std::array<int, 3>> rows_;
  std::vector<std::array<int, 3>> faces_;  ///< the wall's faces, as candidate indices
  std::vector<double> multiplier_;
  bool multipliers_lead_ = false;
};

/// k from the wall's stiffness at rest: `factor` × its largest diagonal entry on the candidates'
/// rows (`rows`).
double default_penalty(const WallPotential& wall, const std::vector<std::array<int, 3>>& rows,
                       double factor) {
  Eigen::SparseMatrix<double> h;
  VectorXd g;
  (void)wall.evaluate(VectorXd::Zero(wall.num_dofs()), &g, &h);
  const VectorXd diag = h.diagonal();
  double largest = 0.0;
  for (const auto& candidate : rows) {
    for (const int row : candidate) {
      if (row >= 0) largest = std::max(largest, diag[row]);
    }
  }
  return factor * largest;
}

/// The Newton steps' factor: one CHOLMOD solver over a solve, its matrices padded with explicit
/// zeros to the union of the patterns met so far, so the symbolic analysis (the fill-reducing
/// ordering) is redone only when a pair near contact brings a block not seen before, not at
/// every step as the zone moves.
class NewtonFactor {
 public:
  /// Factorises h (padded to the pattern). `regularise`: a matrix that is not positive definite
  /// is shifted until it is (msm::CholmodSolver::factorize); otherwise false for it.
  bool factorize(Eigen::SparseMatrix<double> h, bool regularise) {
    ++factorisations_;
    if (pattern_.rows() != h.rows()) {
      pattern_ = 0.0 * h;
    } else {
      Eigen::SparseMatrix<double> grown = pattern_ + 0.0 * h;
      if (grown.nonZeros() != pattern_.nonZeros()) pattern_ = std::move(grown);
      h = h + pattern_;
    }
    if (!regularise) return solver_.try_factorize(h);
    try {
      solver_.factorize(h);
    } catch (const std::runtime_error&) {
      return false;
    }
    return true;
  }
  [[nodiscard]] const msm::CholmodSolver& solver() const { return solver_; }
  [[nodiscard]] int factorisations() const { return factorisations_; }

 private:
  msm::CholmodSolver solver_;
  Eigen::SparseMatrix<double> pattern_;  ///< the union so far, every value zero
  int factorisations_ = 0;
};

/// The Newton model's matrix H(A) = B + Σ_{j∈A} k a_j a_jᵀ for the active sets A of one step's
/// passes: H(A₀) factorised once, a later set's pairs that differ from A₀ applied as rank-one
/// terms (+k entering, −k leaving; msm::LowRankUpdatedSolve), so a pass costs solves with the
/// factor, not a factorisation. Past most_changed() such pairs H(A) is factorised afresh.
class ModelMatrix {
 public:
  static constexpr std::size_t kFewestChanged = 64;
  static constexpr double kColumnBytes = 256e6;  ///< the kept columns A⁻¹u_j, dense

  /// `shift` μ ≥ 0: Levenberg–Marquardt's damping, B + μ diag(|B|) in place of B. `regularise`
  /// as NewtonFactor::factorize.
  ModelMatrix(const Coupled& p, const Linearisation& lin, NewtonFactor& factor, double shift,
              bool regularise)
      : p_(p), lin_(lin), factor_(factor), regularise_(regularise), base_(p.size(), p.size()) {
    base_.setFromTriplets(lin.base.begin(), lin.base.end());
    if (shift > 0.0) {
      for (int i = 0; i < base_.rows(); ++i) {
        double& d = base_.coeffRef(i, i);
        d += shift * std::abs(d);
      }
    }
  }

  [[nodiscard]] NewtonFactor& factor() const { return factor_; }

  /// H(active) v.
  [[nodiscard]] VectorXd product(const std::vector<char>& active, const VectorXd& v) const {
    VectorXd out = base_ * v;  // both triangles stored
    for (std::size_t j = 0; j < active.size(); ++j) {
      if (active[j]) add_pair(lin_, j, p_.stiffness() * pair_dot(lin_, j, v), out);
    }
    return out;
  }

  /// dz = H(active)⁻¹ rhs; false if H cannot be factorised.
  bool solve(const std::vector<char>& active, const VectorXd& rhs, VectorXd& dz) {
    std::vector<int> ids;
    std::vector<msm::SparseColumn> columns;
    std::vector<double> weights;
    for (std::size_t j = 0; j < active.size() && update_; ++j) {
      if (active[j] == factored_[j]) continue;
      ids.push_back(static_cast<int>(j));
      columns.push_back(column(j));
      weights.push_back(active[j] ? p_.stiffness() : -p_.stiffness());
    }
    if (!update_ || ids.size() > most_changed()) {
      if (!factorize(active)) return false;
      ids.clear();
      columns.clear();
      weights.clear();
    }
    try {
      dz = update_->solve(rhs, ids, columns, weights);
      // Woodbury's capacitance (±1/k + aᵀH₀⁻¹a, near-cancelling for a stiff k) costs digits:
      // two steps of iterative refinement on H(A)'s own product restore the direct solve's.
      for (int refinement = 0; refinement < 2 && !ids.empty(); ++refinement) {
        dz += update_->solve(rhs - product(active, dz), ids, columns, weights);
      }
    } catch (const std::runtime_error&) {  // the updated matrix is singular: factorise it
      if (ids.empty() || !factorize(active)) return false;
      dz = update_->solve(rhs, {}, {}, {});
    }
    return true;
  }

 private:
  bool factorize(const std::vector<char>& active) {
    Triplets t;
    t.reserve(81 * active.size());
    for (std::size_t j = 0; j < active.size(); ++j) {
      // Every near pair's block is in the pattern (zero while open), so a refactorisation of the
      // same step reuses the symbolic analysis.
      const auto& a = lin_.gap_gradient[j];
      Coupled::add_block(t, lin_.rows[j], (active[j] ? p_.stiffness() : 0.0) * a * a.transpose());
    }
    Eigen::SparseMatrix<double> near(p_.size(), p_.size());
    near.setFromTriplets(t.begin(), t.end());
    update_.reset();
    if (!factor_.factorize(base_ + near, regularise_)) return false;
    factored_ = active;
    update_ = std::make_unique<msm::LowRankUpdatedSolve>(factor_.solver());
    return true;
  }

  /// The changed pairs past which H(A) is factorised afresh: where their columns' solves with the
  /// kept factor (two sweeps of L, 4 flops per entry of L and column) would cost more than a
  /// factorisation (CHOLMOD's flop count), and at most as many columns as kColumnBytes hold;
  /// never fewer than kFewestChanged. (The arch's P1 wall, 33 k rows: ~126 columns; a P2 wall of
  /// 240 k rows is held to 133 by the memory.)
  [[nodiscard]] std::size_t most_changed() const {
    const msm::CholmodSolver& s = factor_.solver();
    const double by_cost = s.factor_flops() / (4.0 * std::max(s.factor_entries(), 1.0));
    const double by_memory = kColumnBytes / (8.0 * static_cast<double>(p_.size()));
    return std::max(kFewestChanged, static_cast<std::size_t>(std::min(by_cost, by_memory)));
  }

  /// Pair j's gap gradient a_j on its free rows.
  [[nodiscard]] msm::SparseColumn column(std::size_t j) const {
    msm::SparseColumn u;
    for (int i = 0; i < 12; ++i) {
      if (lin_.rows[j][i] < 0) continue;
      u.rows.push_back(lin_.rows[j][i]);
      u.values.push_back(lin_.gap_gradient[j][i]);
    }
    return u;
  }

  const Coupled& p_;
  const Linearisation& lin_;
  NewtonFactor& factor_;
  bool regularise_;
  Eigen::SparseMatrix<double> base_;
  std::vector<char> factored_;
  std::unique_ptr<msm::LowRankUpdatedSolve> update_;
};

/// The gradient at dz = 0 of the Newton model's quadratic piece for the active set A:
/// ∇Π without the pressed pairs' −λ∇g, plus −k c_j a_j for each pair of A.
VectorXd model_gradient(const Coupled& p, const Linearisation& lin, const VectorXd& gradient,
                        const std::vector<char>& active) {
  VectorXd out = gradient;
  for (std::size_t j = 0; j < lin.c.size(); ++j) {
    const double pressed = lin.c[j] > 0.0 ? 1.0 : 0.0;
    const double in_model = active[j] ? 1.0 : 0.0;
    if (pressed != in_model) add_pair(lin, j, p.stiffness() * lin.c[j] * (pressed - in_model), out);
  }
  return out;
}

/// The Newton step: the minimiser of the model ½dzᵀH dz + ∇Πᵀdz in which every pair near
/// contact keeps its piecewise penalty of the linearised gap, k/2 max(0, c − ∇g·dz)², found by
/// an active-set iteration on H's matrices: a wire about to touch is stopped by the wall within
/// the step instead of passing it in the model. `active` ends as the step's pressed pairs (its
/// model's quadratic piece). false if H cannot be factorised.
bool newton_step(const Coupled& p, const Linearisation& lin, const VectorXd& gradient,
                 ModelMatrix& H, VectorXd& dz, std::vector<char>& active) {
  const std::size_t m = lin.c.size();
  std::vector<char> next(m);
  active.assign(m, 0);
  // A pair whose curvature is in the matrix starts pressed: its −λ∇²d without its k a aᵀ would
  // make the model indefinite (Alart–Curnier's multipliers outlive a gap the last step opened).
  for (std::size_t j = 0; j < m; ++j) active[j] = lin.c[j] > 0.0 || lin.weight[j] > 0.0;
  for (int pass = 0; pass < 20; ++pass) {
    if (!H.solve(active, -model_gradient(p, lin, gradient, active), dz)) return false;
    for (std::size_t j = 0; j < m; ++j) next[j] = lin.c[j] - pair_dot(lin, j, dz) > 0.0;
    if (next == active) break;
    active = next;
  }
  return true;
}

struct NewtonOutcome {
  bool converged = false;
  int iterations = 0;
  int factorisations = 0;
  double residual = 0.0;
  std::string reason;
};

/// What the last Newton steps needed, for a progress line on long solves: every kEvery steps, or
/// sooner once kSeconds have passed (a P2 wall's step takes ~20 s: 25 steps would be minutes of
/// silence).
struct RecentSteps {
  static constexpr int kEvery = 25;
  static constexpr double kSeconds = 60.0;
  int steps = 0;      ///< since the last line
  int projected = 0;  ///< steps on the PSD-projected model (the exact one not factorisable)
  int curvature = 0;  ///< of those, extended to the trust region's boundary by the exact model
  int steepest = 0;   ///< steps that fell back to steepest descent
  int capped = 0;     ///< steps cut to the largest move
  double move = 0.0;  ///< the steps' node moves summed, r_w
  Clock::time_point since = Clock::now();  ///< the last line
  [[nodiscard]] bool due() const {
    return steps >= kEvery ||
           (steps > 0 && std::chrono::duration<double>(Clock::now() - since).count() >= kSeconds);
  }
  void report(std::ostream& log, int step, const NewtonOutcome& out, double shift) {
    log << "potential contact:   step " << step << ", residual " << out.residual << " N, "
        << out.factorisations << " factorisations; the last " << steps << " steps: " << projected
        << " on the PSD-projected Hessian (" << curvature
        << " extended to the boundary by the exact curvature), " << steepest
        << " steepest descent, " << capped << " capped at the largest move, mean move "
        << move / steps << " r_w"
        << (shift > 0.0 ? ", Levenberg–Marquardt μ " + std::to_string(shift) : std::string())
        << std::endl;
    *this = {};
  }
};

/// A search direction and what it was.
struct Direction {
  VectorXd dz;
  bool exact = false;  ///< Newton's step on the exact model
  /// On the projected model, extended by Steihaug's CG on the exact one: its P-norm and whether
  /// it ended on the trust region's boundary (0 and false otherwise).
  double steihaug_length = 0.0;
  bool steihaug_boundary = false;
};

/// Where the exact model is indefinite, the projected model's step dz (its matrix Hp factorised
/// for the active set A) extended by Steihaug–Toint CG on the exact model's quadratic piece for
/// A, preconditioned by Hp, within ‖d‖_Hp ≤ max(Δ, ‖dz‖_Hp) (msm/solvers/steihaug.hpp): CG's first
/// iterate is dz itself, so the step lowers the exact model at least as much, and a direction of
/// negative curvature is followed to the boundary. Near a saddle of Π, where Π falls along a
/// direction the per-element projection clamps to zero curvature, projected steps shrink to
/// 1e-2–1e-4 r_w and Newton stalls; the exact curvature leaves it. Keeps dz if the extended step
/// is not a descent direction of Π.
void extend_by_exact_curvature(const Coupled& p, const Linearisation& exact_lin, const VectorXd& g,
                               ModelMatrix& Hp, const std::vector<char>& active, double radius,
                               Direction& d) {
  const ModelMatrix H(p, exact_lin, Hp.factor(), 0.0, false);  // products only
  const double own = std::sqrt(std::max(d.dz.dot(Hp.product(active, d.dz)), 0.0));
  bool solved = true;
  const msm::SteihaugStep step = msm::steihaug_cg(
      [&](const VectorXd& v, VectorXd& out) { out = H.product(active, v); },
      [&](const VectorXd& v, VectorXd& out) { out = Hp.product(active, v); },
      [&](const VectorXd& r, VectorXd& out) { solved = Hp.solve(active, r, out) && solved; },
      model_gradient(p, exact_lin, g, active), std::max(radius, own), 0.1, 20);
  if (!solved || !(g.dot(step.d) < 0.0) || !step.d.allFinite()) return;
  d.dz = step.d;
  d.steihaug_length = std::sqrt(std::max(step.d.dot(Hp.product(active, step.d)), 0.0));
  d.steihaug_boundary = step.boundary;
}

/// The step from z: Newton's on the exact model where it is positive definite, else on the
/// PSD-projected one extended along the exact model's curvature (extend_by_exact_curvature; the
/// projected model shifted if need be: a shift of the exact, indefinite model costs a
/// factorisation per try and gives no better a step), else steepest descent of length r_w. `lin`
/// holds the linearisation at z: the exact one when `exact`, else the projected one with the
/// exact one in `exact_lin`. `radius`: the trust region of the extension (0: none yet).
Direction search_direction(const Coupled& p, const VectorXd& z, const VectorXd& g,
                           Linearisation& lin, Linearisation& exact_lin, bool exact, double band,
                           double shift, double radius, NewtonFactor& factor,
                           msm::ExactBackoff& backoff, RecentSteps& recent) {
  Direction d;
  std::vector<char> active;
  if (exact) {
    ModelMatrix H(p, lin, factor, shift, false);
    d.exact = newton_step(p, lin, g, H, d.dz, active) && g.dot(d.dz) < 0.0;
    backoff.record(d.exact);
    if (d.exact) return d;
  }
  ++recent.projected;
  if (exact) {
    exact_lin = std::move(lin);
    VectorXd same;
    (void)p.evaluate(z, same, &lin, true, band);
  }
  ModelMatrix Hp(p, lin, factor, shift, true);
  if (newton_step(p, lin, g, Hp, d.dz, active) && g.dot(d.dz) < 0.0) {
    extend_by_exact_curvature(p, exact_lin, g, Hp, active, radius, d);
    recent.curvature += d.steihaug_boundary;
    return d;
  }
  ++recent.steepest;
  d.dz = -g * (p.radius() / std::max(g.norm(), 1e-300));
  return d;
}

/// The accepted step length along dz from z (Π(z) = pi, ∇Π(z) = g), at most alpha0, with the
/// point reached in `trial`; 0 if none is found, `inverted` then counting the trials whose wall
/// had an inverted element (Π = +∞). Armijo's condition on Π first. Near the solution the
/// decrease a step makes can fall below the energy's round-off (a neo-Hookean Ψ at small strain
/// is a difference of O(ε) terms, its value O(ε²)); if no step passes, a step is accepted when it
/// lowers ‖∇Π‖ instead.
double line_search(const Coupled& p, const VectorXd& z, const VectorXd& dz, double pi,
                   const VectorXd& g, double alpha0, VectorXd& trial, int& inverted) {
  const double slope = g.dot(dz);
  double alpha = alpha0;
  for (int ls = 0; ls < 12; ++ls, alpha *= 0.5) {
    trial = z + alpha * dz;
    const double next = p.potential(trial);
    inverted += !std::isfinite(next);
    if (std::isfinite(next) && next <= pi + 1e-4 * alpha * slope) return alpha;
  }
  const double residual = g.norm();
  VectorXd g_trial;
  alpha = alpha0;
  for (int ls = 0; ls < 30; ++ls, alpha *= 0.5) {
    trial = z + alpha * dz;
    if (std::isfinite(p.evaluate(trial, g_trial, nullptr, false)) &&
        g_trial.norm() < (1.0 - 1e-4 * alpha) * residual) {
      return alpha;
    }
  }
  return 0.0;
}

/// What an iterate leaves to balance: the force balance's residual (N; ‖∇Π‖, or
/// ‖∇E − Σ λ_j∇g_j‖ while the multipliers lead) and Signorini's (m; Coupled::multiplier_residual).
struct Balance {
  double residual = 0.0;
  double complementarity = 0.0;
};

/// Alart–Curnier's bookkeeping over one minimise: which forces lead (the multipliers, or Π's for
/// held multipliers), what is left to balance, and the fall-back to the augmented Lagrangian's
/// rounds after kPatience full-length Newton steps without halving the residual (the end-on push
/// on a faceted block, whose tip bears on faces that share an edge). Steps cut to the largest
/// move or by the line search do not count: far from the solution the residual need not fall.
class MultiplierSteps {
 public:
  static constexpr int kPatience = 12;

  /// `on`: Alart–Curnier's law, set false where it stalls. `floor`: the residual at which a
  /// Newton step on Π stalls by round-off (Π's minimiser for the held multipliers).
  MultiplierSteps(Coupled& p, bool& on, const PotentialContactOptions& o, double floor)
      : p_(p), on_(on), o_(o), floor_(floor) {
    p_.set_multipliers_lead(on_);
  }

  /// The balance at z, whose ∇Π `evaluate` puts in g (called again when the multipliers or the
  /// forces that lead change: at Π's minimiser for held multipliers they take its forces, the
  /// augmented Lagrangian's update, and lead again).
  Balance at(const VectorXd& z, const VectorXd& g, int step,
             const std::function<void()>& evaluate) {
    Balance b{g.norm()};
    if (!on_) return b;
    if (!p_.multipliers_lead() && b.residual <= floor_) {
      (void)p_.update_multipliers(z);
      p_.set_multipliers_lead(true);
      evaluate();
    }
    if (p_.multipliers_lead()) p_.multiplier_residual(z, g, b.residual, b.complementarity);
    const double target = o_.tolerance * o_.force_scale;
    if (b.residual <= target && b.complementarity <= o_.gap_tolerance) return b;
    if (p_.multipliers_lead() && b.residual < 0.5 * best_) {
      best_ = b.residual;
      stalled_ = 0;
      return b;
    }
    if (last_step_full_) ++stalled_;
    if (stalled_ <= kPatience) return b;
    on_ = false;
    if (o_.log) {
      *o_.log << "potential contact: Alart-Curnier stalled at step " << step << " (residual "
              << best_ << " N); on by augmented-Lagrangian rounds" << std::endl;
    }
    p_.set_multipliers_lead(false);
    evaluate();
    return {g.norm()};
  }

  /// After a step α dz on the model `lin`: Alart–Curnier's update where the model's forces are
  /// an estimate (`model_holds`): a step of the exact model, or one of the projected model (its
  /// curvature clipped, its gaps' linearisation the same) that the line search took whole inside
  /// its trust region. After a projected step the line search cut, or one that Steihaug's CG took
  /// to the trust region's boundary (up to a few r_w, accepted at α ~ 1e-3), the model's forces
  /// at the step's end are far from the contact's: the multipliers are held (λ̂) and Π's forces
  /// lead until the next such step or Π's minimiser for them.
  void after_step(const Linearisation& lin, const VectorXd& dz, double alpha, bool model_holds) {
    last_step_full_ = alpha == 1.0;
    if (!on_) return;
    if (model_holds) p_.step_multipliers(lin, dz, alpha);
    p_.set_multipliers_lead(model_holds);
  }

 private:
  Coupled& p_;
  bool& on_;
  const PotentialContactOptions& o_;
  double floor_;
  double best_ = std::numeric_limits<double>::infinity();
  int stalled_ = 0;
  bool last_step_full_ = false;
};

/// Newton's method from z (left at the last accepted iterate): on (z, λ) while `alart_curnier`
/// (set false where it stalls, MultiplierSteps), else on Π for the held multipliers.
NewtonOutcome minimise(Coupled& p, VectorXd& z, const PotentialContactOptions& o,
                       NewtonFactor& factor, bool& alart_curnier) {
  NewtonOutcome out;
  const int factorisations_before = factor.factorisations();
  VectorXd g, dz, trial;
  Linearisation lin, exact_lin;
  const double target = o.tolerance * o.force_scale;
  const double band = o.max_move * p.radius();
  RecentSteps recent;
  double shift = 0.0;  // Levenberg–Marquardt's μ (damped_newton)
  double radius = 0.0;  // the trust region of the steps extended by the exact curvature
  // Where the exact model was indefinite, the next 1, 2, 4 … 8 steps go to the projected one.
  msm::ExactBackoff backoff(8);
  // Where round-off keeps ‖∇Π‖ above the target (a stiff wall's K u, a neo-Hookean energy's
  // O(ε²) value), a Newton step that stalls there is at Π's minimiser.
  const double floor = 1e3 * target;
  MultiplierSteps multipliers(p, alart_curnier, o, floor);
  for (int it = 0; it <= o.max_newton; ++it) {
    const bool exact = backoff.try_exact();
    double pi = 0.0;
    // A projected step also needs the exact model (extend_by_exact_curvature): one pass.
    const auto evaluate = [&] { pi = p.evaluate(z, g, &lin, !exact, band, &exact_lin); };
    evaluate();
    const Balance b = multipliers.at(z, g, it, evaluate);
    out.residual = b.residual;
    out.iterations = it;
    if (b.residual <= target && b.complementarity <= o.gap_tolerance) {
      out.converged = true;
      return out;
    }
    const bool at_floor = b.residual <= floor && b.complementarity <= o.gap_tolerance;
    if (it == o.max_newton) break;
    if (o.log && recent.due()) recent.report(*o.log, it, out, shift);
    const Direction d = search_direction(p, z, g, lin, exact_lin, exact, band, shift, radius,
                                         factor, backoff, recent);
    dz = d.dz;
    out.factorisations = factor.factorisations() - factorisations_before;
    const double move = p.largest_move(dz);
    const double alpha0 = std::min(1.0, o.max_move * p.radius() / std::max(move, 1e-300));
    int inverted = 0;
    const double alpha = line_search(p, z, dz, pi, g, alpha0, trial, inverted);
    if (alpha == 0.0) {
      out.converged = at_floor;
      if (!out.converged) {
        out.reason = "the line search found no decrease of the potential (" +
                     std::to_string(inverted) + " of its 12 trial steps inverted a wall element)";
      }
      return out;
    }
    if (d.steihaug_length > 0.0) {
      // The trust region (Nocedal & Wright §4.1, judged by the line search): the length the line
      // search accepted after a cut step, twice it after a full step to the boundary.
      const double accepted = alpha * d.steihaug_length;
      radius = alpha < alpha0 ? accepted : d.steihaug_boundary ? 2.0 * accepted : radius;
    }
    if (o.damped_newton) {
      // Levenberg–Marquardt's update of μ (Nocedal & Wright §10.3): a step the line search had to
      // cut was longer than the model can be trusted for; a full one says it can be trusted more.
      shift = alpha < alpha0 ? std::max(10.0 * shift, 1e-4) : (shift < 1e-7 ? 0.0 : 0.1 * shift);
    }
    multipliers.after_step(lin, dz, alpha, d.exact || (alpha == alpha0 && !d.steihaug_boundary));
    z = trial;
    p.prepare(z);
    // A centreline through the wall (between its nodes) does not come back: every node's gap is
    // open again on the far side. Stop there rather than converge outside the lumen.
    p.require_inside_lumen(z, "stopped after Newton step " + std::to_string(it + 1),
                           std::string(": ") + kPassedBetweenNodes);
    ++recent.steps;
    recent.capped += alpha0 < 1.0 && alpha == alpha0;
    recent.move += alpha * move / p.radius();
    // A stiff wall's forces (K u with K up to ~1e6 N/m) floor ‖∇Π‖ above the target by round-off:
    // a step that moves nothing by 1e-12 r_w ends the iteration there.
    if (alpha * move <= 1e-12 * p.radius() && at_floor) {
      out.converged = true;
      return out;
    }
  }
  out.reason = "Newton did not converge in " + std::to_string(o.max_newton) + " steps";
  return out;
}

}  // namespace

std::vector<double> continuation_rungs(double first, double ratio, double target) {
  std::vector<double> rungs;
  if (target > first) {
    const int n = static_cast<int>(std::ceil(std::log(target / first) / std::log(ratio) - 1e-9));
    for (int k = n; k >= 1; --k) rungs.push_back(target / std::pow(ratio, k));
  }
  rungs.push_back(target);
  return rungs;
}

PotentialContactSolution solve_wire_wall_potential(msm::rods::Rod& rod, double radius,
                                                   const WallPotential& wall, const TetMesh& mesh,
                                                   const std::vector<int>& candidates,
                                                   const VectorXd& start,
                                                   const PotentialContactOptions& options,
                                                   const VectorXd& wall_start) {
  const auto t0 = Clock::now();
  if (rod.constraints() != nullptr) {
    throw InputError(
        "the wire-wall potential takes a rod without equality constraints (DER), not CORDE");
  }
  if (!(radius > 0.0)) throw InputError("the wire's radius must be positive");
  if (start.size() != rod.num_dofs()) throw InputError("the wire's start has the wrong size");
  if (wall_start.size() != 0 && wall_start.size() != wall.num_dofs()) {
    throw InputError("the wall's start has " + std::to_string(wall_start.size()) +
                     " rows; expected " + std::to_string(wall.num_dofs()) + " (or none: at rest)");
  }
  Coupled problem(rod, radius, wall, mesh, candidates, start, options.mid_edge_candidates);
  const double k = options.penalty_stiffness > 0.0
                       ? options.penalty_stiffness
                       : default_penalty(wall, problem.candidate_rows(), options.penalty_factor);
  problem.set_stiffness(k);
  rod.prepare(start);
  VectorXd z =
      problem.pack(start, wall_start.size() != 0 ? wall_start : VectorXd::Zero(wall.num_dofs()));
  if (!std::isfinite(wall.evaluate(problem.wall_rows(z), nullptr, nullptr))) {
    // Newton's line search could not leave it: every trial near an inverted start is inverted.
    throw InputError(
        "the wire-wall potential cannot start from a wall that inverts an element "
        "(its energy is infinite there)");
  }
  problem.require_inside_lumen(z, "cannot start outside the lumen", " in the start it was given");
  PotentialContactSolution out;
  out.penalty_stiffness = k;
  bool alart_curnier = options.law == ContactLaw::alart_curnier;
  const int rounds = options.law == ContactLaw::penalty ? 1 : options.max_rounds;
  NewtonFactor factor;
  for (int round = 1; round <= rounds; ++round) {
    const NewtonOutcome n = minimise(problem, z, options, factor, alart_curnier);
    out.newton_iterations += n.iterations;
    out.factorisations += n.factorisations;
    out.rounds = round;
    out.residual = n.residual;
    problem.forces(z, out);
    if (options.log) {
      *options.log << "potential contact: round " << round << ", " << n.iterations
                   << " Newton steps, " << n.factorisations << " factorisations ("
                   << factor.solver().numeric_factorisations() << " by CHOLMOD so far, "
                   << factor.solver().symbolic_analyses() << " analyses, "
                   << factor.solver().factorisation_seconds() << " s), residual " << n.residual
                   << " N, " << out.pressed.size() << " pressed, force "
                   << out.total_force_on_wall().norm() * 1e3 << " mN, penetration "
                   << out.max_penetration << " m" << std::endl;
    }
    if (!n.converged) {
      std::ostringstream m;
      m << "the wire-wall potential did not converge in round " << round << ": " << n.reason
        << " (residual " << n.residual << " N, " << out.pressed.size() << " pressed, penetration "
        << out.max_penetration << " m)";
      throw std::runtime_error(m.str());
    }
    if (out.pressed.empty()) {
      throw std::runtime_error(
          "no wall node bears on the wire: it passed between the wall's nodes (refine the wall "
          "where the wire bears)");
    }
    if (options.law == ContactLaw::penalty || alart_curnier) break;
    const double change = problem.update_multipliers(z);
    if (change <= options.gap_tolerance) break;
    if (round == rounds) {
      std::ostringstream m;
      m << "the wire-wall potential's multipliers did not converge in " << rounds
        << " rounds (their last change " << change << " m over k, penetration "
        << out.max_penetration << " m)";
      throw std::runtime_error(m.str());
    }
  }
  out.x = problem.rod_dofs(z);
  out.u = problem.wall_rows(z);
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::vector<std::pair<int, Vec3>> potential_clamp_forces(const msm::rods::Rod& rod,
                                                        const PotentialContactSolution& s) {
  VectorXd g;
  rod.gradient(s.x, g);
  // The contact's share of ∇Π on the wire: −(the wall's contact force on each node).
  for (std::size_t n = 0; n < s.force_on_wire.size(); ++n) {
    g.segment<3>(3 * static_cast<Eigen::Index>(n)) -= s.force_on_wire[n];
  }
  const std::vector<char> fixed = rod.clamp_fixed();
  std::vector<std::pair<int, Vec3>> out;
  for (int n = 0; n < rod.num_nodes(); ++n) {
    Vec3 f = Vec3::Zero();
    bool held = false;
    for (int c = 0; c < 3; ++c) {
      if (!fixed[static_cast<std::size_t>(3 * n + c)]) continue;
      f[c] = g[3 * n + c];
      held = true;
    }
    if (held) out.emplace_back(n, f);
  }
  return out;
}

Vec3 potential_clamp_reaction(const msm::rods::Rod& rod, const PotentialContactSolution& s) {
  Vec3 r = Vec3::Zero();
  for (const auto& [node, f] : potential_clamp_forces(rod, s)) r += f;
  return r;
}

}  // namespace vessel::contact
