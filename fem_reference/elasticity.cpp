/// deal.II implementation of the FEM reference (the only translation unit that includes deal.II).
/// Structure after deal.II's step-8 (elasticity) and step-22 (mixed u–p): setup, assemble, solve,
/// postprocess.
#include "fem_reference/elasticity.hpp"

#include <Epetra_MultiVector.h>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/fe/mapping_fe_field.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/vector_tools.h>
#include <mpi.h>

#include <Eigen/SparseCore>
#include <Teuchos_ParameterList.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include "fem_reference/cholmod_solve.hpp"
#include "meshes/errors.hpp"

namespace vessel::fem {

namespace dl = dealii;
constexpr int kDim = 3;

double Material::lambda() const {
  if (poisson_ratio >= 0.5) return std::numeric_limits<double>::infinity();
  // λ = Eν / ((1+ν)(1−2ν))  (e.g. Sadd, Elasticity, 3rd ed., Table 4.1)
  return youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
}

double Material::mu() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }

std::string to_string(Formulation f) {
  switch (f) {
    case Formulation::automatic:
      return "auto";
    case Formulation::displacement:
      return "displacement";
    case Formulation::mixed:
      return "mixed";
  }
  return "?";
}

std::string to_string(LinearSolver s) {
  switch (s) {
    case LinearSolver::automatic:
      return "auto";
    case LinearSolver::direct:
      return "direct";
    case LinearSolver::cg_amg:
      return "cg-amg";
  }
  return "?";
}

std::vector<CurvedSurface> tube_curved_walls(double a, double b) {
  auto cylinder = [](double r) {
    return [r](const Vec3& x) {
      const double rho = std::hypot(x.x(), x.y());
      return Vec3(x.x() * r / rho, x.y() * r / rho, x.z());
    };
  };
  return {{"inner_wall", cylinder(a)}, {"outer_wall", cylinder(b)}};
}

std::vector<PointConstraint> tube_in_plane_pins(double a, double z) {
  // In-plane rigid motion (t_x − θy, t_y + θx): u_y(±a,0) = 0 gives t_y = θ = 0, u_x(0,a) = 0
  // then t_x = 0. A radial field u_r(r) e_r satisfies all three.
  return {{Vec3(a, 0.0, z), 1}, {Vec3(-a, 0.0, z), 1}, {Vec3(0.0, a, z), 0}};
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Trilinos (Epetra/ML) is built with MPI: it needs MPI initialised even on one process. The
/// program may not have done so (a serial run): initialise once and finalise at exit.
void ensure_mpi_initialized() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  std::atexit([] {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  });
}

/// A std::function displacement as a deal.II Function with `n_components` components (the first
/// three are u; any further, the mixed element's pressure, are zero).
class VectorFunction : public dl::Function<kDim> {
 public:
  VectorFunction(std::function<Vec3(const Vec3&)> f, unsigned components)
      : dl::Function<kDim>(components), f_(std::move(f)) {}
  double value(const dl::Point<kDim>& p, unsigned component) const override {
    if (component >= 3 || !f_) return 0.0;
    return f_(Vec3(p[0], p[1], p[2]))[component];
  }
  void vector_value(const dl::Point<kDim>& p, dl::Vector<double>& v) const override {
    v = 0.0;
    if (!f_) return;
    const Vec3 u = f_(Vec3(p[0], p[1], p[2]));
    for (unsigned c = 0; c < 3; ++c) v[c] = u[c];
  }

 private:
  std::function<Vec3(const Vec3&)> f_;
};

using Face = std::array<unsigned, 3>;
Face sorted_face(unsigned a, unsigned b, unsigned c) {
  Face f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

/// Uniform bucket grid over the tets' bounding boxes for point location.
class TetLocator {
 public:
  static constexpr double kBoxPadding = 0.1;  ///< of a tet's box diagonal
  explicit TetLocator(const TetMesh& mesh) : mesh_(&mesh) {
    lo_ = hi_ = mesh.nodes.empty() ? Vec3::Zero() : mesh.nodes[0];
    for (const auto& x : mesh.nodes) {
      lo_ = lo_.cwiseMin(x);
      hi_ = hi_.cwiseMax(x);
    }
    const double extent = (hi_ - lo_).maxCoeff();
    double largest_tet = 0.0;
    for (const auto& tet : mesh.tets) {
      largest_tet = std::max(largest_tet, (mesh.nodes[tet[1]] - mesh.nodes[tet[0]]).norm());
    }
    lo_ -= Vec3::Constant(1e-9 * extent + kBoxPadding * largest_tet);
    hi_ += Vec3::Constant(1e-9 * extent + kBoxPadding * largest_tet);
    const double per_axis =
        std::cbrt(static_cast<double>(std::max<std::size_t>(mesh.tets.size(), 1)));
    for (int d = 0; d < 3; ++d) {
      n_[d] = std::max(1, static_cast<int>(per_axis * (hi_[d] - lo_[d]) / extent) + 1);
    }
    buckets_.resize(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2]);
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
      Vec3 a = mesh.nodes[mesh.tets[t][0]], b = a;
      for (int v : mesh.tets[t]) {
        a = a.cwiseMin(mesh.nodes[v]);
        b = b.cwiseMax(mesh.nodes[v]);
      }
      // Listed also in the buckets just outside its box, so that points slightly outside the
      // mesh (a curved wall's chord error) still find their tet when a tolerance allows it.
      const Vec3 pad = Vec3::Constant(kBoxPadding * (b - a).norm());
      a -= pad;
      b += pad;
      const auto ia = bucket_of(a), ib = bucket_of(b);
      for (int i = ia[0]; i <= ib[0]; ++i)
        for (int j = ia[1]; j <= ib[1]; ++j)
          for (int k = ia[2]; k <= ib[2]; ++k)
            buckets_[index(i, j, k)].push_back(static_cast<int>(t));
    }
  }

  /// The tet containing x (the one with the largest smallest barycentric coordinate, ≥ −tol), or
  /// −1.
  [[nodiscard]] int find(const Vec3& x, double tol = 1e-9) const {
    for (int d = 0; d < 3; ++d) {
      if (x[d] < lo_[d] || x[d] > hi_[d]) return -1;
    }
    const auto ijk = bucket_of(x);
    int best = -1;
    double best_min = -tol;
    for (int t : buckets_[index(ijk[0], ijk[1], ijk[2])]) {
      const auto& tet = mesh_->tets[t];
      const Vec3& p0 = mesh_->nodes[tet[0]];
      Eigen::Matrix3d m;
      m.col(0) = mesh_->nodes[tet[1]] - p0;
      m.col(1) = mesh_->nodes[tet[2]] - p0;
      m.col(2) = mesh_->nodes[tet[3]] - p0;
      const Vec3 l = m.partialPivLu().solve(x - p0);
      const double lmin = std::min({1.0 - l.sum(), l[0], l[1], l[2]});
      if (lmin >= best_min) {
        best_min = lmin;
        best = t;
      }
    }
    return best;
  }

 private:
  [[nodiscard]] std::array<int, 3> bucket_of(const Vec3& x) const {
    std::array<int, 3> ijk{};
    for (int d = 0; d < 3; ++d) {
      const int i = static_cast<int>((x[d] - lo_[d]) / (hi_[d] - lo_[d]) * n_[d]);
      ijk[d] = std::clamp(i, 0, n_[d] - 1);
    }
    return ijk;
  }
  [[nodiscard]] std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) * n_[1] + j) * n_[2] + k;
  }
  const TetMesh* mesh_;
  Vec3 lo_, hi_;
  std::array<int, 3> n_{};
  std::vector<std::vector<int>> buckets_;
};

void validate(const TetMesh& mesh, const ElasticityProblem& p) {
  const auto& m = p.material;
  std::ostringstream msg;
  if (!std::isfinite(m.youngs_modulus) || m.youngs_modulus <= 0.0) {
    msg << "Young's modulus E = " << m.youngs_modulus << " Pa is invalid: expected E > 0";
  } else if (!std::isfinite(m.poisson_ratio) || m.poisson_ratio < 0.0 || m.poisson_ratio > 0.5) {
    msg << "Poisson's ratio nu = " << m.poisson_ratio << " is invalid: expected 0 <= nu <= 0.5";
  } else if (!std::isfinite(m.density) || m.density < 0.0) {
    msg << "density = " << m.density << " kg/m^3 is invalid: expected a finite value >= 0";
  } else if (p.options.degree != 1 && p.options.degree != 2) {
    msg << "element degree = " << p.options.degree << " is invalid: expected 1 or 2";
  } else if (m.poisson_ratio == 0.5 && p.options.formulation == Formulation::displacement) {
    msg << "Poisson's ratio nu = 0.5 (incompressible) cannot be solved with the displacement-only "
           "formulation (lambda is infinite): use the mixed formulation (Taylor-Hood P2-P1)";
  } else if (!(p.options.mixed_threshold > 0.0)) {
    msg << "mixed threshold = " << p.options.mixed_threshold << " is invalid: expected > 0";
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

}  // namespace

struct ElasticitySolver::Impl {
  TetMesh mesh;
  ElasticityProblem problem;
  bool mixed = false;
  int degree = 1;
  unsigned n_components = 3;
  double lambda = 0.0, mu = 0.0;

  dl::Triangulation<kDim> tria;
  std::unique_ptr<dl::FiniteElement<kDim>> fe;
  std::unique_ptr<dl::MappingFE<kDim>> linear_mapping;
  std::unique_ptr<dl::Mapping<kDim>> mapping;  // linear_mapping's copy, or the curved one
  std::unique_ptr<dl::FiniteElement<kDim>> geometry_fe;
  dl::DoFHandler<kDim> geometry_dof;
  dl::Vector<double> geometry_positions;  // absolute positions of the P2 geometry nodes
  dl::DoFHandler<kDim> dof;
  dl::AffineConstraints<double> constraints;
  dl::SparsityPattern sparsity;
  dl::SparseMatrix<double> matrix;
  dl::Vector<double> rhs, solution;

  std::vector<dl::DoFHandler<kDim>::active_cell_iterator> cells;  // by tet index
  std::vector<std::array<int, 4>> face_triangle;      // per cell and face: TetMesh triangle or −1
  std::vector<int> triangle_tag;                      // gmsh tag of each triangle's group (0: none)
  std::vector<std::vector<int>> triangle_patches;     // patches acting on each triangle
  std::vector<std::pair<int, double>> pressure_tags;  // (group tag, p) of each pressure load
  std::unique_ptr<TetLocator> locator;
  ElasticityResult result;
  bool solved = false;
  Clock::time_point t_setup;

  Impl(const TetMesh& m, ElasticityProblem p) : mesh(m), problem(std::move(p)) {}

  void build_triangulation();
  void setup_dofs();
  void setup_curved_mapping();
  void local_system(const dl::DoFHandler<kDim>::active_cell_iterator& cell, dl::FEValues<kDim>& fev,
                    dl::FEFaceValues<kDim>& fefv, dl::FullMatrix<double>& k, dl::Vector<double>& f,
                    Vec3* applied) const;
  void assemble();
  void solve_linear();
  void postprocess();

  /// The FE displacement at x as Σ w · u[dof]: the element's shape functions at x, per DoF and
  /// displacement component. InputError if x is outside the mesh (beyond `tol`, barycentric).
  struct PointStencil {
    std::vector<dl::types::global_dof_index> dofs;
    std::vector<unsigned> components;
    std::vector<double> weights;
  };
  [[nodiscard]] PointStencil point_stencil(const Vec3& x, double tol) const;

  /// Stiffness (and mass) of the displacement formulation on the unconstrained DoFs, condensed
  /// like the static system (prescribed Dirichlet values moved to f), with `free_index` mapping
  /// each DoF to its row (−1: constrained) and `constrained_value` each constrained DoF's value.
  struct FreeSystem {
    std::vector<int> free_index;
    std::vector<double> constrained_value;
    Eigen::SparseMatrix<double> K, M;
    Eigen::VectorXd f;
  };
  [[nodiscard]] FreeSystem assemble_free_system(bool with_mass) const;
};

void ElasticitySolver::Impl::build_triangulation() {
  std::vector<dl::Point<kDim>> vertices;
  vertices.reserve(mesh.nodes.size());
  for (const auto& x : mesh.nodes) vertices.emplace_back(x.x(), x.y(), x.z());
  std::vector<dl::CellData<kDim>> cell_data(mesh.tets.size(), dl::CellData<kDim>(4));
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (unsigned v = 0; v < 4; ++v)
      cell_data[t].vertices[v] = static_cast<unsigned>(mesh.tets[t][v]);
    cell_data[t].material_id = 0;
  }
  tria.create_triangulation(vertices, cell_data, dl::SubCellData());

  // Boundary ids from the surface groups' gmsh tags, by matching face vertex sets.
  triangle_tag.assign(mesh.triangles.size(), 0);
  for (const auto& g : mesh.groups) {
    if (g.dim != 2) continue;
    for (int e : g.elements) triangle_tag[e] = g.tag;
  }
  for (const auto& pr : problem.pressures) {
    pressure_tags.emplace_back(mesh.require_group(pr.group, 2, "FEM pressure load").tag,
                               pr.pressure);
  }
  triangle_patches.assign(mesh.triangles.size(), {});
  for (std::size_t i = 0; i < problem.patches.size(); ++i) {
    for (int t : problem.patches[i].triangles) triangle_patches[t].push_back(static_cast<int>(i));
  }
  std::map<Face, int> face_to_triangle;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    face_to_triangle[sorted_face(tri[0], tri[1], tri[2])] = static_cast<int>(t);
  }
  cells.assign(mesh.tets.size(), {});
  face_triangle.assign(mesh.tets.size(), {-1, -1, -1, -1});
  for (const auto& cell : tria.active_cell_iterators()) {
    const auto idx = cell->active_cell_index();
    // The coarse cells keep the CellData order; check it (the locator relies on it).
    std::array<int, 4> cv{}, tv = mesh.tets[idx];
    for (unsigned v = 0; v < 4; ++v) cv[v] = static_cast<int>(cell->vertex_index(v));
    std::sort(cv.begin(), cv.end());
    std::sort(tv.begin(), tv.end());
    if (cv != tv) throw std::logic_error("deal.II reordered the cells of the triangulation");
    for (unsigned f = 0; f < cell->n_faces(); ++f) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto face = cell->face(f);
      const auto it = face_to_triangle.find(
          sorted_face(face->vertex_index(0), face->vertex_index(1), face->vertex_index(2)));
      if (it == face_to_triangle.end()) continue;  // unlabelled boundary: free, id 0
      face_triangle[idx][f] = it->second;
      face->set_boundary_id(static_cast<dl::types::boundary_id>(triangle_tag[it->second]));
    }
  }
}

void ElasticitySolver::Impl::setup_dofs() {
  const dl::FE_SimplexP<kDim> linear(1);
  linear_mapping = std::make_unique<dl::MappingFE<kDim>>(linear);
  mapping = linear_mapping->clone();
  if (degree == 2 && !problem.curved_surfaces.empty()) setup_curved_mapping();
  if (mixed) {
    // Taylor–Hood P2–P1 (step-22's u–p pattern on simplices).
    fe = std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(2), kDim,
                                              dl::FE_SimplexP<kDim>(1), 1);
  } else {
    fe = std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(degree), kDim);
  }
  n_components = fe->n_components();
  dof.reinit(tria);
  dof.distribute_dofs(*fe);
  for (const auto& cell : dof.active_cell_iterators()) cells[cell->active_cell_index()] = cell;

  constraints.clear();
  // Point constraints first (a Dirichlet group over the same node then skips them, same value 0).
  if (!problem.point_constraints.empty()) {
    // Tolerance: 1e-6 of a typical element length (cube root of the mean tet volume).
    const double tol =
        1e-6 * std::cbrt(mesh_volume(mesh) /
                         static_cast<double>(std::max<std::size_t>(mesh.tets.size(), 1)));
    std::vector<std::pair<dl::DoFHandler<kDim>::active_cell_iterator, unsigned>> vertex_cell(
        mesh.nodes.size(), {dof.end(), 0});
    for (const auto& cell : dof.active_cell_iterators())
      for (unsigned v = 0; v < 4; ++v) vertex_cell[cell->vertex_index(v)] = {cell, v};
    for (const auto& pc : problem.point_constraints) {
      std::size_t best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
        const double d = (mesh.nodes[n] - pc.point).norm();
        if (d < best_d) best_d = d, best = n;
      }
      if (best_d > tol || vertex_cell[best].first == dof.end()) {
        std::ostringstream m;
        m << "point constraint at (" << pc.point.x() * 1e3 << ", " << pc.point.y() * 1e3 << ", "
          << pc.point.z() * 1e3 << ") mm: no mesh node there (nearest " << best_d * 1e3
          << " mm away); expected a point on a mesh node";
        throw InputError(m.str());
      }
      const auto d = vertex_cell[best].first->vertex_dof_index(vertex_cell[best].second,
                                                               static_cast<unsigned>(pc.component));
      if (!constraints.is_constrained(d)) constraints.add_line(d);
    }
  }
  for (const auto& bc : problem.dirichlet) {
    const auto tag =
        static_cast<dl::types::boundary_id>(mesh.require_group(bc.group, 2, "FEM").tag);
    std::vector<bool> mask(n_components, false);
    if (bc.kind == DirichletCondition::Kind::clamped) {
      mask[0] = mask[1] = mask[2] = true;
    } else {
      mask[static_cast<std::size_t>(bc.component)] = true;
    }
    const VectorFunction value(bc.kind == DirichletCondition::Kind::clamped
                                   ? bc.value
                                   : std::function<Vec3(const Vec3&)>(),
                               n_components);
    dl::VectorTools::interpolate_boundary_values(*mapping, dof, tag, value, constraints,
                                                 dl::ComponentMask(mask));
  }
  constraints.close();

  dl::DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
  dl::DoFTools::make_sparsity_pattern(dof, dsp, constraints, false);
  sparsity.copy_from(dsp);
  matrix.reinit(sparsity);
  rhs.reinit(dof.n_dofs());
  solution.reinit(dof.n_dofs());
}

void ElasticitySolver::Impl::setup_curved_mapping() {
  geometry_fe = std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(2), kDim);
  geometry_dof.reinit(tria);
  geometry_dof.distribute_dofs(*geometry_fe);
  geometry_positions.reinit(geometry_dof.n_dofs());
  std::map<int, const CurvedSurface*> by_tag;
  for (const auto& cs : problem.curved_surfaces) {
    by_tag[mesh.require_group(cs.group, 2, "curved surface").tag] = &cs;
  }
  const auto& unit = geometry_fe->get_unit_support_points();
  const unsigned n = geometry_fe->n_dofs_per_cell();
  std::vector<dl::types::global_dof_index> dofs(n);
  // A node on a curved face is shared with cells that touch the surface only along an edge: once
  // projected (from a cell that has the face), it must not be overwritten from such a cell.
  std::vector<bool> projected(geometry_dof.n_dofs(), false);
  for (const auto& cell : geometry_dof.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < n; ++i) {
      if (projected[dofs[i]]) continue;
      const auto x = linear_mapping->transform_unit_to_real_cell(cell, unit[i]);
      Vec3 y(x[0], x[1], x[2]);
      // A P2 node lies on a face iff it is one of the face's vertices or edge midpoints.
      for (unsigned f = 0; f < cell->n_faces(); ++f) {
        if (!cell->face(f)->at_boundary()) continue;
        const auto it = by_tag.find(static_cast<int>(cell->face(f)->boundary_id()));
        if (it == by_tag.end()) continue;
        const auto face = cell->face(f);
        const double h = face->diameter();
        bool on_face = false;
        for (unsigned a = 0; a < 3 && !on_face; ++a) {
          for (unsigned b = a; b < 3 && !on_face; ++b) {
            const auto m = 0.5 * (face->vertex(a) + face->vertex(b));
            on_face = x.distance(m) < 1e-9 * h;
          }
        }
        if (on_face) {
          y = it->second->project(y);
          projected[dofs[i]] = true;
          break;
        }
      }
      geometry_positions(dofs[i]) = y[geometry_fe->system_to_component_index(i).first];
    }
  }
  mapping = std::make_unique<dl::MappingFEField<kDim, kDim, dl::Vector<double>>>(
      geometry_dof, geometry_positions);
  result.curved = true;
}

void ElasticitySolver::Impl::local_system(const dl::DoFHandler<kDim>::active_cell_iterator& cell,
                                          dl::FEValues<kDim>& fev, dl::FEFaceValues<kDim>& fefv,
                                          dl::FullMatrix<double>& k, dl::Vector<double>& f,
                                          Vec3* applied) const {
  const dl::FEValuesExtractors::Vector disp(0);
  const dl::FEValuesExtractors::Scalar pres(kDim);
  const unsigned n = fe->n_dofs_per_cell();
  k = 0.0;
  f = 0.0;
  fev.reinit(cell);
  std::vector<dl::SymmetricTensor<2, kDim>> eps(n);
  std::vector<double> div(n), psi(n);
  const Vec3 rho_g = problem.material.density * problem.gravity;
  dl::Tensor<1, kDim> body;
  const double inv_lambda = mixed ? (std::isinf(lambda) ? 0.0 : 1.0 / lambda) : 0.0;
  for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
    const double jxw = fev.JxW(q);
    Vec3 b = rho_g;
    if (problem.body_force) {
      const auto& x = fev.quadrature_point(q);
      b += problem.body_force(Vec3(x[0], x[1], x[2]));
    }
    for (unsigned c = 0; c < 3; ++c) body[c] = b[c];
    for (unsigned i = 0; i < n; ++i) {
      eps[i] = fev[disp].symmetric_gradient(i, q);
      div[i] = fev[disp].divergence(i, q);
      psi[i] = mixed ? fev[pres].value(i, q) : 0.0;
    }
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j <= i; ++j) {
        double kij;
        if (mixed) {
          // a(u,v) = ∫ 2μ ε(u):ε(v) − p div v;  −∫ q div u − ∫ p q / λ  (p = −λ div u; step-22
          // pattern, symmetric; λ = ∞ at ν = 0.5 leaves the saddle-point Stokes system).
          kij = 2.0 * mu * (eps[i] * eps[j]) - psi[i] * div[j] - div[i] * psi[j] -
                inv_lambda * psi[i] * psi[j];
        } else {
          // a(u,v) = ∫ λ div u div v + 2μ ε(u):ε(v)  (step-8)
          kij = lambda * div[i] * div[j] + 2.0 * mu * (eps[i] * eps[j]);
        }
        k(i, j) += kij * jxw;
      }
      f(i) += (fev[disp].value(i, q) * body) * jxw;
    }
    if (applied) {
      for (int c = 0; c < 3; ++c) (*applied)[c] += body[c] * jxw;
    }
  }
  for (unsigned i = 0; i < n; ++i)
    for (unsigned j = i + 1; j < n; ++j) k(i, j) = k(j, i);

  const auto idx = cell->active_cell_index();
  for (unsigned face = 0; face < 4; ++face) {
    const int tri = face_triangle[idx][face];
    if (tri < 0) continue;
    bool has_pressure = false;
    double p_total = 0.0;
    for (const auto& [tag, pressure] : pressure_tags) {
      if (tag == triangle_tag[tri]) {
        has_pressure = true;
        p_total += pressure;
      }
    }
    if (!has_pressure && triangle_patches[tri].empty()) continue;
    Vec3 patch_traction = Vec3::Zero();
    for (int pi : triangle_patches[tri]) patch_traction += problem.patches[pi].traction;
    fefv.reinit(cell, face);
    for (unsigned q = 0; q < fefv.n_quadrature_points; ++q) {
      const auto& nrm = fefv.normal_vector(q);
      dl::Tensor<1, kDim> t;
      for (unsigned c = 0; c < 3; ++c) t[c] = -p_total * nrm[c] + patch_traction[c];
      const double jxw = fefv.JxW(q);
      for (unsigned i = 0; i < n; ++i) f(i) += (fefv[disp].value(i, q) * t) * jxw;
      if (applied) {
        for (unsigned c = 0; c < 3; ++c) (*applied)[c] += t[c] * jxw;
      }
    }
  }
}

namespace {
dl::Quadrature<kDim> cell_quadrature(int degree) {
  return dl::QGaussSimplex<kDim>(static_cast<unsigned>(degree + 1));
}
dl::Quadrature<kDim - 1> face_quadrature(int degree) {
  return dl::QGaussSimplex<kDim - 1>(static_cast<unsigned>(degree + 1));
}
}  // namespace

void ElasticitySolver::Impl::assemble() {
  const int q_degree = mixed ? 2 : degree;
  dl::FEValues<kDim> fev(*mapping, *fe, cell_quadrature(q_degree),
                         dl::update_values | dl::update_gradients | dl::update_JxW_values |
                             dl::update_quadrature_points);
  dl::FEFaceValues<kDim> fefv(
      *mapping, *fe, face_quadrature(q_degree),
      dl::update_values | dl::update_normal_vectors | dl::update_JxW_values);
  const unsigned n = fe->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n);
  dl::Vector<double> f(n);
  std::vector<dl::types::global_dof_index> dofs(n);
  Vec3 applied = Vec3::Zero();
  for (const auto& cell : dof.active_cell_iterators()) {
    local_system(cell, fev, fefv, k, f, &applied);
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(k, f, dofs, matrix, rhs);
  }
  result.applied_load = applied;
}

void ElasticitySolver::Impl::solve_linear() {
  const auto& o = problem.options;
  LinearSolver s = o.solver;
  if (s == LinearSolver::automatic) {
    s = (mixed || dof.n_dofs() <= o.direct_max_dofs) ? LinearSolver::direct : LinearSolver::cg_amg;
  }
  if (s == LinearSolver::cg_amg && mixed) {
    throw InputError(
        "solver cg-amg is for the symmetric positive definite displacement system; the mixed "
        "(Taylor-Hood) system is indefinite: use the direct solver");
  }
  result.solver = s;
  if (rhs.l2_norm() == 0.0) {
    solution = 0.0;  // no load and homogeneous constraints: u = 0
  } else if (s == LinearSolver::direct && !mixed) {
    // CHOLMOD (supernodal Cholesky) for the SPD displacement system: the constraints keep K
    // symmetric with positive diagonal entries on constrained rows.
    const std::size_t n = dof.n_dofs();
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(matrix.n_nonzero_elements());
    for (std::size_t row = 0; row < n; ++row) {
      for (auto it = matrix.begin(row); it != matrix.end(row); ++it) {
        if (it->value() != 0.0) {
          entries.emplace_back(static_cast<int>(row), static_cast<int>(it->column()), it->value());
        }
      }
    }
    Eigen::SparseMatrix<double> K(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    K.setFromTriplets(entries.begin(), entries.end());
    const Eigen::VectorXd x = solve_spd_cholmod(
        K, Eigen::Map<const Eigen::VectorXd>(rhs.begin(), static_cast<Eigen::Index>(n)));
    std::copy(x.data(), x.data() + x.size(), solution.begin());
  } else if (s == LinearSolver::direct) {
    // UMFPACK for the indefinite mixed (Taylor–Hood) system.
    dl::SparseDirectUMFPACK direct;
    direct.initialize(matrix);
    direct.vmult(solution, rhs);
  } else {
    ensure_mpi_initialized();
    dl::TrilinosWrappers::PreconditionAMG amg;
    dl::TrilinosWrappers::PreconditionAMG::AdditionalData data;
    data.elliptic = true;
    data.higher_order_elements = degree > 1;
    data.smoother_sweeps = 2;
    data.aggregation_threshold = 0.02;
    dl::TrilinosWrappers::SparseMatrix trilinos_matrix;
    std::vector<double> rigid_modes;  // must outlive amg.initialize
    if (o.amg_rigid_body_modes) {
      // All six rigid-body modes as ML's near-null space (smoothed aggregation for elasticity,
      // Vaněk, Mandel & Brezina 1996): AdditionalData only passes constant modes, so the ML
      // parameter list is filled first and the rotations are added as pre-computed vectors.
      trilinos_matrix.reinit(matrix);
      Teuchos::ParameterList ml;
      std::unique_ptr<Epetra_MultiVector> unused;
      data.set_parameters(ml, unused, trilinos_matrix);
      const std::size_t n = dof.n_dofs();
      std::vector<dl::Point<kDim>> x(n);
      dl::DoFTools::map_dofs_to_support_points(*mapping, dof, x);
      dl::Point<kDim> centre;
      for (const auto& p : x) centre += p / static_cast<double>(n);
      std::vector<unsigned> component(n, 0);
      std::vector<dl::types::global_dof_index> dofs(fe->n_dofs_per_cell());
      for (const auto& cell : dof.active_cell_iterators()) {
        cell->get_dof_indices(dofs);
        for (unsigned i = 0; i < dofs.size(); ++i)
          component[dofs[i]] = fe->system_to_component_index(i).first;
      }
      rigid_modes.assign(6 * n, 0.0);
      for (std::size_t d = 0; d < n; ++d) {
        const auto r = x[d] - centre;
        const unsigned c = component[d];
        rigid_modes[c * n + d] = 1.0;  // translation along c
        // rotations ω × r about x, y, z: (0, −z, y), (z, 0, −x), (−y, x, 0)
        const double rot[3][3] = {{0, -r[2], r[1]}, {r[2], 0, -r[0]}, {-r[1], r[0], 0}};
        for (unsigned k = 0; k < 3; ++k) rigid_modes[(3 + k) * n + d] = rot[k][c];
      }
      ml.set("null space: type", "pre-computed");
      ml.set("null space: dimension", 6);
      ml.set("null space: vectors", rigid_modes.data());
      amg.initialize(trilinos_matrix, ml);
    } else {
      dl::DoFTools::extract_constant_modes(
          dof, fe->component_mask(dl::FEValuesExtractors::Vector(0)), data.constant_modes);
      amg.initialize(matrix, data);
    }
    dl::SolverControl control(o.max_iterations, o.cg_relative_tolerance * rhs.l2_norm());
    dl::SolverCG<dl::Vector<double>> cg(control);
    try {
      cg.solve(matrix, solution, rhs, amg);
    } catch (const dl::SolverControl::NoConvergence& e) {
      std::ostringstream m;
      m << "CG with AMG did not converge in " << e.last_step << " iterations (residual "
        << e.last_residual << "); try --solver direct or more --max-iterations";
      throw std::runtime_error(m.str());
    }
    result.iterations = control.last_step();
  }
  constraints.distribute(solution);
}

void ElasticitySolver::Impl::postprocess() {
  result.nodal_displacement.assign(mesh.nodes.size(), Vec3::Zero());
  for (const auto& cell : dof.active_cell_iterators()) {
    for (unsigned v = 0; v < 4; ++v) {
      Vec3& u = result.nodal_displacement[cell->vertex_index(v)];
      for (unsigned c = 0; c < 3; ++c) u[c] = solution(cell->vertex_dof_index(v, c));
    }
  }

  // Energy and principal strains at the assembly quadrature points; ε, σ at each centroid.
  const int q_degree = mixed ? 2 : degree;
  const dl::FEValuesExtractors::Vector disp(0);
  const dl::FEValuesExtractors::Scalar pres(kDim);
  dl::FEValues<kDim> fev(*mapping, *fe, cell_quadrature(q_degree),
                         dl::update_values | dl::update_gradients | dl::update_JxW_values |
                             dl::update_quadrature_points);
  dl::FEValues<kDim> centre(*mapping, *fe, dl::Quadrature<kDim>(dl::Point<kDim>(0.25, 0.25, 0.25)),
                            dl::update_values | dl::update_gradients);
  dl::FEFaceValues<kDim> fefv(
      *mapping, *fe, face_quadrature(q_degree),
      dl::update_values | dl::update_normal_vectors | dl::update_JxW_values);
  std::vector<dl::SymmetricTensor<2, kDim>> eps(fev.n_quadrature_points);
  std::vector<double> p(fev.n_quadrature_points);
  const double inv_lambda = std::isinf(lambda) ? 0.0 : 1.0 / lambda;
  double energy = 0.0;
  double max_eig = -std::numeric_limits<double>::infinity();
  double max_abs = 0.0;
  result.tet_strain.assign(mesh.tets.size(), {});
  result.tet_stress.assign(mesh.tets.size(), {});
  const unsigned n = fe->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n);
  dl::Vector<double> f(n), u_local(n), r_local(n);
  dl::Vector<double> residual(dof.n_dofs());
  std::vector<dl::types::global_dof_index> dofs(n);
  std::vector<unsigned> dof_component(dof.n_dofs(), 0);
  for (const auto& cell : dof.active_cell_iterators()) {
    fev.reinit(cell);
    fev[disp].get_function_symmetric_gradients(solution, eps);
    if (mixed) fev[pres].get_function_values(solution, p);
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
      // W = ½∫ λ (tr ε)² + 2μ ε:ε  (displacement);  ½∫ 2μ ε:ε + p²/λ  (mixed, p = −λ tr ε)
      const double tr = dl::trace(eps[q]);
      const double w = mixed ? 2.0 * mu * (eps[q] * eps[q]) + inv_lambda * p[q] * p[q]
                             : lambda * tr * tr + 2.0 * mu * (eps[q] * eps[q]);
      energy += 0.5 * w * fev.JxW(q);
      const auto ev = dl::eigenvalues(eps[q]);  // descending
      max_eig = std::max(max_eig, ev[0]);
      max_abs = std::max({max_abs, std::abs(ev[0]), std::abs(ev[2])});
    }
    centre.reinit(cell);
    std::vector<dl::SymmetricTensor<2, kDim>> e1(1);
    std::vector<double> p1(1, 0.0);
    centre[disp].get_function_symmetric_gradients(solution, e1);
    if (mixed) centre[pres].get_function_values(solution, p1);
    const double pc = mixed ? p1[0] : -lambda * dl::trace(e1[0]);
    const dl::SymmetricTensor<2, kDim> sigma =
        2.0 * mu * e1[0] - pc * dl::unit_symmetric_tensor<kDim>();
    const auto idx = cell->active_cell_index();
    constexpr std::array<std::array<unsigned, 2>, 6> kVoigt{
        {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}}};
    for (unsigned v = 0; v < 6; ++v) {
      result.tet_strain[idx][v] = e1[0][kVoigt[v][0]][kVoigt[v][1]];
      result.tet_stress[idx][v] = sigma[kVoigt[v][0]][kVoigt[v][1]];
    }
    // Residual K_e u_e − f_e of the unconstrained system: the support reactions at Dirichlet DoFs.
    local_system(cell, fev, fefv, k, f, nullptr);
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < n; ++i) {
      u_local(i) = solution(dofs[i]);
      dof_component[dofs[i]] = fe->system_to_component_index(i).first;
    }
    k.vmult(r_local, u_local);
    r_local -= f;
    for (unsigned i = 0; i < n; ++i) residual(dofs[i]) += r_local(i);
  }
  result.strain_energy = energy;
  result.max_principal_strain = max_eig;
  result.max_abs_principal_strain = max_abs;

  result.reactions.clear();
  std::vector<std::string> seen;
  for (const auto& bc : problem.dirichlet) {
    if (std::find(seen.begin(), seen.end(), bc.group) != seen.end()) continue;
    seen.push_back(bc.group);
    const auto tag =
        static_cast<dl::types::boundary_id>(mesh.require_group(bc.group, 2, "FEM").tag);
    std::vector<bool> mask(n_components, false);
    mask[0] = mask[1] = mask[2] = true;
    const dl::IndexSet on_group =
        dl::DoFTools::extract_boundary_dofs(dof, dl::ComponentMask(mask), {tag});
    GroupReaction r{bc.group, Vec3::Zero()};
    for (const auto d : on_group) {
      if (constraints.is_constrained(d)) r.force[dof_component[d]] += residual(d);
    }
    result.reactions.push_back(r);
  }
}

ElasticitySolver::ElasticitySolver(const TetMesh& mesh, ElasticityProblem problem) {
  validate(mesh, problem);
  const auto t0 = Clock::now();
  impl_ = std::make_unique<Impl>(mesh, std::move(problem));
  auto& im = *impl_;
  const auto& o = im.problem.options;
  const double nu = im.problem.material.poisson_ratio;
  im.mixed = o.formulation == Formulation::mixed ||
             (o.formulation == Formulation::automatic && (nu >= o.mixed_threshold || nu == 0.5));
  im.degree = im.mixed ? 2 : o.degree;
  im.lambda = im.problem.material.lambda();
  im.mu = im.problem.material.mu();
  im.build_triangulation();
  im.setup_dofs();
  im.locator = std::make_unique<TetLocator>(im.mesh);
  im.result.element = im.mixed ? "P2-P1 (Taylor-Hood)" : (im.degree == 1 ? "P1" : "P2");
  im.result.formulation = im.mixed ? Formulation::mixed : Formulation::displacement;
  im.result.n_dofs = im.dof.n_dofs();
  if (im.mixed) {
    std::vector<bool> mask(4, false);
    mask[3] = true;
    im.result.n_pressure_dofs =
        dl::DoFTools::extract_dofs(im.dof, dl::ComponentMask(mask)).n_elements();
  }
  im.result.timings.setup = seconds_since(t0);
}

ElasticitySolver::~ElasticitySolver() = default;

const ElasticityResult& ElasticitySolver::solve() {
  auto& im = *impl_;
  auto t0 = Clock::now();
  im.assemble();
  im.result.timings.assembly = seconds_since(t0);
  t0 = Clock::now();
  im.solve_linear();
  im.result.timings.solve = seconds_since(t0);
  t0 = Clock::now();
  im.postprocess();
  im.result.timings.postprocess = seconds_since(t0);
  im.solved = true;
  return im.result;
}

const ElasticityResult& ElasticitySolver::result() const { return impl_->result; }

ElasticitySolver::Impl::PointStencil ElasticitySolver::Impl::point_stencil(const Vec3& x,
                                                                          double tol) const {
  const int t = locator->find(x, tol);
  if (t < 0) {
    std::ostringstream m;
    m << "point (" << x.x() * 1e3 << ", " << x.y() * 1e3 << ", " << x.z() * 1e3
      << ") mm is outside the FEM mesh: expected a point inside the vessel wall";
    throw InputError(m.str());
  }
  const auto& cell = cells[static_cast<std::size_t>(t)];
  const dl::Point<kDim> px(x.x(), x.y(), x.z());
  dl::Point<kDim> ref = linear_mapping->transform_real_to_unit_cell(cell, px);
  if (result.curved) {
    // The curved cell differs from the straight one only near the curved faces (O(h²)); use
    // the curved inverse where deal.II provides it, else the straight one.
    try {
      ref = mapping->transform_real_to_unit_cell(cell, px);
    } catch (...) {
    }
  }
  const unsigned n = fe->n_dofs_per_cell();
  std::vector<dl::types::global_dof_index> dofs(n);
  cell->get_dof_indices(dofs);
  PointStencil s;
  for (unsigned i = 0; i < n; ++i) {
    const unsigned c = fe->system_to_component_index(i).first;
    if (c >= 3) continue;
    s.dofs.push_back(dofs[i]);
    s.components.push_back(c);
    s.weights.push_back(fe->shape_value(i, ref));
  }
  return s;
}

std::vector<Vec3> ElasticitySolver::displacement_at(const std::vector<Vec3>& points,
                                                    double outside_tolerance) const {
  const auto& im = *impl_;
  if (!im.solved) throw std::logic_error("displacement_at called before solve()");
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const auto& x : points) {
    const auto st = im.point_stencil(x, outside_tolerance);
    Vec3 u = Vec3::Zero();
    for (std::size_t i = 0; i < st.dofs.size(); ++i)
      u[st.components[i]] += im.solution(st.dofs[i]) * st.weights[i];
    out.push_back(u);
  }
  return out;
}

double ElasticitySolver::relative_l2_error(const std::function<Vec3(const Vec3&)>& exact) const {
  const auto& im = *impl_;
  if (!im.solved) throw std::logic_error("relative_l2_error called before solve()");
  // Own loop rather than VectorTools::integrate_difference: with the curved MappingFEField on
  // simplices deal.II 9.4 returns NaN there, so the quadrature points are computed from the
  // geometry field itself (x_q = Σ x_i φ_i(ξ_q)) and only JxW comes from the mapping.
  const dl::QWitherdenVincentSimplex<kDim> quad(static_cast<unsigned>(im.degree + 2));
  const dl::FEValuesExtractors::Vector disp(0);
  dl::FEValues<kDim> fev(*im.mapping, *im.fe, quad, dl::update_values | dl::update_JxW_values);
  dl::FEValues<kDim> lin(*im.linear_mapping, *im.fe, quad, dl::update_quadrature_points);
  std::unique_ptr<dl::FEValues<kDim>> geo;
  if (im.result.curved) {
    geo = std::make_unique<dl::FEValues<kDim>>(*im.linear_mapping, *im.geometry_fe, quad,
                                               dl::update_values);
  }
  std::vector<dl::Tensor<1, kDim>> uh(quad.size());
  std::vector<dl::types::global_dof_index> gdofs(im.geometry_fe ? im.geometry_fe->n_dofs_per_cell()
                                                                : 0);
  double err2 = 0.0, norm2 = 0.0;
  for (const auto& cell : im.dof.active_cell_iterators()) {
    fev.reinit(cell);
    lin.reinit(cell);
    fev[disp].get_function_values(im.solution, uh);
    std::vector<Vec3> xq(quad.size());
    for (unsigned q = 0; q < quad.size(); ++q) {
      const auto& p = lin.quadrature_point(q);
      xq[q] = Vec3(p[0], p[1], p[2]);
    }
    if (geo) {
      const typename dl::DoFHandler<kDim>::active_cell_iterator gcell(
          &im.tria, cell->level(), cell->index(), &im.geometry_dof);
      geo->reinit(gcell);
      gcell->get_dof_indices(gdofs);
      for (unsigned q = 0; q < quad.size(); ++q) {
        Vec3 x = Vec3::Zero();
        for (unsigned i = 0; i < gdofs.size(); ++i) {
          x[im.geometry_fe->system_to_component_index(i).first] +=
              im.geometry_positions(gdofs[i]) * geo->shape_value(i, q);
        }
        xq[q] = x;
      }
    }
    for (unsigned q = 0; q < quad.size(); ++q) {
      const Vec3 u = exact(xq[q]);
      const Vec3 d = Vec3(uh[q][0], uh[q][1], uh[q][2]) - u;
      err2 += d.squaredNorm() * fev.JxW(q);
      norm2 += u.squaredNorm() * fev.JxW(q);
    }
  }
  return std::sqrt(err2 / norm2);
}

double ElasticitySolver::domain_volume() const {
  const auto& im = *impl_;
  dl::FEValues<kDim> fev(*im.mapping, *im.fe, cell_quadrature(2), dl::update_JxW_values);
  double v = 0.0;
  for (const auto& cell : im.dof.active_cell_iterators()) {
    fev.reinit(cell);
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) v += fev.JxW(q);
  }
  return v;
}

namespace {

using SpMat = Eigen::SparseMatrix<double>;

/// (K − σM)⁻¹ for Spectra's shift-invert mode, by CHOLMOD's supernodal Cholesky (K − σM is SPD
/// for σ < 0).
class ShiftInvertCholmod {
 public:
  using Scalar = double;
  ShiftInvertCholmod(const SpMat& k, const SpMat& m) : k_(k), m_(m) {}
  [[nodiscard]] Eigen::Index rows() const { return k_.rows(); }
  [[nodiscard]] Eigen::Index cols() const { return k_.cols(); }
  void set_shift(const double& sigma) {
    const SpMat a = k_ - sigma * m_;
    try {
      factor_ = std::make_unique<CholmodFactor>(a);
    } catch (const std::runtime_error&) {
      throw std::runtime_error("modal analysis: factorisation of K - sigma M failed");
    }
  }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = factor_->solve(x);
  }

 private:
  const SpMat& k_;
  const SpMat& m_;
  std::unique_ptr<CholmodFactor> factor_;
};

}  // namespace

ElasticitySolver::Impl::FreeSystem ElasticitySolver::Impl::assemble_free_system(
    bool with_mass) const {
  // The same local systems and constraint condensation as the static assemble(), into matrices
  // of their own (this is const); then the unconstrained rows and columns are kept.
  const dl::FEValuesExtractors::Vector disp(0);
  dl::FEValues<kDim> fev(*mapping, *fe, cell_quadrature(degree),
                         dl::update_values | dl::update_gradients | dl::update_JxW_values |
                             dl::update_quadrature_points);
  dl::FEFaceValues<kDim> fefv(
      *mapping, *fe, face_quadrature(degree),
      dl::update_values | dl::update_normal_vectors | dl::update_JxW_values);
  const unsigned n = fe->n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n), m(n, n);
  dl::Vector<double> f(n);
  std::vector<dl::types::global_dof_index> dofs(n);
  std::vector<unsigned> comp(n);
  for (unsigned i = 0; i < n; ++i) comp[i] = fe->system_to_component_index(i).first;
  dl::SparseMatrix<double> kd(sparsity), md;
  if (with_mass) md.reinit(sparsity);
  dl::Vector<double> fd(dof.n_dofs());
  const double rho = problem.material.density;
  for (const auto& cell : dof.active_cell_iterators()) {
    local_system(cell, fev, fefv, k, f, nullptr);  // leaves fev on this cell
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(k, f, dofs, kd, fd);
    if (!with_mass) continue;
    // Consistent mass M_ij = ∫ ρ φ_i·φ_j dV (nonzero only between equal components).
    m = 0.0;
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
      const double w = rho * fev.JxW(q);
      for (unsigned i = 0; i < n; ++i) {
        const double ni = fev.shape_value(i, q) * w;
        for (unsigned j = 0; j < n; ++j) {
          if (comp[i] == comp[j]) m(i, j) += ni * fev.shape_value(j, q);
        }
      }
    }
    constraints.distribute_local_to_global(m, dofs, md);
  }
  FreeSystem out;
  const std::size_t n_all = dof.n_dofs();
  out.free_index.assign(n_all, -1);
  out.constrained_value.assign(n_all, 0.0);
  int n_free = 0;
  for (std::size_t d = 0; d < n_all; ++d) {
    if (!constraints.is_constrained(d)) {
      out.free_index[d] = n_free++;
      continue;
    }
    // Only Dirichlet-type lines (u_d = g) exist here: no hanging nodes on this unrefined mesh.
    const auto* entries = constraints.get_constraint_entries(d);
    if (entries != nullptr && !entries->empty()) {
      throw std::logic_error("constraint couples DoFs: not supported by the free-DoF system");
    }
    out.constrained_value[d] = constraints.get_inhomogeneity(d);
  }
  auto to_eigen = [&](const dl::SparseMatrix<double>& a) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(a.n_nonzero_elements());
    for (std::size_t row = 0; row < n_all; ++row) {
      const int fr = out.free_index[row];
      if (fr < 0) continue;
      for (auto it = a.begin(row); it != a.end(row); ++it) {
        const int fc = out.free_index[it->column()];
        if (fc >= 0 && it->value() != 0.0) t.emplace_back(fr, fc, it->value());
      }
    }
    Eigen::SparseMatrix<double> e(n_free, n_free);
    e.setFromTriplets(t.begin(), t.end());
    return e;
  };
  out.K = to_eigen(kd);
  kd.clear();
  if (with_mass) out.M = to_eigen(md);
  out.f.resize(n_free);
  for (std::size_t d = 0; d < n_all; ++d) {
    if (out.free_index[d] >= 0) out.f[out.free_index[d]] = fd(d);
  }
  return out;
}

ModalResult ElasticitySolver::modes(int count) const {
  const auto& im = *impl_;
  if (im.mixed) {
    throw InputError(
        "modal analysis needs the displacement formulation (P1 or P2); the mixed "
        "Taylor-Hood system has no pressure mass: use nu below the mixed threshold");
  }
  if (count < 1) throw InputError("modal analysis: number of modes must be >= 1");
  if (!(im.problem.material.density > 0.0)) {
    throw InputError("modal analysis needs density > 0 (the mass matrix)");
  }
  const auto t0 = Clock::now();
  // K and the consistent mass M_ij = ∫ ρ φ_i·φ_j on the free DoFs (not Dirichlet or point
  // constrained): the constraints made homogeneous.
  auto sys = im.assemble_free_system(true);
  const int n_free = static_cast<int>(sys.K.rows());
  if (n_free <= count) throw InputError("modal analysis: fewer free DoFs than modes requested");
  const SpMat& k = sys.K;
  const SpMat& m = sys.M;
  const std::vector<int>& free_index = sys.free_index;

  ShiftInvertCholmod op(k, m);
  Spectra::SparseSymMatProd<double> bop(m);
  const int ncv = std::min(n_free, std::max(2 * count + 1, 30));
  // σ slightly below zero keeps K − σM positive definite even without constraints (rigid modes).
  const double sigma = -1.0;  // (rad/s)²
  Spectra::SymGEigsShiftSolver<ShiftInvertCholmod, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, count, ncv, sigma);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw std::runtime_error("modal analysis: the Lanczos iteration did not converge");
  }
  const Eigen::VectorXd lambda = eigs.eigenvalues();
  const Eigen::MatrixXd vectors = eigs.eigenvectors();
  ModalResult out;
  out.n_dofs = static_cast<std::size_t>(n_free);
  for (int e = 0; e < lambda.size(); ++e) {
    out.frequencies_hz.push_back(std::sqrt(std::max(lambda[e], 0.0)) / (2.0 * std::numbers::pi));
    std::vector<Vec3> shape(im.mesh.nodes.size(), Vec3::Zero());
    for (const auto& cell : im.dof.active_cell_iterators()) {
      for (unsigned v = 0; v < 4; ++v) {
        for (unsigned c = 0; c < 3; ++c) {
          const int fi = free_index[cell->vertex_dof_index(v, c)];
          shape[cell->vertex_index(v)][c] = fi < 0 ? 0.0 : vectors(fi, e);
        }
      }
    }
    double mx = 0.0;
    for (const auto& u : shape) mx = std::max(mx, u.norm());
    if (mx > 0.0)
      for (auto& u : shape) u /= mx;
    out.mode_shapes.push_back(std::move(shape));
  }
  out.seconds = seconds_since(t0);
  return out;
}

TransientResult ElasticitySolver::transient(const TransientOptions& o) const {
  const auto& im = *impl_;
  if (im.mixed) {
    throw InputError(
        "FEM transient needs the displacement formulation (P1 or P2); the mixed Taylor-Hood "
        "system is not supported: use --formulation displacement or nu below the mixed "
        "threshold");
  }
  std::ostringstream bad;
  if (!std::isfinite(o.dt) || o.dt <= 0.0) {
    bad << "transient time step dt = " << o.dt << " s is invalid: expected dt > 0";
  } else if (o.steps <= 0) {
    bad << "transient steps = " << o.steps << " is invalid: expected steps > 0";
  } else if (!std::isfinite(o.mass_damping) || o.mass_damping < 0.0) {
    bad << "transient mass damping alpha = " << o.mass_damping
        << " 1/s is invalid: expected alpha >= 0";
  } else if (!(im.problem.material.density > 0.0)) {
    bad << "FEM transient needs density > 0 (the mass matrix); found "
        << im.problem.material.density << " kg/m^3";
  }
  if (!bad.str().empty()) throw InputError(bad.str());
  // Probes first, so that a bad point fails before the expensive part.
  std::vector<Impl::PointStencil> probes;
  for (const auto& x : o.probe_points) probes.push_back(im.point_stencil(x, o.outside_tolerance));

  const auto t0 = Clock::now();
  const auto sys = im.assemble_free_system(true);
  const SpMat& K = sys.K;
  const SpMat& M = sys.M;
  const Eigen::VectorXd& f = sys.f;
  const double dt = o.dt, alpha = o.mass_damping;
  // Newmark, β = 1/4, γ = 1/2 (Newmark 1959; Hughes, The Finite Element Method, 2000, §9.1):
  //   u₁ = u₀ + dt v₀ + dt²/4 (a₀ + a₁),  v₁ = v₀ + dt/2 (a₀ + a₁),  M a + C v + K u = f,
  // so (K + 4/dt² M + 2/dt C) u₁ = f + M(4/dt² u₀ + 4/dt v₀ + a₀) + C(2/dt u₀ + v₀). With C = αM
  // and M a₀ = f − K u₀ − C v₀ (equilibrium at the previous step; no solve with M needed).
  const double cu = 4.0 / (dt * dt) + 2.0 * alpha / dt;
  const double cv = 4.0 / dt + alpha;
  const SpMat Keff = K + cu * M;
  const CholmodFactor factor(Keff);
  TransientResult r;
  r.setup_seconds = seconds_since(t0);
  r.n_dofs = im.dof.n_dofs();

  const Eigen::Index n = K.rows();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd Ma = f;  // M a₀ = f (at rest)
  auto value_of = [&](dl::types::global_dof_index d) {
    const int fi = sys.free_index[d];
    return fi < 0 ? sys.constrained_value[d] : u[fi];
  };
  auto record = [&](double t, const Eigen::VectorXd& Ku, const Eigen::VectorXd& Mv) {
    r.time.push_back(t);
    std::vector<Vec3> at(probes.size(), Vec3::Zero());
    for (std::size_t p = 0; p < probes.size(); ++p) {
      for (std::size_t i = 0; i < probes[p].dofs.size(); ++i)
        at[p][probes[p].components[i]] += value_of(probes[p].dofs[i]) * probes[p].weights[i];
    }
    r.probe_displacement.push_back(std::move(at));
    r.kinetic_energy.push_back(0.5 * v.dot(Mv));
    r.strain_energy.push_back(0.5 * u.dot(Ku));
    r.load_work.push_back(f.dot(u));
  };
  r.time.reserve(static_cast<std::size_t>(o.steps) + 1);
  record(0.0, Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n));
  const auto t1 = Clock::now();
  for (int step = 1; step <= o.steps; ++step) {
    const Eigen::VectorXd rhs = f + Ma + M * (cu * u + cv * v);
    Eigen::VectorXd u1 = factor.solve(rhs);
    v = (2.0 / dt) * (u1 - u) - v;  // v₁ = 2/dt (u₁ − u₀) − v₀ (γ = 1/2)
    u = std::move(u1);
    const Eigen::VectorXd Ku = K * u;
    const Eigen::VectorXd Mv = M * v;
    Ma = f - Ku - alpha * Mv;
    if (!u.allFinite()) {
      throw std::runtime_error("FEM transient: non-finite displacement at step " +
                               std::to_string(step));
    }
    record(step * dt, Ku, Mv);
  }
  r.seconds_per_step = seconds_since(t1) / o.steps;

  r.final_nodal_displacement.assign(im.mesh.nodes.size(), Vec3::Zero());
  for (const auto& cell : im.dof.active_cell_iterators()) {
    for (unsigned vtx = 0; vtx < 4; ++vtx) {
      for (unsigned c = 0; c < 3; ++c)
        r.final_nodal_displacement[cell->vertex_index(vtx)][c] =
            value_of(cell->vertex_dof_index(vtx, c));
    }
  }
  return r;
}

ElasticityResult solve_elasticity(const TetMesh& mesh, const ElasticityProblem& problem) {
  ElasticitySolver solver(mesh, problem);
  return solver.solve();
}

}  // namespace vessel::fem
