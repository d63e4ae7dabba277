/// deal.II/MPI implementation of the distributed FEM reference (issue #3). The serial mesh is
/// partitioned with METIS on every rank, each rank then keeps its part plus one ghost layer in a
/// parallel::fullydistributed::Triangulation; assembly into Trilinos matrices as in step-40, the
/// element integrals as in elasticity.cpp (step-8's bilinear form, the same quadratures), so one
/// rank and many ranks solve the same discrete system.
#include "fem_reference/distributed_elasticity.hpp"

#include <Epetra_MultiVector.h>
#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/numerics/vector_tools.h>
#include <mpi.h>

#include <Teuchos_ParameterList.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "meshes/errors.hpp"

namespace vessel::fem {

namespace dl = dealii;
constexpr int kDim = 3;

// ---------------------------------------------------------------------------------------------
// MPI session

struct MpiSession::Impl {
  int argc = 1;
  char name[16] = "vesselverify";
  char* argv_storage[2] = {name, nullptr};
  char** argv = argv_storage;
  std::unique_ptr<dl::Utilities::MPI::MPI_InitFinalize> mpi;
};

MpiSession::MpiSession() : impl_(std::make_unique<Impl>()) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) {
    throw std::logic_error("MpiSession: MPI is already initialised in this process");
  }
  // One thread per rank: the ranks are the parallelism (the machines have few cores).
  impl_->mpi = std::make_unique<dl::Utilities::MPI::MPI_InitFinalize>(impl_->argc, impl_->argv, 1);
}

MpiSession::~MpiSession() = default;

int MpiSession::rank() const {
  return static_cast<int>(dl::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD));
}
int MpiSession::size() const {
  return static_cast<int>(dl::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD));
}

// ---------------------------------------------------------------------------------------------
// Mesh broadcast

namespace {

/// Byte buffer writer/reader for the mesh broadcast (all ranks run the same binary, so raw
/// little-endian PODs are fine).
struct Writer {
  std::vector<char> bytes;
  template <class T>
  void pod(const T& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    pod<std::uint64_t>(v.size());
    const auto* p = reinterpret_cast<const char*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
  }
};

struct Reader {
  const std::vector<char>& bytes;
  std::size_t at = 0;
  template <class T>
  T pod() {
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  template <class T>
  std::vector<T> array() {
    const auto n = pod<std::uint64_t>();
    std::vector<T> v(n);
    std::memcpy(static_cast<void*>(v.data()), bytes.data() + at, n * sizeof(T));
    at += n * sizeof(T);
    return v;
  }
};

/// MPI_Bcast of a byte buffer in chunks (MPI counts are int).
void broadcast_bytes(std::vector<char>& bytes, int root, MPI_Comm comm) {
  std::uint64_t n = bytes.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, root, comm);
  bytes.resize(n);
  constexpr std::uint64_t kChunk = 1u << 30;
  for (std::uint64_t at = 0; at < n; at += kChunk) {
    const int count = static_cast<int>(std::min(kChunk, n - at));
    MPI_Bcast(bytes.data() + at, count, MPI_CHAR, root, comm);
  }
}

std::vector<char> pack_mesh(const TetMesh& m) {
  Writer w;
  w.array(m.nodes);
  w.array(m.tets);
  w.array(m.triangles);
  w.pod<std::uint64_t>(m.groups.size());
  for (const auto& g : m.groups) {
    w.array(std::vector<char>(g.name.begin(), g.name.end()));
    w.pod(g.dim);
    w.pod(g.tag);
    w.array(g.elements);
  }
  return std::move(w.bytes);
}

TetMesh unpack_mesh(const std::vector<char>& bytes) {
  Reader r{bytes};
  TetMesh m;
  m.nodes = r.array<Vec3>();
  m.tets = r.array<Tet>();
  m.triangles = r.array<Triangle>();
  const auto n_groups = r.pod<std::uint64_t>();
  for (std::uint64_t i = 0; i < n_groups; ++i) {
    PhysicalGroup g;
    const auto name = r.array<char>();
    g.name.assign(name.begin(), name.end());
    g.dim = r.pod<int>();
    g.tag = r.pod<int>();
    g.elements = r.array<int>();
    m.groups.push_back(std::move(g));
  }
  return m;
}

}  // namespace

TetMesh make_mesh_on_rank0(const std::function<TetMesh()>& make) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const unsigned rank = dl::Utilities::MPI::this_mpi_process(comm);
  TetMesh mesh;
  std::exception_ptr failure;
  std::vector<char> message;
  if (rank == 0) {
    try {
      mesh = make();
    } catch (const std::exception& e) {
      failure = std::current_exception();
      const std::string what = e.what();
      message.assign(what.begin(), what.end());
    } catch (...) {
      failure = std::current_exception();
      const std::string what = "meshing failed on rank 0";
      message.assign(what.begin(), what.end());
    }
  }
  int failed = failure ? 1 : 0;
  MPI_Bcast(&failed, 1, MPI_INT, 0, comm);
  if (failed) {
    broadcast_bytes(message, 0, comm);
    if (rank == 0) std::rethrow_exception(failure);
    throw InputError(std::string(message.begin(), message.end()));
  }
  std::vector<char> bytes;
  if (rank == 0) bytes = pack_mesh(mesh);
  broadcast_bytes(bytes, 0, comm);
  if (rank != 0) mesh = unpack_mesh(bytes);
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// The distributed solver

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// A clamped group's prescribed u(x) as a deal.II Function (three components).
class VectorFunction : public dl::Function<kDim> {
 public:
  explicit VectorFunction(std::function<Vec3(const Vec3&)> f)
      : dl::Function<kDim>(kDim), f_(std::move(f)) {}
  double value(const dl::Point<kDim>& p, unsigned component) const override {
    if (!f_) return 0.0;
    return f_(Vec3(p[0], p[1], p[2]))[component];
  }

 private:
  std::function<Vec3(const Vec3&)> f_;
};

using Face = std::array<int, 3>;
Face sorted_face(int a, int b, int c) {
  Face f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

/// The same checks as the serial solver's, plus what the distributed one does not do. Depends on
/// the (identical) input only, so every rank throws the same error.
void validate(const TetMesh& mesh, const ElasticityProblem& p) {
  const auto& m = p.material;
  const auto& o = p.options;
  std::ostringstream msg;
  if (!std::isfinite(m.youngs_modulus) || m.youngs_modulus <= 0.0) {
    msg << "Young's modulus E = " << m.youngs_modulus << " Pa is invalid: expected E > 0";
  } else if (!std::isfinite(m.poisson_ratio) || m.poisson_ratio < 0.0 || m.poisson_ratio > 0.5) {
    msg << "Poisson's ratio nu = " << m.poisson_ratio << " is invalid: expected 0 <= nu <= 0.5";
  } else if (!std::isfinite(m.density) || m.density < 0.0) {
    msg << "density = " << m.density << " kg/m^3 is invalid: expected a finite value >= 0";
  } else if (o.degree != 1 && o.degree != 2) {
    msg << "element degree = " << o.degree << " is invalid: expected 1 or 2";
  } else if (o.formulation == Formulation::mixed ||
             (o.formulation == Formulation::automatic &&
              (m.poisson_ratio >= o.mixed_threshold || m.poisson_ratio == 0.5))) {
    msg << "the distributed (MPI) solver has the displacement formulation (P1, P2) only; nu = "
        << m.poisson_ratio << " with formulation '" << to_string(o.formulation)
        << "' needs the mixed Taylor-Hood system (automatic for nu >= the mixed threshold "
        << o.mixed_threshold << "): run it without --distributed, or use nu below the threshold";
  } else if (m.poisson_ratio == 0.5) {
    msg << "Poisson's ratio nu = 0.5 (incompressible) cannot be solved with the displacement-only "
           "formulation (lambda is infinite): use the serial mixed formulation (Taylor-Hood P2-P1)";
  } else if (!p.curved_surfaces.empty()) {
    msg << "the distributed (MPI) solver has straight-sided (affine) tets only; curved surfaces "
           "(--curved) need the serial solver";
  } else if (o.solver == LinearSolver::direct) {
    msg << "the distributed (MPI) solver uses CG with algebraic multigrid; solver 'direct' is "
           "serial only: use cg-amg or auto";
  } else if (!(o.cg_relative_tolerance > 0.0) || !std::isfinite(o.cg_relative_tolerance)) {
    msg << "CG tolerance = " << o.cg_relative_tolerance << " is invalid: expected > 0";
  } else if (o.max_iterations == 0) {
    msg << "CG iteration limit = 0 is invalid: expected >= 1";
  } else if (!p.gravity.allFinite()) {
    msg << "gravity must be finite";
  }
  if (!msg.str().empty()) throw InputError(msg.str());
  for (const auto& d : p.dirichlet) {
    (void)mesh.require_group(d.group, 2, "FEM boundary condition");
    if (d.kind == DirichletCondition::Kind::roller && (d.component < 0 || d.component > 2)) {
      throw InputError("roller on '" + d.group + "': component " + std::to_string(d.component) +
                       " is invalid: expected 0, 1 or 2 (x, y, z)");
    }
  }
  for (const auto& pr : p.pressures) {
    (void)mesh.require_group(pr.group, 2, "FEM pressure load");
    if (!std::isfinite(pr.pressure))
      throw InputError("pressure on '" + pr.group + "' is not finite");
  }
  for (const auto& patch : p.patches) {
    if (!patch.traction.allFinite()) throw InputError("traction patch: traction is not finite");
    for (int t : patch.triangles) {
      if (t < 0 || static_cast<std::size_t>(t) >= mesh.triangles.size()) {
        throw InputError("traction patch refers to triangle " + std::to_string(t) +
                         " which is not in the mesh");
      }
    }
  }
  for (const auto& pc : p.point_constraints) {
    if (pc.component < 0 || pc.component > 2) {
      throw InputError("point constraint component " + std::to_string(pc.component) +
                       " is invalid: expected 0, 1 or 2");
    }
  }
}

dl::Quadrature<kDim> cell_quadrature(int degree) {
  return dl::QGaussSimplex<kDim>(static_cast<unsigned>(degree + 1));
}
dl::Quadrature<kDim - 1> face_quadrature(int degree) {
  return dl::QGaussSimplex<kDim - 1>(static_cast<unsigned>(degree + 1));
}

using CellIt = dl::DoFHandler<kDim>::active_cell_iterator;
using VectorT = dl::TrilinosWrappers::MPI::Vector;

class Distributed {
 public:
  Distributed(const TetMesh& mesh, const ElasticityProblem& problem, MPI_Comm comm)
      : mesh_(mesh),
        problem_(problem),
        comm_(comm),
        rank_(dl::Utilities::MPI::this_mpi_process(comm)),
        n_ranks_(dl::Utilities::MPI::n_mpi_processes(comm)),
        degree_(problem.options.degree),
        lambda_(problem.material.lambda()),
        mu_(problem.material.mu()),
        linear_(1),
        mapping_(linear_),
        tria_(comm) {}

  DistributedResult run(const std::vector<Vec3>& points);

 private:
  void build_triangulation();
  void setup_dofs();
  void local_system(const CellIt& cell, dl::FEValues<kDim>& fev, dl::FEFaceValues<kDim>& fefv,
                    dl::FullMatrix<double>& k, dl::Vector<double>& f, Vec3* applied) const;
  void assemble();
  void solve_linear();
  void postprocess();
  std::vector<Vec3> evaluate(const std::vector<Vec3>& points) const;
  [[nodiscard]] double max_over_ranks(double v) const { return dl::Utilities::MPI::max(v, comm_); }

  const TetMesh& mesh_;
  const ElasticityProblem& problem_;
  MPI_Comm comm_;
  unsigned rank_, n_ranks_;
  int degree_;
  double lambda_, mu_;

  dl::FE_SimplexP<kDim> linear_;
  dl::MappingFE<kDim> mapping_;
  dl::parallel::fullydistributed::Triangulation<kDim> tria_;
  std::unique_ptr<dl::FESystem<kDim>> fe_;
  dl::DoFHandler<kDim> dof_;
  dl::IndexSet owned_, relevant_;
  dl::AffineConstraints<double> constraints_;
  dl::TrilinosWrappers::SparseMatrix matrix_;
  VectorT rhs_, solution_, ghosted_;

  // Per local cell (active_cell_index of the distributed triangulation, ghosts included): the
  // TetMesh tet and, per face, the TetMesh triangle (−1: none). Per local vertex: the mesh node.
  std::vector<int> cell_tet_;
  std::vector<std::array<int, 4>> face_triangle_;
  std::vector<int> vertex_node_;
  std::vector<int> triangle_tag_;
  std::vector<std::vector<int>> triangle_patches_;
  std::vector<std::pair<int, double>> pressure_tags_;

  DistributedResult out_;
};

void Distributed::build_triangulation() {
  {
    // The serial coarse mesh on every rank (the cells in TetMesh order, so a cell's coarse cell
    // id is its tet index), partitioned by METIS; each rank then keeps its own cells and ghosts.
    dl::Triangulation<kDim> serial;
    std::vector<dl::Point<kDim>> vertices;
    vertices.reserve(mesh_.nodes.size());
    for (const auto& x : mesh_.nodes) vertices.emplace_back(x.x(), x.y(), x.z());
    std::vector<dl::CellData<kDim>> cells(mesh_.tets.size(), dl::CellData<kDim>(4));
    for (std::size_t t = 0; t < mesh_.tets.size(); ++t) {
      for (unsigned v = 0; v < 4; ++v)
        cells[t].vertices[v] = static_cast<unsigned>(mesh_.tets[t][v]);
    }
    serial.create_triangulation(vertices, cells, dl::SubCellData());
    dl::GridTools::partition_triangulation(n_ranks_, serial);
    const auto description =
        dl::TriangulationDescription::Utilities::create_description_from_triangulation(serial,
                                                                                       comm_);
    tria_.create_triangulation(description);
  }

  triangle_tag_.assign(mesh_.triangles.size(), 0);
  for (const auto& g : mesh_.groups) {
    if (g.dim != 2) continue;
    for (int e : g.elements) triangle_tag_[static_cast<std::size_t>(e)] = g.tag;
  }
  for (const auto& pr : problem_.pressures) {
    pressure_tags_.emplace_back(mesh_.require_group(pr.group, 2, "FEM pressure load").tag,
                                pr.pressure);
  }
  triangle_patches_.assign(mesh_.triangles.size(), {});
  for (std::size_t i = 0; i < problem_.patches.size(); ++i) {
    for (int t : problem_.patches[i].triangles)
      triangle_patches_[static_cast<std::size_t>(t)].push_back(static_cast<int>(i));
  }
  std::map<Face, int> face_to_triangle;
  for (std::size_t t = 0; t < mesh_.triangles.size(); ++t) {
    const auto& tri = mesh_.triangles[t];
    face_to_triangle[sorted_face(tri[0], tri[1], tri[2])] = static_cast<int>(t);
  }

  cell_tet_.assign(tria_.n_active_cells(), -1);
  face_triangle_.assign(tria_.n_active_cells(), {-1, -1, -1, -1});
  vertex_node_.assign(tria_.n_vertices(), -1);
  for (const auto& cell : tria_.active_cell_iterators()) {
    if (cell->is_artificial()) continue;
    const auto coarse = cell->id().get_coarse_cell_id();
    if (coarse >= mesh_.tets.size()) throw std::logic_error("distributed cell with unknown tet");
    const auto idx = cell->active_cell_index();
    const auto& tet = mesh_.tets[coarse];
    cell_tet_[idx] = static_cast<int>(coarse);
    // The description keeps the serial vertex order, but match by position to be sure.
    for (unsigned v = 0; v < 4; ++v) {
      const dl::Point<kDim>& x = cell->vertex(v);
      int best = -1;
      double best_d = std::numeric_limits<double>::infinity();
      for (int n : tet) {
        const double d = (mesh_.nodes[static_cast<std::size_t>(n)] - Vec3(x[0], x[1], x[2])).norm();
        if (d < best_d) best_d = d, best = n;
      }
      if (best_d > 1e-12 * (1.0 + x.norm())) {
        throw std::logic_error("distributed cell vertex does not match its tet's nodes");
      }
      vertex_node_[cell->vertex_index(v)] = best;
    }
    for (unsigned f = 0; f < cell->n_faces(); ++f) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto face = cell->face(f);
      const auto it = face_to_triangle.find(sorted_face(vertex_node_[face->vertex_index(0)],
                                                        vertex_node_[face->vertex_index(1)],
                                                        vertex_node_[face->vertex_index(2)]));
      if (it == face_to_triangle.end()) continue;  // unlabelled boundary: free, id 0
      face_triangle_[idx][f] = it->second;
      // Boundary ids from the surface groups' gmsh tags (as the serial solver sets them).
      face->set_boundary_id(
          static_cast<dl::types::boundary_id>(triangle_tag_[static_cast<std::size_t>(it->second)]));
    }
  }
}

void Distributed::setup_dofs() {
  fe_ = std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(degree_), kDim);
  dof_.reinit(tria_);
  dof_.distribute_dofs(*fe_);
  owned_ = dof_.locally_owned_dofs();
  dl::DoFTools::extract_locally_relevant_dofs(dof_, relevant_);

  constraints_.clear();
  constraints_.reinit(relevant_);
  // Point constraints first (a Dirichlet group over the same node then skips them, same value 0).
  if (!problem_.point_constraints.empty()) {
    const double tol =
        1e-6 * std::cbrt(mesh_volume(mesh_) /
                         static_cast<double>(std::max<std::size_t>(mesh_.tets.size(), 1)));
    std::vector<char> used(mesh_.nodes.size(), 0);
    for (const auto& tet : mesh_.tets)
      for (int n : tet) used[static_cast<std::size_t>(n)] = 1;
    for (const auto& pc : problem_.point_constraints) {
      std::size_t best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (std::size_t n = 0; n < mesh_.nodes.size(); ++n) {
        const double d = (mesh_.nodes[n] - pc.point).norm();
        if (used[n] && d < best_d) best_d = d, best = n;
      }
      if (best_d > tol) {
        std::ostringstream m;
        m << "point constraint at (" << pc.point.x() * 1e3 << ", " << pc.point.y() * 1e3 << ", "
          << pc.point.z() * 1e3 << ") mm: no mesh node there (nearest " << best_d * 1e3
          << " mm away); expected a point on a mesh node";
        throw InputError(m.str());
      }
      for (const auto& cell : dof_.active_cell_iterators()) {
        if (cell->is_artificial()) continue;
        for (unsigned v = 0; v < 4; ++v) {
          if (vertex_node_[cell->vertex_index(v)] != static_cast<int>(best)) continue;
          const auto d = cell->vertex_dof_index(v, static_cast<unsigned>(pc.component));
          if (!constraints_.is_constrained(d)) constraints_.add_line(d);
        }
      }
    }
  }
  for (const auto& bc : problem_.dirichlet) {
    const auto tag =
        static_cast<dl::types::boundary_id>(mesh_.require_group(bc.group, 2, "FEM").tag);
    std::vector<bool> mask(kDim, false);
    if (bc.kind == DirichletCondition::Kind::clamped) {
      mask[0] = mask[1] = mask[2] = true;
    } else {
      mask[static_cast<std::size_t>(bc.component)] = true;
    }
    const VectorFunction value(bc.kind == DirichletCondition::Kind::clamped
                                   ? bc.value
                                   : std::function<Vec3(const Vec3&)>());
    dl::VectorTools::interpolate_boundary_values(mapping_, dof_, tag, value, constraints_,
                                                 dl::ComponentMask(mask));
  }
  constraints_.close();

  // step-40's distributed sparsity pattern.
  dl::DynamicSparsityPattern dsp(relevant_);
  dl::DoFTools::make_sparsity_pattern(dof_, dsp, constraints_, false);
  dl::SparsityTools::distribute_sparsity_pattern(dsp, owned_, comm_, relevant_);
  matrix_.reinit(owned_, owned_, dsp, comm_);
  rhs_.reinit(owned_, comm_);
  solution_.reinit(owned_, comm_);
  ghosted_.reinit(owned_, relevant_, comm_);
}

/// The element stiffness and load (step-8's a(u,v) = ∫ λ div u div v + 2μ ε(u):ε(v); body force
/// and boundary tractions), the same integrals as the serial ElasticitySolver's.
void Distributed::local_system(const CellIt& cell, dl::FEValues<kDim>& fev,
                               dl::FEFaceValues<kDim>& fefv, dl::FullMatrix<double>& k,
                               dl::Vector<double>& f, Vec3* applied) const {
  const dl::FEValuesExtractors::Vector disp(0);
  const unsigned n = fe_->n_dofs_per_cell();
  k = 0.0;
  f = 0.0;
  fev.reinit(cell);
  std::vector<dl::SymmetricTensor<2, kDim>> eps(n);
  std::vector<double> div(n);
  const Vec3 rho_g = problem_.material.density * problem_.gravity;
  dl::Tensor<1, kDim> body;
  for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
    const double jxw = fev.JxW(q);
    Vec3 b = rho_g;
    if (problem_.body_force) {
      const auto& x = fev.quadrature_point(q);
      b += problem_.body_force(Vec3(x[0], x[1], x[2]));
    }
    for (unsigned c = 0; c < 3; ++c) body[c] = b[c];
    for (unsigned i = 0; i < n; ++i) {
      eps[i] = fev[disp].symmetric_gradient(i, q);
      div[i] = fev[disp].divergence(i, q);
    }
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j <= i; ++j) {
        k(i, j) += (lambda_ * div[i] * div[j] + 2.0 * mu_ * (eps[i] * eps[j])) * jxw;
      }
      f(i) += (fev[disp].value(i, q) * body) * jxw;
    }
    if (applied) {
      for (unsigned c = 0; c < 3; ++c) (*applied)[static_cast<int>(c)] += body[c] * jxw;
    }
  }
  for (unsigned i = 0; i < n; ++i)
    for (unsigned j = i + 1; j < n; ++j) k(i, j) = k(j, i);

  const auto idx = cell->active_cell_index();
  for (unsigned face = 0; face < 4; ++face) {
    const int tri = face_triangle_[idx][face];
    if (tri < 0) continue;
    const auto t = static_cast<std::size_t>(tri);
    bool has_pressure = false;
    double p_total = 0.0;
    for (const auto& [tag, pressure] : pressure_tags_) {
      if (tag == triangle_tag_[t]) {
        has_pressure = true;
        p_total += pressure;
      }
    }
    if (!has_pressure && triangle_patches_[t].empty()) continue;
    Vec3 patch_traction = Vec3::Zero();
    for (int pi : triangle_patches_[t])
      patch_traction += problem_.patches[static_cast<std::size_t>(pi)].traction;
    fefv.reinit(cell, face);
    for (unsigned q = 0; q < fefv.n_quadrature_points; ++q) {
      const auto& nrm = fefv.normal_vector(q);
      dl::Tensor<1, kDim> tr;
      for (unsigned c = 0; c < 3; ++c)
        tr[c] = -p_total * nrm[c] + patch_traction[static_cast<int>(c)];
      const double jxw = fefv.JxW(q);
      for (unsigned i = 0; i < n; ++i) f(i) += (fefv[disp].value(i, q) * tr) * jxw;
      if (applied) {
        for (unsigned c = 0; c < 3; ++c) (*applied)[static_cast<int>(c)] += tr[c] * jxw;
      }
    }
  }
}

void Distributed::assemble() {
  dl::FEValues<kDim> fev(mapping_, *fe_, cell_quadrature(degree_),
                         dl::update_values | dl::update_gradients | dl::update_JxW_values |
                             dl::update_quadrature_points);
  dl::FEFaceValues<kDim> fefv(
      mapping_, *fe_, face_quadrature(degree_),
      dl::update_values | dl::update_normal_vectors | dl::update_JxW_values);
  const unsigned n = fe_->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n);
  dl::Vector<double> f(n);
  std::vector<dl::types::global_dof_index> dofs(n);
  Vec3 applied = Vec3::Zero();
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    local_system(cell, fev, fefv, k, f, &applied);
    cell->get_dof_indices(dofs);
    constraints_.distribute_local_to_global(k, f, dofs, matrix_, rhs_);
  }
  matrix_.compress(dl::VectorOperation::add);
  rhs_.compress(dl::VectorOperation::add);
  for (int c = 0; c < 3; ++c) out_.fem.applied_load[c] = dl::Utilities::MPI::sum(applied[c], comm_);
}

void Distributed::solve_linear() {
  const auto& o = problem_.options;
  out_.fem.solver = LinearSolver::cg_amg;
  const double rhs_norm = rhs_.l2_norm();
  solution_ = 0.0;
  if (rhs_norm > 0.0) {
    dl::TrilinosWrappers::PreconditionAMG amg;
    dl::TrilinosWrappers::PreconditionAMG::AdditionalData data;
    data.elliptic = true;
    data.higher_order_elements = degree_ > 1;
    data.smoother_sweeps = 2;
    data.aggregation_threshold = 0.02;
    Teuchos::ParameterList ml;
    std::unique_ptr<Epetra_MultiVector> unused;
    data.set_parameters(ml, unused, matrix_);
    // All six rigid-body modes as ML's near-null space (smoothed aggregation for elasticity,
    // Vaněk, Mandel & Brezina 1996), as the serial solver does; here for the locally owned rows,
    // in the row map's order (the owned DoFs' order within the IndexSet). Rotations about the
    // mesh's node centroid, the same point on every rank.
    std::vector<double> rigid_modes;
    if (o.amg_rigid_body_modes) {
      const std::size_t n_local = owned_.n_elements();
      std::map<dl::types::global_dof_index, dl::Point<kDim>> x;
      dl::DoFTools::map_dofs_to_support_points(mapping_, dof_, x);
      Vec3 centre = Vec3::Zero();
      for (const auto& p : mesh_.nodes) centre += p;
      centre /= static_cast<double>(std::max<std::size_t>(mesh_.nodes.size(), 1));
      std::vector<unsigned> component(n_local, 0);
      std::vector<dl::types::global_dof_index> dofs(fe_->n_dofs_per_cell());
      for (const auto& cell : dof_.active_cell_iterators()) {
        if (!cell->is_locally_owned()) continue;
        cell->get_dof_indices(dofs);
        for (unsigned i = 0; i < dofs.size(); ++i) {
          if (owned_.is_element(dofs[i]))
            component[owned_.index_within_set(dofs[i])] = fe_->system_to_component_index(i).first;
        }
      }
      rigid_modes.assign(6 * n_local, 0.0);
      for (std::size_t l = 0; l < n_local; ++l) {
        const auto d = owned_.nth_index_in_set(static_cast<dl::IndexSet::size_type>(l));
        const auto& p = x.at(d);
        const Vec3 r = Vec3(p[0], p[1], p[2]) - centre;
        const unsigned c = component[l];
        rigid_modes[c * n_local + l] = 1.0;  // translation along c
        // rotations ω × r about x, y, z: (0, −z, y), (z, 0, −x), (−y, x, 0)
        const double rot[3][3] = {{0, -r[2], r[1]}, {r[2], 0, -r[0]}, {-r[1], r[0], 0}};
        for (unsigned k = 0; k < 3; ++k) rigid_modes[(3 + k) * n_local + l] = rot[k][c];
      }
      ml.set("null space: type", "pre-computed");
      ml.set("null space: dimension", 6);
      ml.set("null space: vectors", rigid_modes.data());
      amg.initialize(matrix_, ml);
    } else {
      dl::DoFTools::extract_constant_modes(
          dof_, fe_->component_mask(dl::FEValuesExtractors::Vector(0)), data.constant_modes);
      amg.initialize(matrix_, data);
    }
    dl::SolverControl control(o.max_iterations, o.cg_relative_tolerance * rhs_norm);
    dl::SolverCG<VectorT> cg(control);
    try {
      cg.solve(matrix_, solution_, rhs_, amg);
    } catch (const dl::SolverControl::NoConvergence& e) {
      std::ostringstream m;
      m << "distributed CG with AMG did not converge in " << e.last_step << " iterations (residual "
        << e.last_residual << ", target " << o.cg_relative_tolerance * rhs_norm
        << "): raise --max-iterations or --tolerance";
      throw std::runtime_error(m.str());
    }
    out_.fem.iterations = control.last_step();
  }
  constraints_.distribute(solution_);
  ghosted_ = solution_;
}

void Distributed::postprocess() {
  auto& r = out_.fem;
  // Nodal displacement: each rank sends (node, u) for the vertices of its cells; rank 0 gathers.
  std::vector<double> mine;
  std::vector<char> sent(tria_.n_vertices(), 0);
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (unsigned v = 0; v < 4; ++v) {
      const auto vi = cell->vertex_index(v);
      if (sent[vi]) continue;
      sent[vi] = 1;
      mine.push_back(static_cast<double>(vertex_node_[vi]));
      for (unsigned c = 0; c < 3; ++c) mine.push_back(ghosted_(cell->vertex_dof_index(v, c)));
    }
  }
  const int my_count = static_cast<int>(mine.size());
  std::vector<int> counts(n_ranks_, 0), offsets(n_ranks_, 0);
  MPI_Gather(&my_count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  std::vector<double> all;
  if (rank_ == 0) {
    for (unsigned i = 1; i < n_ranks_; ++i) offsets[i] = offsets[i - 1] + counts[i - 1];
    all.resize(static_cast<std::size_t>(offsets.back() + counts.back()));
  }
  MPI_Gatherv(mine.data(), my_count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
              MPI_DOUBLE, 0, comm_);
  if (rank_ == 0) {
    r.nodal_displacement.assign(mesh_.nodes.size(), Vec3::Zero());
    for (std::size_t i = 0; i + 4 <= all.size(); i += 4) {
      r.nodal_displacement[static_cast<std::size_t>(all[i])] =
          Vec3(all[i + 1], all[i + 2], all[i + 3]);
    }
  }

  // Energy and principal strains at the assembly quadrature points; residual K u − f of the
  // unconstrained system for the support reactions (as the serial solver computes them).
  const dl::FEValuesExtractors::Vector disp(0);
  dl::FEValues<kDim> fev(mapping_, *fe_, cell_quadrature(degree_),
                         dl::update_values | dl::update_gradients | dl::update_JxW_values |
                             dl::update_quadrature_points);
  dl::FEFaceValues<kDim> fefv(
      mapping_, *fe_, face_quadrature(degree_),
      dl::update_values | dl::update_normal_vectors | dl::update_JxW_values);
  std::vector<dl::SymmetricTensor<2, kDim>> eps(fev.n_quadrature_points);
  double energy = 0.0;
  double max_eig = -std::numeric_limits<double>::infinity();
  double max_abs = 0.0;
  const unsigned n = fe_->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n);
  dl::Vector<double> f(n), u_local(n), r_local(n);
  std::vector<dl::types::global_dof_index> dofs(n);
  VectorT residual(owned_, comm_);
  for (const auto& cell : dof_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    fev.reinit(cell);
    fev[disp].get_function_symmetric_gradients(ghosted_, eps);
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
      // W = ½∫ λ (tr ε)² + 2μ ε:ε
      const double tr = dl::trace(eps[q]);
      energy += 0.5 * (lambda_ * tr * tr + 2.0 * mu_ * (eps[q] * eps[q])) * fev.JxW(q);
      const auto ev = dl::eigenvalues(eps[q]);  // descending
      max_eig = std::max(max_eig, ev[0]);
      max_abs = std::max({max_abs, std::abs(ev[0]), std::abs(ev[2])});
    }
    local_system(cell, fev, fefv, k, f, nullptr);
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < n; ++i) u_local(i) = ghosted_(dofs[i]);
    k.vmult(r_local, u_local);
    r_local -= f;
    residual.add(dofs, r_local);
  }
  residual.compress(dl::VectorOperation::add);
  r.strain_energy = dl::Utilities::MPI::sum(energy, comm_);
  r.max_principal_strain = dl::Utilities::MPI::max(max_eig, comm_);
  r.max_abs_principal_strain = dl::Utilities::MPI::max(max_abs, comm_);

  // Reactions: the residual summed over each group's constrained owned DoFs (point constraints on
  // the group included), found from the faces of owned and ghost cells.
  r.reactions.clear();
  std::vector<std::string> seen;
  std::vector<dl::types::global_dof_index> face_dofs(fe_->n_dofs_per_face());
  for (const auto& bc : problem_.dirichlet) {
    if (std::find(seen.begin(), seen.end(), bc.group) != seen.end()) continue;
    seen.push_back(bc.group);
    const auto tag =
        static_cast<dl::types::boundary_id>(mesh_.require_group(bc.group, 2, "FEM").tag);
    std::map<dl::types::global_dof_index, unsigned> on_group;  // owned DoF → component
    for (const auto& cell : dof_.active_cell_iterators()) {
      if (cell->is_artificial()) continue;
      for (unsigned fno = 0; fno < cell->n_faces(); ++fno) {
        const auto face = cell->face(fno);
        if (!face->at_boundary() || face->boundary_id() != tag) continue;
        face->get_dof_indices(face_dofs);
        for (unsigned i = 0; i < face_dofs.size(); ++i) {
          const auto d = face_dofs[i];
          if (owned_.is_element(d) && constraints_.is_constrained(d))
            on_group[d] = fe_->face_system_to_component_index(i).first;
        }
      }
    }
    Vec3 force = Vec3::Zero();
    for (const auto& [d, c] : on_group) force[static_cast<int>(c)] += residual(d);
    for (int c = 0; c < 3; ++c) force[c] = dl::Utilities::MPI::sum(force[c], comm_);
    r.reactions.push_back({bc.group, force});
  }
}

std::vector<Vec3> Distributed::evaluate(const std::vector<Vec3>& points) const {
  std::vector<Vec3> out;
  const unsigned n = fe_->n_dofs_per_cell();
  std::vector<dl::types::global_dof_index> dofs(n);
  for (const auto& x : points) {
    // The owned cell whose tet has the largest smallest barycentric coordinate; then the best
    // over the ranks (MAXLOC), which evaluates and broadcasts.
    double best_min = -std::numeric_limits<double>::infinity();
    CellIt best_cell;
    for (const auto& cell : dof_.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      const auto& tet = mesh_.tets[static_cast<std::size_t>(cell_tet_[cell->active_cell_index()])];
      const Vec3& p0 = mesh_.nodes[static_cast<std::size_t>(tet[0])];
      Eigen::Matrix3d m;
      for (int c = 0; c < 3; ++c) m.col(c) = mesh_.nodes[static_cast<std::size_t>(tet[c + 1])] - p0;
      const Vec3 l = m.partialPivLu().solve(x - p0);
      const double lmin = std::min({1.0 - l.sum(), l[0], l[1], l[2]});
      if (lmin > best_min) best_min = lmin, best_cell = cell;
    }
    struct {
      double value;
      int rank;
    } mine{best_min, static_cast<int>(rank_)}, global{};
    MPI_Allreduce(&mine, &global, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm_);
    if (!(global.value >= -1e-9)) {
      std::ostringstream m;
      m << "point (" << x.x() * 1e3 << ", " << x.y() * 1e3 << ", " << x.z() * 1e3
        << ") mm is outside the FEM mesh: expected a point inside the vessel wall";
      throw InputError(m.str());
    }
    Vec3 u = Vec3::Zero();
    if (global.rank == static_cast<int>(rank_)) {
      const auto ref =
          mapping_.transform_real_to_unit_cell(best_cell, dl::Point<kDim>(x.x(), x.y(), x.z()));
      best_cell->get_dof_indices(dofs);
      for (unsigned i = 0; i < n; ++i) {
        const unsigned c = fe_->system_to_component_index(i).first;
        u[static_cast<int>(c)] += ghosted_(dofs[i]) * fe_->shape_value(i, ref);
      }
    }
    MPI_Bcast(u.data(), 3, MPI_DOUBLE, global.rank, comm_);
    out.push_back(u);
  }
  return out;
}

DistributedResult Distributed::run(const std::vector<Vec3>& points) {
  auto& r = out_.fem;
  r.element = degree_ == 1 ? "P1" : "P2";
  r.formulation = Formulation::displacement;
  out_.n_ranks = static_cast<int>(n_ranks_);
  auto t0 = Clock::now();
  build_triangulation();
  setup_dofs();
  r.n_dofs = dof_.n_dofs();
  r.timings.setup = max_over_ranks(seconds_since(t0));

  std::size_t owned_cells = 0;
  for (const auto& cell : tria_.active_cell_iterators()) owned_cells += cell->is_locally_owned();
  const auto cells = dl::Utilities::MPI::all_gather(comm_, owned_cells);
  const auto dofs =
      dl::Utilities::MPI::all_gather(comm_, static_cast<std::size_t>(owned_.n_elements()));
  out_.cells_per_rank.assign(cells.begin(), cells.end());
  out_.dofs_per_rank.assign(dofs.begin(), dofs.end());

  t0 = Clock::now();
  assemble();
  r.timings.assembly = max_over_ranks(seconds_since(t0));
  t0 = Clock::now();
  solve_linear();
  r.timings.solve = max_over_ranks(seconds_since(t0));
  t0 = Clock::now();
  postprocess();
  out_.point_displacement = evaluate(points);
  r.timings.postprocess = max_over_ranks(seconds_since(t0));
  return std::move(out_);
}

}  // namespace

DistributedResult solve_elasticity_distributed(const TetMesh& mesh,
                                               const ElasticityProblem& problem,
                                               const DistributedOptions& options) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    throw std::logic_error(
        "solve_elasticity_distributed needs MPI: create a fem::MpiSession first");
  }
  validate(mesh, problem);
  Distributed solver(mesh, problem, options.self_only ? MPI_COMM_SELF : MPI_COMM_WORLD);
  return solver.run(options.evaluation_points);
}

}  // namespace vessel::fem
