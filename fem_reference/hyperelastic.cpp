/// The finite-strain reference: the neo-Hookean kernel, the total-Lagrangian residual and tangent
/// (displacement or mixed u–p, dead loads from the linear reference's weak form, follower
/// pressure on the deformed faces), and Newton with a line search inside adaptive load stepping.
/// The discretisation (triangulation, DoFs, supports, linear solvers, point evaluation) is the
/// linear reference's (ElasticitySolver::Impl). Derivations: docs/physics/finite_strain.md.
#include "fem_reference/hyperelastic.hpp"

#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "fem_reference/detail/matrix_free_elasticity.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/self_contact.hpp"

namespace vessel::fem {

using detail::Clock;
using detail::seconds_since;

// ---------------------------------------------------------------------------------------------
// The material kernel.

double NeoHookean::energy(const Mat3& F) const {
  const double J = F.determinant();
  if (!(J > 0.0)) return std::numeric_limits<double>::infinity();
  const double ln_j = std::log(J);
  return 0.5 * mu * (F.squaredNorm() - 3.0) - mu * ln_j + 0.5 * lambda * ln_j * ln_j;
}

Mat3 NeoHookean::stress_at_pressure(const Mat3& F, double p, double mu) {
  const Mat3 f_inv_t = F.inverse().transpose();
  return mu * (F - f_inv_t) - p * f_inv_t;
}

Mat9 NeoHookean::tangent_at_pressure(const Mat3& F, double p, double mu) {
  // d(F⁻ᵀ)_aJ / dF_bL = −F⁻¹_Jb F⁻¹_La, so ∂[μF − (μ + p)F⁻ᵀ]/∂F as in the header.
  const Mat3 G = F.inverse();
  Mat9 A;
  for (int a = 0; a < 3; ++a)
    for (int J = 0; J < 3; ++J)
      for (int b = 0; b < 3; ++b)
        for (int L = 0; L < 3; ++L)
          A(3 * a + J, 3 * b + L) = (a == b && J == L ? mu : 0.0) + (mu + p) * G(J, b) * G(L, a);
  return A;
}

Mat3 NeoHookean::stress(const Mat3& F) const {
  return stress_at_pressure(F, -lambda * std::log(F.determinant()), mu);
}

Mat9 NeoHookean::tangent(const Mat3& F) const {
  const Mat3 f_inv_t = F.inverse().transpose();
  Mat9 A = tangent_at_pressure(F, -lambda * std::log(F.determinant()), mu);
  // p = −λ ln J depends on F: ∂p/∂F_bL = −λ F⁻ᵀ_bL, entering P through −p F⁻ᵀ.
  Eigen::Matrix<double, 9, 1> g;  // g(3a+J) = F⁻ᵀ_aJ
  for (int a = 0; a < 3; ++a)
    for (int J = 0; J < 3; ++J) g(3 * a + J) = f_inv_t(a, J);
  A += lambda * g * g.transpose();
  return A;
}

// ---------------------------------------------------------------------------------------------
// The solver.

namespace {

Mat3 to_mat3(const dl::Tensor<2, kDim>& t) {
  Mat3 m;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) m(i, j) = t[i][j];
  return m;
}

/// Which share of the tangent a pass over the cells computes: none, the follower pressure's
/// faces only (what the matrix-free Newton system adds to its operator), or all of it.
enum class Tangent { none, faces, all };

/// What one pass over the cells found, besides the local systems it handed on.
struct PassStats {
  bool valid = true;  ///< J > 0 at every quadrature point
  double min_jacobian = std::numeric_limits<double>::infinity();
  double energy = 0.0;     ///< ∫Ψ dV, J
  double dead_work = 0.0;  ///< f_dead · w at unit load (all DoFs), J
  double max_abs_strain = 0.0;  ///< with PassExtras::strain
};

/// What a pass computes besides the energy, the internal forces and its share of the tangent.
struct PassExtras {
  /// The dead loads f_dead and dead_work: left out (zero) where the load factor is 0 anyway.
  bool dead_loads = true;
  /// PassStats::max_abs_strain: a 3 × 3 eigenvalue problem per quadrature point.
  bool strain = false;
};

/// The largest |eigenvalue| of the Green–Lagrange strain E = ½(FᵀF − I).
double largest_principal_strain(const Mat3& F) {
  const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
  return Eigen::SelfAdjointEigenSolver<Mat3>()
      .computeDirect(E, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .cwiseAbs()
      .maxCoeff();
}

/// The free rows' block of a cell-by-cell assembled matrix, assembled straight into its
/// compressed columns: the pattern of every coupling of two free DoFs in a cell and, per cell in
/// deal.II's active cell order, where each entry (i, j) of its local matrix goes (−1 where row
/// or column is constrained). Entries are summed in cell order, as deal.II's SparseMatrix::add
/// sums them.
struct FreeBlockAssembly {
  Eigen::SparseMatrix<double> pattern;  ///< n_free × n_free, compressed, values zero
  std::vector<int> position;            ///< n_cells × n × n, row-major per cell
  unsigned n = 0;                       ///< DoFs per cell

  FreeBlockAssembly(const dl::DoFHandler<kDim>& dof, const std::vector<int>& free_index, int n_free)
      : n(dof.get_fe().n_dofs_per_cell()) {
    std::vector<Index> dofs(n);
    std::vector<Eigen::Triplet<double>> t;
    for (const auto& cell : dof.active_cell_iterators()) {
      cell->get_dof_indices(dofs);
      for (const Index a : dofs) {
        for (const Index b : dofs) {
          if (free_index[a] >= 0 && free_index[b] >= 0) {
            t.emplace_back(free_index[a], free_index[b], 0.0);
          }
        }
      }
    }
    pattern.resize(n_free, n_free);
    pattern.setFromTriplets(t.begin(), t.end());
    pattern.makeCompressed();
    const int* outer = pattern.outerIndexPtr();
    const int* inner = pattern.innerIndexPtr();
    for (const auto& cell : dof.active_cell_iterators()) {
      cell->get_dof_indices(dofs);
      for (const Index a : dofs) {
        for (const Index b : dofs) {
          const int r = free_index[a], c = free_index[b];
          if (r < 0 || c < 0) {
            position.push_back(-1);
            continue;
          }
          const int* at = std::lower_bound(inner + outer[c], inner + outer[c + 1], r);
          position.push_back(static_cast<int>(at - inner));
        }
      }
    }
  }

  /// m (a copy of the pattern) with the cell's local matrix k added at its positions.
  void add(std::size_t cell, const dl::FullMatrix<double>& k,
           Eigen::SparseMatrix<double>& m) const {
    double* values = m.valuePtr();
    const int* at = position.data() + cell * n * n;
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j < n; ++j, ++at) {
        if (*at >= 0) values[*at] += k(i, j);
      }
    }
  }

  /// m assembled: its zero entries left out (as a matrix from triplets of the non-zero values
  /// has them).
  static void finish(Eigen::SparseMatrix<double>& m) {
    m.prune([](Eigen::Index, Eigen::Index, double v) { return v != 0.0; });
  }
};

}  // namespace

struct HyperelasticSolver::Impl {
  ElasticitySolver linear;  // owns the discretisation
  ElasticitySolver::Impl& d;
  HyperelasticOptions opt;
  NeoHookean material;
  double inv_lambda = 0.0;
  bool mixed = false;
  bool symmetric = true;            // false with follower pressure (its tangent is not symmetric)
  /// The Newton systems by the matrix-free p-multigrid on the tangent (solver matrix-free, or
  /// automatic where the linear reference's rule takes it).
  bool matrix_free = false;
  /// matrix_free by `automatic`: a Krylov failure (an indefinite tangent) moves the solve to the
  /// assembled tangent instead of failing the Newton step.
  bool assembled_fallback = false;
  std::string solver_reason;        // why the Newton systems are solved as they are
  std::vector<unsigned> component;  // per DoF: 0..2 displacement, 3 pressure
  std::vector<Index> constrained;   // constrained DoFs
  std::vector<double> prescribed;   // their values at load factor 1
  std::vector<int> free_index;      // per DoF its row among the unconstrained ones, −1 if constrained
  int n_free = 0;
  std::optional<FreeBlockAssembly> free_block;  // free_state's Hessians' (built on first use)
  dl::Vector<double> pressure_volume;  // per pressure DoF: ∫ψ dV (scale of its residual)
  dl::Vector<double> u, internal;
  HyperelasticResult result;
  bool solved = false;

  Impl(const TetMesh& mesh, ElasticityProblem problem, HyperelasticOptions o)
      : linear(mesh, std::move(problem)), d(*linear.impl_), opt(o) {
    material = NeoHookean::of(d.problem.material);
    mixed = d.mixed;
    d.tangent_systems = true;
    inv_lambda = std::isinf(material.lambda) ? 0.0 : 1.0 / material.lambda;
    symmetric = !(opt.follower_pressure && !d.problem.pressures.empty());
    // Where requested, or under `automatic` for the unsymmetric tangent (follower pressure:
    // UMFPACK otherwise) where `automatic` takes the linear reference's matrix-free solve (P2 on
    // straight-sided tets from matrix_free_min_dofs): 2x faster than UMFPACK at P2 level 0, 17x
    // at level 1 in 1/18 of its memory (docs/measurements/finite_strain_solvers.md). The
    // symmetric tangent keeps CHOLMOD, whose symbolic analysis is reused over the Newton
    // systems: on the main job's contact references (P2 level 0, 40 Newton systems) the
    // matrix-free solves took twice as long. A Newton iterate's tangent can be indefinite (a
    // compressed or buckling wall), where the Krylov solve fails: a requested matrix-free solve
    // then halves the step; an automatic one moves to the assembled tangent for the rest.
    const bool requested = d.problem.options.solver == LinearSolver::matrix_free;
    assembled_fallback = d.problem.options.solver == LinearSolver::automatic && !d.mixed &&
                         !symmetric && d.linear_choice.solver == LinearSolver::matrix_free;
    matrix_free = requested || assembled_fallback;
    if (assembled_fallback) {
      solver_reason = d.linear_choice.reason +
                      "; follower pressure: the Newton systems on the matrix-free tangent, the "
                      "assembled one if its Krylov solve fails";
    } else if (requested) {
      solver_reason = d.linear_choice.reason;
    }
    if (!matrix_free) d.ensure_matrix();
    component = d.dof_components();
    free_index.assign(d.dof.n_dofs(), -1);
    for (Index i = 0; i < d.dof.n_dofs(); ++i) {
      if (d.constraints.is_constrained(i)) {
        constrained.push_back(i);
        prescribed.push_back(d.constraints.get_inhomogeneity(i));
      } else {
        free_index[i] = n_free++;
      }
    }
    u.reinit(d.dof.n_dofs());
    internal.reinit(d.dof.n_dofs());
    pressure_volume.reinit(d.dof.n_dofs());
    if (mixed) {
      detail::CellValues values(*d.mapping, *d.fe, d.degree);
      std::vector<Index> dofs(d.fe->n_dofs_per_cell());
      for (const auto& cell : d.dof.active_cell_iterators()) {
        values.cell.reinit(cell);
        cell->get_dof_indices(dofs);
        for (unsigned q = 0; q < values.cell.n_quadrature_points; ++q)
          for (unsigned i = 0; i < dofs.size(); ++i)
            if (component[dofs[i]] == 3)
              pressure_volume(dofs[i]) += values.cell.shape_value(i, q) * values.cell.JxW(q);
      }
    }
    result.element = d.result.element;
    result.formulation = d.result.formulation;
    result.n_dofs = d.dof.n_dofs();
    result.timings.setup = d.result.timings.setup;
  }

  /// One pass over the cells at DoF values `w` and load factor s: per cell, the residual
  /// r = f_int − f_follower − s f_dead and the share `tangent` of its tangent k = ∂r/∂u, handed
  /// to sink(dofs, k, r, r_int) with r_int = f_int alone.
  template <class Sink>
  PassStats pass(const dl::Vector<double>& w, double s, bool with_matrix, Sink&& sink,
                 PassExtras extras = {}) const {
    return pass(w, s, with_matrix ? Tangent::all : Tangent::none, sink, extras);
  }
  template <class Sink>
  PassStats pass(const dl::Vector<double>& w, double s, Tangent tangent, Sink&& sink,
                 PassExtras extras = {}) const {
    const bool with_matrix = tangent == Tangent::all;
    const unsigned n = d.fe->n_dofs_per_cell();
    detail::CellValues values(*d.mapping, *d.fe, d.degree);
    dl::FEFaceValues<kDim> face(*d.mapping, *d.fe, detail::face_quadrature(d.degree),
                                dl::update_values | dl::update_gradients |
                                    dl::update_normal_vectors | dl::update_JxW_values);
    const dl::FEValuesExtractors::Vector disp(0);
    const dl::FEValuesExtractors::Scalar pres(kDim);
    dl::FullMatrix<double> k(n, n);
    dl::Vector<double> r(n), r_int(n), f_dead(n);
    std::vector<Index> dofs(n);
    std::vector<unsigned> comp(n);
    for (unsigned i = 0; i < n; ++i) comp[i] = d.fe->system_to_component_index(i).first;
    const unsigned nq = values.cell.n_quadrature_points;
    std::vector<dl::Tensor<2, kDim>> grad_u(nq);
    std::vector<double> p_h(nq, 0.0);
    std::vector<dl::Tensor<2, kDim>> face_grad(face.n_quadrature_points);
    std::vector<Eigen::Vector3d> g(n);
    std::vector<Eigen::Matrix<double, 9, 1>> h(n);
    const bool dead_pressure = !opt.follower_pressure;
    PassStats stats;

    for (const auto& cell : d.dof.active_cell_iterators()) {
      if (extras.dead_loads) {
        d.form->local_load(cell, values, f_dead, nullptr, dead_pressure);  // reinits values.cell
      } else {
        values.cell.reinit(cell);
        f_dead = 0.0;
      }
      const auto& fev = values.cell;
      fev[disp].get_function_gradients(w, grad_u);
      if (mixed) fev[pres].get_function_values(w, p_h);
      cell->get_dof_indices(dofs);
      if (extras.dead_loads) {
        for (unsigned i = 0; i < n; ++i) stats.dead_work += f_dead(i) * w(dofs[i]);
      }
      k = 0.0;
      r_int = 0.0;
      for (unsigned q = 0; q < nq; ++q) {
        const Mat3 F = Mat3::Identity() + to_mat3(grad_u[q]);
        const double J = F.determinant();
        stats.min_jacobian = std::min(stats.min_jacobian, J);
        if (!(J > 0.0)) {
          stats.valid = false;
          return stats;
        }
        const double ln_j = std::log(J);
        const double jxw = fev.JxW(q);
        // p: the mixed field, or −λ ln J (compressible).
        const double p = mixed ? p_h[q] : -material.lambda * ln_j;
        const Mat3 P = NeoHookean::stress_at_pressure(F, p, material.mu);
        const double psi =
            0.5 * material.mu * (F.squaredNorm() - 3.0) - material.mu * ln_j +
            (mixed ? -p * ln_j - 0.5 * p * p * inv_lambda : 0.5 * material.lambda * ln_j * ln_j);
        stats.energy += psi * jxw;
        if (extras.strain) {
          stats.max_abs_strain = std::max(stats.max_abs_strain, largest_principal_strain(F));
        }
        // R_p = ∫ (−ln J − p/λ) ψ: stationarity of ∫ −p ln J − p²/(2λ) in p (p = −λ ln J).
        const double r_p = -ln_j - p * inv_lambda;
        for (unsigned i = 0; i < n; ++i) {
          if (comp[i] < 3) {
            const auto gi = fev.shape_grad(i, q);
            g[i] = Eigen::Vector3d(gi[0], gi[1], gi[2]);
            r_int(i) += P.row(comp[i]).dot(g[i]) * jxw;
          } else {
            r_int(i) += r_p * fev.shape_value(i, q) * jxw;
          }
        }
        if (with_matrix) add_point_tangent(F, p, fev, q, jxw, comp, g, h, k);
      }
      r = r_int;
      r.add(-s, f_dead);
      if (opt.follower_pressure) {
        const auto& faces = d.mesh_map.face_triangle[cell->active_cell_index()];
        for (unsigned fi = 0; fi < 4; ++fi) {
          double pressure = 0.0;
          if (faces[fi] < 0 || !d.form->pressure_on(faces[fi], pressure)) continue;
          add_follower_pressure(face, cell, fi, s * pressure, w, comp, face_grad,
                                tangent != Tangent::none, k, r, stats);
          if (!stats.valid) return stats;
        }
      }
      sink(dofs, k, r, r_int);
    }
    return stats;
  }

  /// Adds one quadrature point's tangent ∂r/∂w to k: the displacement block ∇vᵀ A ∇δu, and with
  /// the mixed field the couplings ∂R_u/∂p = −F⁻ᵀ : ∇v ψ, ∂R_p/∂u = −ψ F⁻ᵀ : ∇δu and −ψψ/λ.
  /// g holds the point's shape gradients (pass fills them); h is scratch.
  void add_point_tangent(const Mat3& F, double p, const dl::FEValues<kDim>& fev, unsigned q,
                         double jxw, const std::vector<unsigned>& comp,
                         const std::vector<Eigen::Vector3d>& g,
                         std::vector<Eigen::Matrix<double, 9, 1>>& h,
                         dl::FullMatrix<double>& k) const {
    const auto n = static_cast<unsigned>(comp.size());
    const Mat3 f_inv_t = F.inverse().transpose();
    const Mat9 A = mixed ? NeoHookean::tangent_at_pressure(F, p, material.mu) : material.tangent(F);
    for (unsigned j = 0; j < n; ++j) {
      if (comp[j] < 3) h[j] = A.middleCols<3>(3 * comp[j]) * g[j] * jxw;
    }
    for (unsigned i = 0; i < n; ++i) {
      const double vi = comp[i] < 3 ? 0.0 : fev.shape_value(i, q);
      for (unsigned j = 0; j < n; ++j) {
        const double vj = comp[j] < 3 ? 0.0 : fev.shape_value(j, q);
        double kij;
        if (comp[i] < 3 && comp[j] < 3) {
          kij = h[j].segment<3>(3 * comp[i]).dot(g[i]);
        } else if (comp[i] < 3) {
          kij = -f_inv_t.row(comp[i]).dot(g[i]) * vj * jxw;
        } else if (comp[j] < 3) {
          kij = -vi * f_inv_t.row(comp[j]).dot(g[j]) * jxw;
        } else {
          kij = -vi * vj * inv_lambda * jxw;
        }
        k(i, j) += kij;
      }
    }
  }

  /// The follower pressure on one face: f_ext = −p J F⁻ᵀ N dA (Nanson's n da = J F⁻ᵀ N dA),
  /// added to the residual as +p ∫ J F⁻ᵀN · v dA, with its tangent
  /// ∂/∂u: p ∫ J [(F⁻ᵀ:∇δu)(F⁻ᵀN) − (F⁻ᵀ ∇δuᵀ F⁻ᵀ N)]·v dA.
  void add_follower_pressure(dl::FEFaceValues<kDim>& face, const detail::CellIterator& cell,
                             unsigned fi, double pressure, const dl::Vector<double>& w,
                             const std::vector<unsigned>& comp,
                             std::vector<dl::Tensor<2, kDim>>& grad, bool with_matrix,
                             dl::FullMatrix<double>& k, dl::Vector<double>& r,
                             PassStats& stats) const {
    const dl::FEValuesExtractors::Vector disp(0);
    face.reinit(cell, fi);
    face[disp].get_function_gradients(w, grad);
    const unsigned n = face.dofs_per_cell;
    for (unsigned q = 0; q < face.n_quadrature_points; ++q) {
      const Mat3 F = Mat3::Identity() + to_mat3(grad[q]);
      const double J = F.determinant();
      if (!(J > 0.0)) {
        stats.valid = false;
        return;
      }
      const Mat3 G = F.inverse();
      const auto nn = face.normal_vector(q);
      const Eigen::Vector3d n0 = G.transpose() * Eigen::Vector3d(nn[0], nn[1], nn[2]);
      const double c = pressure * J * face.JxW(q);
      for (unsigned i = 0; i < n; ++i) {
        if (comp[i] >= 3) continue;
        const double phi_i = face.shape_value(i, q);
        if (phi_i == 0.0) continue;
        r(i) += c * n0[comp[i]] * phi_i;
        if (!with_matrix) continue;
        for (unsigned j = 0; j < n; ++j) {
          if (comp[j] >= 3) continue;
          const auto gj = face.shape_grad(j, q);
          const Eigen::Vector3d sj = G.transpose() * Eigen::Vector3d(gj[0], gj[1], gj[2]);
          k(i, j) += c * phi_i * (sj[comp[j]] * n0[comp[i]] - n0[comp[j]] * sj[comp[i]]);
        }
      }
    }
  }

  /// Residual norms at a pass: displacement rows relative to the internal force's norm (all
  /// DoFs: loads and reactions), pressure rows relative to ∫ψ dV (a volumetric strain).
  struct Norms {
    double force = 0.0, force_scale = 0.0, pressure = 0.0;
    [[nodiscard]] double relative(double scale) const {
      return std::max(force / std::max(scale, std::numeric_limits<double>::min()), pressure);
    }
  };

  /// Assembles the constrained Newton system into d.matrix (with_matrix) and d.rhs = −R, using
  /// d.constraints as they stand (their inhomogeneities: the prescribed increment).
  PassStats assemble(const dl::Vector<double>& w, double s, bool with_matrix, Norms& norms) {
    const auto t0 = Clock::now();
    if (with_matrix) d.matrix = 0.0;
    d.rhs = 0.0;
    internal = 0.0;
    dl::Vector<double> minus_r;
    const PassStats stats =
        pass(w, s, with_matrix,
             [&](const std::vector<Index>& dofs, const dl::FullMatrix<double>& k,
                 const dl::Vector<double>& r, const dl::Vector<double>& r_int) {
               minus_r = r;
               minus_r *= -1.0;
               if (with_matrix) {
                 d.constraints.distribute_local_to_global(k, minus_r, dofs, d.matrix, d.rhs);
               } else {
                 d.constraints.distribute_local_to_global(minus_r, dofs, d.rhs);
               }
               for (unsigned i = 0; i < dofs.size(); ++i) internal(dofs[i]) += r_int(i);
             });
    norms = residual_norms();
    result.timings.assembly += seconds_since(t0);
    return stats;
  }

  /// The norms of d.rhs = −R against the internal forces `internal`.
  [[nodiscard]] Norms residual_norms() const {
    Norms norms;
    double f2 = 0.0, s2 = 0.0, p_max = 0.0;
    for (Index i = 0; i < d.dof.n_dofs(); ++i) {
      if (component[i] < 3) {
        f2 += d.rhs(i) * d.rhs(i);
        s2 += internal(i) * internal(i);
      } else {
        p_max = std::max(p_max, std::abs(d.rhs(i)) / pressure_volume(i));
      }
    }
    norms.force = std::sqrt(f2);
    norms.force_scale = std::sqrt(s2);
    norms.pressure = p_max;
    return norms;
  }

  using AddedMatrix = detail::MatrixFreeElasticitySolver::AddedMatrix;

  /// The matrix-free Newton system's right-hand side d.rhs = −R on the free DoFs and, with
  /// follower pressure, its faces' share of the tangent into `follower` (free rows and columns;
  /// empty otherwise). `lift`: the prescribed increment (d.constraints' inhomogeneities) enters
  /// the free rows as −K u₀ (the tangent predictor), which takes every cell's tangent.
  PassStats assemble_matrix_free(const dl::Vector<double>& w, double s, bool lift, Norms& norms,
                                 AddedMatrix& follower) {
    const auto t0 = Clock::now();
    d.rhs = 0.0;
    internal = 0.0;
    const bool faces = !symmetric;
    std::vector<Eigen::Triplet<double>> entries;
    const auto add_faces = [&](const std::vector<Index>& dofs, const dl::FullMatrix<double>& k) {
      for (unsigned i = 0; i < dofs.size(); ++i) {
        if (free_index[dofs[i]] < 0) continue;
        for (unsigned j = 0; j < dofs.size(); ++j) {
          if (free_index[dofs[j]] >= 0 && k(i, j) != 0.0) {
            entries.emplace_back(static_cast<int>(dofs[i]), static_cast<int>(dofs[j]), k(i, j));
          }
        }
      }
    };
    dl::Vector<double> minus_r;
    PassStats stats = pass(w, s,
                           lift    ? Tangent::all
                           : faces ? Tangent::faces
                                   : Tangent::none,
                           [&](const std::vector<Index>& dofs, const dl::FullMatrix<double>& k,
                               const dl::Vector<double>& r, const dl::Vector<double>& r_int) {
                             minus_r = r;
                             minus_r *= -1.0;
                             if (lift) {
                               d.constraints.distribute_local_to_global(minus_r, dofs, d.rhs, k);
                             } else {
                               d.constraints.distribute_local_to_global(minus_r, dofs, d.rhs);
                               if (faces) add_faces(dofs, k);
                             }
                             for (unsigned i = 0; i < dofs.size(); ++i)
                               internal(dofs[i]) += r_int(i);
                           });
    if (stats.valid && faces && lift) {
      stats = pass(w, s, Tangent::faces,
                   [&](const std::vector<Index>& dofs, const dl::FullMatrix<double>& k, const auto&,
                       const auto&) { add_faces(dofs, k); });
    }
    const auto n = static_cast<Eigen::Index>(d.dof.n_dofs());
    follower.resize(faces ? n : 0, faces ? n : 0);
    follower.setFromTriplets(entries.begin(), entries.end());
    norms = residual_norms();
    result.timings.assembly += seconds_since(t0);
    return stats;
  }

  /// The neo-Hookean tangent's coefficients (F⁻¹, μ − λ ln J) at the residual's quadrature
  /// points at DoF values w (no element inverted: the pass at w checked it).
  [[nodiscard]] detail::NeoHookeanTangentState tangent_state(const dl::Vector<double>& w) const {
    detail::NeoHookeanTangentState state;
    state.quadrature = detail::cell_quadrature(d.degree);
    const unsigned nq = state.n_q();
    constexpr unsigned kPer = detail::NeoHookeanTangentState::kPerPoint;
    dl::FEValues<kDim> values(*d.mapping, *d.fe, state.quadrature, dl::update_gradients);
    const dl::FEValuesExtractors::Vector disp(0);
    std::vector<dl::Tensor<2, kDim>> grad_u(nq);
    state.values.resize(std::size_t{d.dof.get_triangulation().n_active_cells()} * nq * kPer);
    for (const auto& cell : d.dof.active_cell_iterators()) {
      values.reinit(cell);
      values[disp].get_function_gradients(w, grad_u);
      for (unsigned q = 0; q < nq; ++q) {
        const Mat3 F = Mat3::Identity() + to_mat3(grad_u[q]);
        const Mat3 g = F.inverse();
        double* v = state.values.data() + (std::size_t{cell->active_cell_index()} * nq + q) * kPer;
        for (unsigned i = 0; i < kDim; ++i)
          for (unsigned j = 0; j < kDim; ++j) v[kDim * i + j] = g(i, j);
        v[kDim * kDim] = material.mu - material.lambda * std::log(F.determinant());
      }
    }
    return state;
  }

  /// The Newton system d.rhs (from assemble_matrix_free) by CG (FGMRES with follower pressure)
  /// on the matrix-free tangent at u with the p-multigrid; d.solution with the constraints'
  /// values (the prescribed increment) distributed.
  void solve_tangent_matrix_free(const AddedMatrix& follower) {
    const auto& o = d.problem.options;
    const detail::NeoHookeanTangentState state = tangent_state(u);
    detail::PMultigridSettings settings;
    settings.direct_coarse_max_dofs = o.matrix_free_direct_coarse_max_dofs;
    const detail::MatrixFreeElasticitySolver tangent(
        *d.mapping, d.dof,
        [this](const dl::DoFHandler<kDim>& dof, dl::AffineConstraints<double>& c) {
          d.support_constraints(dof, c);
        },
        d.degree, material.lambda, material.mu, detail::node_centroid(d.mesh), settings, &state);
    d.solution = 0.0;
    const auto outcome = tangent.solve(d.rhs, d.solution, o.cg_relative_tolerance, o.max_iterations,
                                       symmetric ? nullptr : &follower);
    d.constraints.distribute(d.solution);
    d.result.iterations = outcome.iterations;
    d.result.solver = LinearSolver::matrix_free;
    add_profile(result.matrix_free, tangent.profile());
  }

  /// total += one, part by part (the method and per-system counts: one's).
  static void add_profile(MatrixFreeProfile& total, const MatrixFreeProfile& one) {
    for (const auto member :
         {&MatrixFreeProfile::fine_operator, &MatrixFreeProfile::coarse_level,
          &MatrixFreeProfile::transfer, &MatrixFreeProfile::diagonal,
          &MatrixFreeProfile::eigenvalue_estimate, &MatrixFreeProfile::coarse_matrix,
          &MatrixFreeProfile::coarse_factor, &MatrixFreeProfile::cg,
          &MatrixFreeProfile::operator_seconds, &MatrixFreeProfile::coarse_solve_seconds,
          &MatrixFreeProfile::transfer_seconds}) {
      total.*member += one.*member;
    }
    for (const auto member :
         {&MatrixFreeProfile::coarse_iterations, &MatrixFreeProfile::operator_applications,
          &MatrixFreeProfile::coarse_solves}) {
      total.*member += one.*member;
    }
    total.coarse_method = one.coarse_method;
    total.chebyshev_degree = one.chebyshev_degree;
    total.quadrature_points = one.quadrature_points;
  }

  void set_prescribed_increment(double ds) {
    for (std::size_t c = 0; c < constrained.size(); ++c)
      d.constraints.set_inhomogeneity(constrained[c], ds * prescribed[c]);
  }

  struct StepOutcome {
    bool converged = false;
    int iterations = 0;
    double residual = 0.0;
    std::string reason;
  };

  /// The assembled Newton system at (u, s) into d.solution: matrix-free, or directly. Away from
  /// equilibrium (a Newton iterate after a large increment) the symmetric tangent can be
  /// indefinite, which CHOLMOD refuses: LU (UMFPACK) solves it.
  void solve_newton_system(const AddedMatrix& follower, double s) {
    if (matrix_free) {
      try {
        solve_tangent_matrix_free(follower);
        return;
      } catch (const std::runtime_error& e) {
        if (!assembled_fallback) throw;
        // This system and the rest of the solve on the assembled tangent (the same system:
        // the prescribed increment is in the constraints already).
        matrix_free = false;
        solver_reason +=
            std::string("; it failed (") + e.what() + "): the assembled tangent from then on";
        d.ensure_matrix();
        Norms norms;
        assemble(u, s, true, norms);
      }
    }
    try {
      d.solve_linear(symmetric, DirectReuse::analysis);
    } catch (const std::exception&) {
      if (!symmetric || d.mixed) throw;
      d.solve_linear(false);
    }
  }

  /// Newton from the equilibrium u at s0 to s1; u is left at the new equilibrium on success.
  StepOutcome newton_step(double s0, double s1) {
    StepOutcome out;
    const bool moves_supports =
        std::any_of(prescribed.begin(), prescribed.end(), [](double v) { return v != 0.0; });
    Norms norms;
    for (int it = 0; it <= opt.max_newton_iterations; ++it) {
      // The first iteration moves the supports by their whole increment (a tangent predictor);
      // later updates leave them where they are.
      const bool predictor = it == 0 && moves_supports;
      set_prescribed_increment(predictor ? s1 - s0 : 0.0);
      AddedMatrix follower;
      const PassStats st = matrix_free ? assemble_matrix_free(u, s1, predictor, norms, follower)
                                       : assemble(u, s1, true, norms);
      if (!st.valid) {
        out.reason = "an element inverted (J <= 0)";
        return out;
      }
      const double scale = norms.force_scale;
      out.residual = norms.relative(scale);
      if (!predictor && out.residual <= opt.residual_tolerance) {
        out.converged = true;
        out.iterations = it;
        return out;
      }
      if (it == opt.max_newton_iterations) break;
      const auto t0 = Clock::now();
      try {
        solve_newton_system(follower, s1);
      } catch (const std::exception& e) {
        result.timings.solve += seconds_since(t0);
        out.reason = std::string("the linear solve failed: ") + e.what();
        out.iterations = it + 1;
        return out;
      }
      result.timings.solve += seconds_since(t0);
      result.linear_iterations += d.result.iterations;
      result.solver = d.result.solver;
      result.solver_reason = solver_reason.empty() ? d.result.solver_reason : solver_reason;
      ++result.newton_iterations;
      out.iterations = it + 1;
      if (predictor) {
        u += d.solution;
        continue;
      }
      // Backtracking line search. A step is accepted when it decreases the residual's norm or,
      // where the problem has a potential Π(u) = ∫Ψ dV − s f_dead·u (dead loads, displacement
      // form: the tangent is Π's Hessian), when it meets Armijo's condition on Π (Nocedal &
      // Wright, Numerical Optimization, eq. 3.4). The residual's norm alone rejects the full
      // Newton step of a tube sagging between clamped ends: the step is right, but its
      // membrane forces raise the norm (gravity_sag took 10+ damped iterations per step).
      // Follower pressure has no potential, and the mixed form's Π is a saddle.
      const dl::Vector<double> du = d.solution;
      const dl::Vector<double> u0 = u;
      const double merit0 = out.residual;
      const double energy0 = st.energy - s1 * st.dead_work;
      const double slope = -(d.rhs * du);  // ∇Π·du = R·du, d.rhs = −R on the free DoFs
      const bool energy_merit = symmetric && !mixed && slope < 0.0;
      double alpha = 1.0;
      bool accepted = false;
      for (int ls = 0; ls <= opt.max_line_search; ++ls, alpha *= 0.5) {
        u = u0;
        u.add(alpha, du);
        Norms trial;
        const PassStats ts = assemble(u, s1, false, trial);
        if (!ts.valid) continue;
        const bool residual_decreases = trial.relative(scale) <= (1.0 - 1e-4 * alpha) * merit0;
        const bool energy_decreases =
            energy_merit && ts.energy - s1 * ts.dead_work <= energy0 + 1e-4 * alpha * slope;
        if (residual_decreases || energy_decreases) {
          accepted = true;
          break;
        }
      }
      if (!accepted) {
        // At round-off no step decreases the residual: accept when the update is negligible.
        if (du.linfty_norm() <= 1e-12 * std::max(u0.linfty_norm(), 1e-300) &&
            merit0 <= 1e3 * opt.residual_tolerance) {
          u = u0;
          out.converged = true;
          return out;
        }
        u = u0;
        std::ostringstream m;
        m << "the line search found no decrease of the residual (relative residual " << merit0
          << ")";
        out.reason = m.str();
        return out;
      }
    }
    std::ostringstream m;
    m << "Newton did not converge in " << opt.max_newton_iterations
      << " iterations (relative residual " << out.residual << ")";
    out.reason = m.str();
    return out;
  }

  /// Load stepping; `self` and `observer` serve the checkpoints.
  void solve(const HyperelasticSolver& self, const CheckpointObserver& observer) {
    result.steps.clear();
    result.checkpoints.clear();
    result.rejected_steps = 0;
    result.newton_iterations = 0;
    result.linear_iterations = 0;
    result.timings.assembly = result.timings.solve = 0.0;
    u = 0.0;
    double s = 0.0;
    double ds = std::min(opt.initial_step, opt.max_step);
    const double target = opt.target_load_factor;
    std::size_t next = 0;  // the next checkpoint
    result.completed = true;
    result.self_contact = false;
    result.stop_reason.clear();
    while (s < target * (1.0 - 1e-14)) {
      // A step ends at the next checkpoint when it would pass it, or reach it within round-off
      // (steps of 0.1 sum to 0.9999999999999999, not 1); ds itself (the increment the adaptation
      // has learnt) is kept for the steps after it.
      const double stop = next < opt.checkpoints.size() ? opt.checkpoints[next] : target;
      const bool to_stop = ds >= (stop - s) - 1e-12 * stop;
      const double step = to_stop ? stop - s : ds;
      const dl::Vector<double> u_start = u;
      StepOutcome o = newton_step(s, s + step);
      bool self_contact = false;
      if (o.converged && opt.stop_at_self_contact) {
        o.reason = self_penetration();
        self_contact = !o.reason.empty();
        o.converged = !self_contact;
      }
      if (o.converged) {
        s = to_stop ? stop : s + step;
        result.steps.push_back({s, o.iterations, o.residual});
        if (o.iterations <= opt.fast_iterations) ds = std::min(ds * opt.growth, opt.max_step);
        if (to_stop && next < opt.checkpoints.size()) {
          ++next;
          const std::string why = checkpoint(self, s, observer);
          if (!why.empty()) {
            result.completed = false;
            result.stop_reason = why;
            break;
          }
        }
        continue;
      }
      u = u_start;
      ++result.rejected_steps;
      if (step * 0.5 < opt.min_step) {
        std::ostringstream m;
        m << (self_contact ? "no equilibrium without self-contact beyond load factor "
                           : "no equilibrium found beyond load factor ")
          << s << ": at " << s + step << ", " << o.reason << "; the increment " << step
          << " cannot be halved below the minimum " << opt.min_step;
        result.completed = false;
        result.self_contact = self_contact;
        result.stop_reason = m.str();
        break;
      }
      ds = step * 0.5;
    }
    d.release_same_pattern();  // the last tangent's factor: gigabytes at level 1
    result.load_factor = s;
    set_prescribed_increment(0.0);
    const auto t0 = Clock::now();
    const PassStats st = pass(u, s, false, [](auto&&...) {}, {.strain = true});
    result.strain_energy = st.energy;
    result.max_abs_principal_strain = st.max_abs_strain;
    result.min_jacobian = st.min_jacobian;
    d.solution = u;
    d.solved = true;
    result.nodal_displacement = d.nodal([&](Index i) { return u(i); });
    result.timings.postprocess = seconds_since(t0);
    solved = true;
  }

  /// Empty when the wall at the current state u does not pass through itself; else what does.
  std::string self_penetration() const {
    const std::vector<Vec3> disp = d.nodal([&](Index i) { return u(i); });
    const SelfPenetration p = find_self_penetration(d.mesh, disp);
    if (p.nodes.empty()) return {};
    const Vec3 x = d.mesh.nodes[static_cast<std::size_t>(p.nodes.front())] * 1e3;
    std::ostringstream m;
    m << "the wall passes through itself (" << p.nodes.size()
      << " surface nodes inside the wall elsewhere, the first at rest point (" << x.x() << ", "
      << x.y() << ", " << x.z() << ") mm; this reference models no self-contact)";
    return m.str();
  }

  /// Records the equilibrium at checkpoint s and asks the observer whether to go on.
  std::string checkpoint(const HyperelasticSolver& self, double s,
                         const CheckpointObserver& observer) {
    Checkpoint c;
    c.load_factor = s;
    c.load_steps = static_cast<int>(result.steps.size());
    c.rejected_steps = result.rejected_steps;
    c.newton_iterations = result.newton_iterations;
    c.seconds = result.timings.assembly + result.timings.solve;
    c.nodal_displacement = d.nodal([&](Index i) { return u(i); });
    result.checkpoints.push_back(std::move(c));
    if (!observer) return {};
    d.solution = u;  // what displacement_at reads
    d.solved = true;
    solved = true;
    result.load_factor = s;
    return observer(self, result.checkpoints.back());
  }
};

HyperelasticSolver::HyperelasticSolver(const TetMesh& mesh, ElasticityProblem problem,
                                       HyperelasticOptions options) {
  const auto& o = options;
  auto require = [](bool ok, const char* what) {
    if (!ok) throw InputError(std::string("finite-strain option ") + what);
  };
  require(o.target_load_factor > 0.0 && std::isfinite(o.target_load_factor),
          "target_load_factor: expected a finite number > 0");
  require(o.min_step > 0.0 && o.initial_step >= o.min_step && o.max_step >= o.min_step,
          "steps: expected 0 < min_step <= initial_step and min_step <= max_step");
  require(o.growth >= 1.0, "growth: expected >= 1");
  require(o.max_newton_iterations > 0 && o.max_line_search >= 0,
          "iterations: expected max_newton_iterations > 0 and max_line_search >= 0");
  require(o.residual_tolerance > 0.0, "residual_tolerance: expected > 0");
  for (std::size_t i = 0; i < o.checkpoints.size(); ++i) {
    const double c = o.checkpoints[i];
    require(c > 0.0 && c <= o.target_load_factor && (i == 0 || c > o.checkpoints[i - 1]),
            "checkpoints: expected ascending load factors in (0, target_load_factor]");
  }
  impl_ = std::make_unique<Impl>(mesh, std::move(problem), options);
}

HyperelasticSolver::~HyperelasticSolver() = default;

const HyperelasticResult& HyperelasticSolver::solve(const CheckpointObserver& observer) {
  impl_->solve(*this, observer);
  return impl_->result;
}

const HyperelasticResult& HyperelasticSolver::result() const { return impl_->result; }

std::vector<Vec3> HyperelasticSolver::displacement_at(const std::vector<Vec3>& points,
                                                      double outside_tolerance) const {
  if (!impl_->solved) throw std::logic_error("displacement_at called before solve()");
  return impl_->linear.displacement_at(points, outside_tolerance);
}

double HyperelasticSolver::relative_l2_error(const std::function<Vec3(const Vec3&)>& exact) const {
  if (!impl_->solved) throw std::logic_error("relative_l2_error called before solve()");
  return impl_->linear.relative_l2_error(exact);
}

std::vector<Vec3> HyperelasticSolver::free_displacement_at(const Eigen::VectorXd& u_free,
                                                           const std::vector<Vec3>& points,
                                                           double outside_tolerance) const {
  const auto& im = *impl_;
  if (u_free.size() != im.n_free) {
    throw std::invalid_argument("free_displacement_at: wrong number of free DoF values");
  }
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Vec3& x : points) {
    const auto st = im.d.point_stencil(x, outside_tolerance);
    Vec3 u = Vec3::Zero();
    for (std::size_t i = 0; i < st.dofs.size(); ++i) {
      const int row = im.free_index[st.dofs[i]];
      if (row >= 0) u[st.components[i]] += u_free[row] * st.weights[i];
    }
    out.push_back(u);
  }
  return out;
}

std::vector<std::vector<int>> HyperelasticSolver::free_rows_per_cell() const {
  const auto& im = *impl_;
  std::vector<Index> dofs(im.d.fe->n_dofs_per_cell());
  std::vector<std::vector<int>> out;
  out.reserve(im.d.dof.get_triangulation().n_active_cells());
  for (const auto& cell : im.d.dof.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    std::vector<int>& rows = out.emplace_back();
    for (unsigned i = 0; i < dofs.size(); ++i) {
      if (im.free_index[dofs[i]] >= 0 && im.component[dofs[i]] < 3)
        rows.push_back(im.free_index[dofs[i]]);
    }
  }
  return out;
}

std::vector<int> HyperelasticSolver::inverted_cells(const Eigen::VectorXd& u_free) const {
  const auto& im = *impl_;
  if (u_free.size() != im.n_free) {
    throw std::invalid_argument("inverted_cells: wrong number of free DoF values");
  }
  dl::Vector<double> w(im.d.dof.n_dofs());
  for (Index i = 0; i < w.size(); ++i) {
    if (im.free_index[i] >= 0) w(i) = u_free[im.free_index[i]];
  }
  detail::CellValues values(*im.d.mapping, *im.d.fe, im.d.degree);
  const dl::FEValuesExtractors::Vector disp(0);
  std::vector<dl::Tensor<2, kDim>> grad_u(values.cell.n_quadrature_points);
  std::vector<int> out;
  int index = 0;
  for (const auto& cell : im.d.dof.active_cell_iterators()) {
    values.cell.reinit(cell);
    values.cell[disp].get_function_gradients(w, grad_u);
    for (const auto& g : grad_u) {
      if (!((Mat3::Identity() + to_mat3(g)).determinant() > 0.0)) {
        out.push_back(index);
        break;
      }
    }
    ++index;
  }
  return out;
}

FreeDisplacementSystem HyperelasticSolver::free_dofs() const {
  if (impl_->mixed) {
    throw InputError("the free DoFs' state is for the displacement formulation, not the mixed one");
  }
  FreeDisplacementSystem out;
  out.free_index = impl_->free_index;
  out.node_rows = impl_->d.node_rows(out.free_index);
  impl_->d.set_row_points(out);
  return out;
}

namespace {

/// k with its negative eigenvalues set to zero (k symmetric).
void project_onto_psd_cone(dl::FullMatrix<double>& k) {
  const auto n = static_cast<Eigen::Index>(k.m());
  Eigen::MatrixXd a(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) a(i, j) = k(i, j);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(a);
  if (es.eigenvalues().minCoeff() >= 0.0) return;
  a = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() *
      es.eigenvectors().transpose();
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) k(i, j) = a(i, j);
}

}  // namespace

FreeHyperelasticState HyperelasticSolver::free_state(const Eigen::VectorXd& u_free,
                                                     FreeTangents tangents,
                                                     bool with_strain) const {
  auto& im = *impl_;
  if (im.mixed) {
    throw InputError("the free DoFs' state is for the displacement formulation, not the mixed one");
  }
  if (u_free.size() != im.n_free) {
    throw std::invalid_argument("free_state: wrong number of free DoF values");
  }
  dl::Vector<double> w(im.d.dof.n_dofs());
  for (Index i = 0; i < w.size(); ++i) {
    if (im.free_index[i] >= 0) w(i) = u_free[im.free_index[i]];
  }
  const bool exact = tangents == FreeTangents::exact || tangents == FreeTangents::both;
  const bool projected = tangents == FreeTangents::projected || tangents == FreeTangents::both;
  if ((exact || projected) && !im.free_block)
    im.free_block.emplace(im.d.dof, im.free_index, im.n_free);
  FreeHyperelasticState out;
  if (exact) out.tangent = im.free_block->pattern;
  if (projected) out.projected_tangent = im.free_block->pattern;
  out.gradient = Eigen::VectorXd::Zero(im.n_free);
  dl::FullMatrix<double> k_projected;
  std::size_t cell = 0;
  // Load factor 0: the strain energy alone (loads and prescribed values are not applied).
  const PassStats st = im.pass(w, 0.0, exact || projected,
                               [&](const std::vector<Index>& dofs, const dl::FullMatrix<double>& k,
                                   const auto&, const dl::Vector<double>& r_int) {
                                 for (unsigned i = 0; i < dofs.size(); ++i) {
                                   const int fi = im.free_index[dofs[i]];
                                   if (fi >= 0) out.gradient[fi] += r_int(i);
                                 }
                                 if (exact) im.free_block->add(cell, k, out.tangent);
                                 if (projected) {
                                   k_projected = k;
                                   project_onto_psd_cone(k_projected);
                                   im.free_block->add(cell, k_projected, out.projected_tangent);
                                 }
                                 ++cell;
                               },
                               {.dead_loads = false, .strain = with_strain});
  out.admissible = st.valid;
  out.min_jacobian = st.min_jacobian;
  if (!st.valid) {
    out.energy = std::numeric_limits<double>::infinity();
    out.tangent = {};
    out.projected_tangent = {};
    return out;
  }
  out.energy = st.energy;
  out.max_abs_principal_strain = st.max_abs_strain;
  if (exact) FreeBlockAssembly::finish(out.tangent);
  if (projected) FreeBlockAssembly::finish(out.projected_tangent);
  return out;
}

std::size_t HyperelasticSolver::n_dofs() const { return impl_->d.dof.n_dofs(); }

std::vector<unsigned> HyperelasticSolver::dof_components() const { return impl_->component; }

std::vector<double> HyperelasticSolver::residual(const std::vector<double>& u, double s) const {
  const auto& im = *impl_;
  if (u.size() != n_dofs()) throw std::invalid_argument("residual: wrong number of DoF values");
  dl::Vector<double> w(u.begin(), u.end());
  std::vector<double> out(n_dofs(), 0.0);
  const PassStats st = im.pass(
      w, s, false,
      [&](const std::vector<Index>& dofs, const auto&, const dl::Vector<double>& r, const auto&) {
        for (unsigned i = 0; i < dofs.size(); ++i) out[dofs[i]] += r(i);
      });
  if (!st.valid) throw std::invalid_argument("residual: an element is inverted (J <= 0)");
  return out;
}

std::vector<std::vector<double>> HyperelasticSolver::tangent_columns(const std::vector<double>& u,
                                                                     double s) const {
  const auto& im = *impl_;
  if (u.size() != n_dofs()) throw std::invalid_argument("tangent: wrong number of DoF values");
  dl::Vector<double> w(u.begin(), u.end());
  std::vector<std::vector<double>> cols(n_dofs(), std::vector<double>(n_dofs(), 0.0));
  const PassStats st = im.pass(w, s, true,
                               [&](const std::vector<Index>& dofs, const dl::FullMatrix<double>& k,
                                   const auto&, const auto&) {
                                 for (unsigned i = 0; i < dofs.size(); ++i)
                                   for (unsigned j = 0; j < dofs.size(); ++j)
                                     cols[dofs[j]][dofs[i]] += k(i, j);
                               });
  if (!st.valid) throw std::invalid_argument("tangent: an element is inverted (J <= 0)");
  return cols;
}

namespace {
/// The matrix-free tangent of `im` (HyperelasticSolver's, private: deduced) at u, on f(op).
template <typename Impl, typename Use>
std::vector<double> with_tangent_operator(const Impl& im, const std::vector<double>& u,
                                          const char* what, const Use& f) {
  if (im.mixed) {
    throw InputError(
        "the matrix-free tangent is for the displacement formulation, not the mixed one");
  }
  if (u.size() != im.d.dof.n_dofs()) {
    throw std::invalid_argument(std::string(what) + ": wrong number of DoF values");
  }
  detail::ensure_mpi_initialized();
  const dl::Vector<double> w(u.begin(), u.end());
  const detail::NeoHookeanTangentState state = im.tangent_state(w);
  const auto homogeneous = detail::homogeneous_copy(im.d.constraints);
  const detail::ElasticityOperator op(*im.d.mapping, im.d.dof, homogeneous, im.d.degree,
                                      im.material.lambda, im.material.mu, 1, &state);
  const detail::MfVector out = f(op);
  return {out.begin(), out.end()};
}
}  // namespace

std::vector<double> HyperelasticSolver::matrix_free_tangent_diagonal(
    const std::vector<double>& u) const {
  return with_tangent_operator(*impl_, u, "matrix_free_tangent_diagonal",
                               [](const detail::ElasticityOperator& op) { return op.diagonal(); });
}

std::vector<double> HyperelasticSolver::matrix_free_tangent_product(
    const std::vector<double>& u, const std::vector<double>& v) const {
  if (v.size() != n_dofs()) {
    throw std::invalid_argument("matrix_free_tangent_product: wrong number of DoF values");
  }
  return with_tangent_operator(*impl_, u, "matrix_free_tangent_product",
                               [&](const detail::ElasticityOperator& op) {
                                 detail::MfVector src, dst;
                                 op.initialize_dof_vector(src);
                                 op.initialize_dof_vector(dst);
                                 std::copy(v.begin(), v.end(), src.begin());
                                 op.vmult(dst, src);
                                 return dst;
                               });
}

}  // namespace vessel::fem
