/// What rank 0 sends each rank of the distributed solver: its tets and their ghost layer, the
/// loads and supports on them and the evaluation points it owns (detail/rank_part.hpp), so that
/// only rank 0 ever holds the whole mesh.
#include <algorithm>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "fem_reference/detail/amg.hpp"
#include "fem_reference/detail/byte_buffer.hpp"
#include "fem_reference/detail/constraints.hpp"
#include "fem_reference/detail/rank_part.hpp"
#include "fem_reference/detail/tet_locator.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem::detail {

void run_on_root(MPI_Comm comm, const std::function<void()>& work) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::exception_ptr failure;
  std::vector<char> message;
  if (rank == 0) {
    try {
      work();
    } catch (const std::exception& e) {
      failure = std::current_exception();
      const std::string what = e.what();
      message.assign(what.begin(), what.end());
    } catch (...) {
      failure = std::current_exception();
      const std::string what = "rank 0 failed";
      message.assign(what.begin(), what.end());
    }
  }
  int failed = failure ? 1 : 0;
  MPI_Bcast(&failed, 1, MPI_INT, 0, comm);
  if (!failed) return;
  broadcast_bytes(message, 0, comm);
  if (rank == 0) std::rethrow_exception(failure);
  throw InputError(std::string(message.begin(), message.end()));
}

namespace {

constexpr int kPartTag = 3201;
static_assert(std::is_trivially_copyable_v<SolverOptions>);
static_assert(std::is_trivially_copyable_v<Material>);
// Vec3 (an Eigen fixed-size vector) and the PODs holding it are sent byte-wise too, as the mesh
// broadcast sends nodes: plain doubles, the same binary on every rank.

/// What rank 0 found in the whole mesh before cutting: the node of each point constraint and
/// the tet of each evaluation point.
struct Located {
  std::vector<int> constraint_node;
  std::vector<int> point_tet;
};

Located locate(const TetMesh& mesh, const ElasticityProblem& p, const DistributedOptions& o) {
  Located l;
  l.constraint_node = point_constraint_nodes(mesh, p.point_constraints);
  if (o.evaluation_points.empty()) return l;
  const TetLocator locator(mesh);
  for (const Vec3& x : o.evaluation_points) {
    const int t = locator.find(x, o.outside_tolerance);
    if (t < 0) {
      std::ostringstream m;
      m << "point (" << x.x() * 1e3 << ", " << x.y() * 1e3 << ", " << x.z() * 1e3
        << ") mm is outside the FEM mesh: expected a point inside the vessel wall";
      throw InputError(m.str());
    }
    l.point_tet.push_back(t);
  }
  return l;
}

/// Local index of global tet `t` in the ascending `global_tet` (−1 if absent).
int local_tet(const std::vector<int>& global_tet, int t) {
  const auto it = std::lower_bound(global_tet.begin(), global_tet.end(), t);
  return it != global_tet.end() && *it == t ? static_cast<int>(it - global_tet.begin()) : -1;
}

/// Rank `r`'s tets (owned, and every tet sharing a node with an owned one: deal.II's ghost layer
/// of a fully distributed triangulation), nodes, triangles and groups. `node_local` and
/// `triangle_local` are −1-filled scratch of the whole mesh's sizes, filled for this part.
void cut_mesh(const TetMesh& mesh, const std::vector<unsigned>& owner, unsigned r, RankPart& part,
              std::vector<int>& node_local, std::vector<int>& triangle_local) {
  std::vector<char> near(mesh.nodes.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (owner[t] == r)
      for (int n : mesh.tets[t]) near[static_cast<std::size_t>(n)] = 1;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    if (std::any_of(tet.begin(), tet.end(),
                    [&](int n) { return near[static_cast<std::size_t>(n)]; }))
      part.global_tet.push_back(static_cast<int>(t));
  }
  for (int t : part.global_tet)
    for (int n : mesh.tets[static_cast<std::size_t>(t)])
      node_local[static_cast<std::size_t>(n)] = 0;
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (node_local[n] < 0) continue;
    node_local[n] = static_cast<int>(part.global_node.size());
    part.global_node.push_back(static_cast<int>(n));
    part.mesh.nodes.push_back(mesh.nodes[n]);
  }
  const auto local = [&](int n) { return node_local[static_cast<std::size_t>(n)]; };
  for (int t : part.global_tet) {
    const Tet& g = mesh.tets[static_cast<std::size_t>(t)];
    part.mesh.tets.push_back({local(g[0]), local(g[1]), local(g[2]), local(g[3])});
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& g = mesh.triangles[t];
    if (local(g[0]) < 0 || local(g[1]) < 0 || local(g[2]) < 0) continue;
    triangle_local[t] = static_cast<int>(part.mesh.triangles.size());
    part.mesh.triangles.push_back({local(g[0]), local(g[1]), local(g[2])});
  }
  for (const PhysicalGroup& g : mesh.groups) {
    PhysicalGroup mine{g.name, g.dim, g.tag, {}};
    for (int e : g.elements) {
      const int l = g.dim == 3 ? local_tet(part.global_tet, e)
                               : (g.dim == 2 ? triangle_local[static_cast<std::size_t>(e)] : -1);
      if (l >= 0) mine.elements.push_back(l);
    }
    part.mesh.groups.push_back(std::move(mine));
  }
}

/// Rank 0's problem on a cut part: patch points on its triangles, point constraints on its nodes.
ElasticityProblem cut_problem(const TetMesh& mesh, const ElasticityProblem& p, const Located& at,
                              const std::vector<int>& node_local,
                              const std::vector<int>& triangle_local) {
  ElasticityProblem q;
  q.material = p.material;
  q.dirichlet = p.dirichlet;
  q.pressures = p.pressures;
  q.gravity = p.gravity;
  q.body_force = p.body_force;
  q.options = p.options;
  for (std::size_t k = 0; k < p.point_constraints.size(); ++k) {
    const auto node = static_cast<std::size_t>(at.constraint_node[k]);
    if (node_local[node] >= 0)
      q.point_constraints.push_back({mesh.nodes[node], p.point_constraints[k].component});
  }
  for (const TractionPatch& patch : p.patches) {
    TractionPatch mine = patch;
    mine.triangles.clear();
    mine.points.clear();
    for (int t : patch.triangles)
      if (const int l = triangle_local[static_cast<std::size_t>(t)]; l >= 0)
        mine.triangles.push_back(l);
    for (SurfacePoint s : patch.points) {
      s.triangle = triangle_local[static_cast<std::size_t>(s.triangle)];
      if (s.triangle >= 0) mine.points.push_back(s);
    }
    q.patches.push_back(std::move(mine));
  }
  return q;
}

void pack_problem(ByteWriter& w, const ElasticityProblem& p) {
  w.pod(p.material);
  w.pod<std::uint64_t>(p.dirichlet.size());
  for (const auto& d : p.dirichlet) {
    w.string(d.group);
    w.pod(d.kind);
    w.pod(d.component);
    w.pod<char>(d.value ? 1 : 0);
  }
  w.array(p.point_constraints);
  w.pod<std::uint64_t>(p.pressures.size());
  for (const auto& pr : p.pressures) {
    w.string(pr.group);
    w.pod(pr.pressure);
  }
  w.pod<std::uint64_t>(p.patches.size());
  for (const auto& patch : p.patches) {
    w.array(patch.triangles);
    w.array(patch.points);
    w.pod(patch.traction);
    w.pod(patch.area);
    w.pod(patch.outward_normal);
    w.pod(patch.centre);
    w.pod(patch.projected_area);
  }
  w.pod(p.gravity);
  w.pod<char>(p.body_force ? 1 : 0);
  w.pod(p.options);
}

/// The problem rank 0 packed, with the functions it flagged taken from `own`; `missing` names
/// the first one `own` lacks.
ElasticityProblem unpack_problem(ByteReader& r, const ElasticityProblem& own,
                                 std::string& missing) {
  ElasticityProblem p;
  p.material = r.pod<Material>();
  const auto n_dirichlet = r.pod<std::uint64_t>();
  for (std::uint64_t i = 0; i < n_dirichlet; ++i) {
    DirichletCondition d;
    d.group = r.string();
    d.kind = r.pod<DirichletCondition::Kind>();
    d.component = r.pod<int>();
    if (r.pod<char>()) {
      if (i < own.dirichlet.size() && own.dirichlet[i].value) {
        d.value = own.dirichlet[i].value;
      } else if (missing.empty()) {
        missing = "the prescribed displacement on '" + d.group + "'";
      }
    }
    p.dirichlet.push_back(std::move(d));
  }
  p.point_constraints = r.array<Pin>();
  const auto n_pressures = r.pod<std::uint64_t>();
  for (std::uint64_t i = 0; i < n_pressures; ++i) {
    PressureLoad pr;
    pr.group = r.string();
    pr.pressure = r.pod<double>();
    p.pressures.push_back(std::move(pr));
  }
  const auto n_patches = r.pod<std::uint64_t>();
  for (std::uint64_t i = 0; i < n_patches; ++i) {
    TractionPatch patch;
    patch.triangles = r.array<int>();
    patch.points = r.array<SurfacePoint>();
    patch.traction = r.pod<Vec3>();
    patch.area = r.pod<double>();
    patch.outward_normal = r.pod<Vec3>();
    patch.centre = r.pod<Vec3>();
    patch.projected_area = r.pod<double>();
    p.patches.push_back(std::move(patch));
  }
  p.gravity = r.pod<Vec3>();
  if (r.pod<char>()) {
    if (own.body_force) {
      p.body_force = own.body_force;
    } else if (missing.empty()) {
      missing = "the body force";
    }
  }
  p.options = r.pod<SolverOptions>();
  return p;
}

std::vector<char> pack_part(const RankPart& part) {
  ByteWriter w;
  write_mesh(w, part.mesh);
  w.array(part.global_tet);
  w.array(part.global_node);
  pack_problem(w, part.problem);
  w.pod<char>(part.mixed ? 1 : 0);
  w.array(part.points);
  w.pod<std::uint64_t>(part.n_points);
  w.pod<std::uint64_t>(part.n_nodes);
  w.pod<std::uint64_t>(part.n_tets);
  w.pod(part.centroid);
  w.pod<char>(part.serial_dofs ? 1 : 0);
  return std::move(w.bytes);
}

RankPart unpack_part(const std::vector<char>& bytes, const ElasticityProblem& own,
                     std::string& missing) {
  ByteReader r{bytes};
  RankPart part;
  part.mesh = read_mesh(r);
  part.global_tet = r.array<int>();
  part.global_node = r.array<int>();
  part.problem = unpack_problem(r, own, missing);
  part.mixed = r.pod<char>() != 0;
  part.points = r.array<RankPart::Point>();
  part.n_points = r.pod<std::uint64_t>();
  part.n_nodes = r.pod<std::uint64_t>();
  part.n_tets = r.pod<std::uint64_t>();
  part.centroid = r.pod<Vec3>();
  part.serial_dofs = r.pod<char>() != 0;
  return part;
}

/// Rank 0: rank r's part of the whole mesh and problem.
RankPart cut_part(const TetMesh& mesh, const ElasticityProblem& problem, const Located& at,
                  const std::vector<unsigned>& owner, unsigned r, const DistributedOptions& o,
                  bool mixed, const Vec3& centroid) {
  RankPart part;
  std::vector<int> node_local(mesh.nodes.size(), -1), triangle_local(mesh.triangles.size(), -1);
  cut_mesh(mesh, owner, r, part, node_local, triangle_local);
  part.problem = cut_problem(mesh, problem, at, node_local, triangle_local);
  part.mixed = mixed;
  for (std::size_t k = 0; k < at.point_tet.size(); ++k) {
    const int t = at.point_tet[k];
    if (owner[static_cast<std::size_t>(t)] != r) continue;
    part.points.push_back(
        {static_cast<std::int64_t>(k), local_tet(part.global_tet, t), o.evaluation_points[k]});
  }
  part.n_points = o.evaluation_points.size();
  part.n_nodes = mesh.nodes.size();
  part.n_tets = mesh.tets.size();
  part.centroid = centroid;
  part.serial_dofs = o.serial_dofs;
  return part;
}

}  // namespace

RankPart distribute_parts(const TetMesh& mesh, const ElasticityProblem& own,
                          const std::vector<unsigned>& owner, const DistributedOptions& options,
                          bool mixed, MPI_Comm comm) {
  int rank = 0, n_ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &n_ranks);
  Located at;
  run_on_root(comm, [&] { at = locate(mesh, own, options); });
  RankPart part;
  std::string missing;
  if (rank == 0) {
    const Vec3 centroid = node_centroid(mesh);
    for (int r = 1; r < n_ranks; ++r) {
      send_bytes(pack_part(cut_part(mesh, own, at, owner, static_cast<unsigned>(r), options, mixed,
                                    centroid)),
                 r, kPartTag, comm);
    }
    part = cut_part(mesh, own, at, owner, 0, options, mixed, centroid);
  } else {
    part = unpack_part(receive_bytes(0, kPartTag, comm), own, missing);
  }
  // Functions cannot be sent: every rank must have been given rank 0's. The first rank lacking
  // one names it to all.
  int first = missing.empty() ? n_ranks : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first < n_ranks) {
    std::vector<char> text(missing.begin(), missing.end());
    broadcast_bytes(text, first, comm);
    throw std::logic_error(
        "solve_elasticity_distributed: rank 0's problem has a function that rank " +
        std::to_string(first) +
        "'s problem lacks (functions cannot be sent; every rank must pass "
        "them): " +
        std::string(text.begin(), text.end()));
  }
  return part;
}

}  // namespace vessel::fem::detail
