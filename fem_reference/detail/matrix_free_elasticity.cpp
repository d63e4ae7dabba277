#include "fem_reference/detail/matrix_free_elasticity.hpp"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/tools.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "fem_reference/cholmod_solve.hpp"
#include "meshes/foundation/solver_threads.hpp"

namespace vessel::fem::detail {

namespace {

using Evaluation = dl::FEEvaluation<kDim, -1, 0, kDim, double>;
using Number = dl::VectorizedArray<double>;

/// At each quadrature point σ = λ tr(ε) I + 2μ ε of the cell's ε(u), tested with ε(v): the
/// displacement weak form of detail/weak_form (step-8's a(u, v)).
void stress_divergence(Evaluation& phi, double lambda, double mu) {
  phi.evaluate(dl::EvaluationFlags::gradients);
  for (unsigned q = 0; q < phi.n_q_points; ++q) {
    const dl::SymmetricTensor<2, kDim, Number> eps = phi.get_symmetric_gradient(q);
    const Number lambda_trace = lambda * dl::trace(eps);
    dl::SymmetricTensor<2, kDim, Number> sigma = (2.0 * mu) * eps;
    for (unsigned d = 0; d < kDim; ++d) sigma[d][d] += lambda_trace;
    phi.submit_symmetric_gradient(sigma, q);
  }
  phi.integrate(dl::EvaluationFlags::gradients);
}

/// Cells per batch of the straight-tet kernel: one AVX-512 register of doubles per quantity
/// (two AVX2, four SSE2 registers).
constexpr unsigned kLanes = 8;
/// Doubles per cell of a batch's geometry: J⁻ᵀ (∂ξ_e/∂x_d at [3d + e]) and |det J|.
constexpr unsigned kGeometry = kDim * kDim + 1;
/// Two, four and eight doubles as one GCC vector: arithmetic on them is lane-wise (a scalar
/// operand is broadcast); an SSE2, an AVX2 and an AVX-512 register.
using Lanes2 = double __attribute__((vector_size(2 * sizeof(double))));
using Lanes4 = double __attribute__((vector_size(4 * sizeof(double))));
using Lanes8 = double __attribute__((vector_size(8 * sizeof(double))));

/// The cell loop the straight-tet kernels share, on V's lanes of a batch's kLanes straight-sided
/// tets (struct of arrays: entry [k·kLanes + l] belongs to cell l; the pointers start at V's
/// first): u_e from `in` and out = A_e u_e, both component-major (k = c·N + i for component c of
/// the scalar element's shape i), `geometry` [j·kLanes + l] as kGeometry describes. J⁻ᵀ and
/// |det J| are constant on a straight-sided tet, so ∇u is taken at a rule's n_q points x_q
/// (reference weights `weights`, summing to 1/6) from `ref_grad`, the N shape gradients there,
/// [(q·N + i)·3 + e] = ∂N_i/∂ξ_e(x_q). At each point stress(q, ∇u, w, p) gives p = w·P(∇u)
/// (p[c][d], ∇u[c][d] = ∂u_c/∂x_d), and out_ci += Σ_d p[c][d] ∂N_i/∂x_d.
template <typename V, unsigned N, typename Stress>
[[gnu::always_inline]] inline void tested_stress_lanes(const double* in, double* out,
                                                       const double* geometry,
                                                       const double* ref_grad,
                                                       const double* weights, unsigned n_q,
                                                       const Stress& stress) {
  V u[kDim * N], a[kDim * N] = {}, inv_jt[kDim][kDim], det;
  for (unsigned k = 0; k < kDim * N; ++k) std::memcpy(&u[k], in + k * kLanes, sizeof(V));
  for (unsigned j = 0; j < kDim * kDim; ++j) {
    std::memcpy(&inv_jt[j / kDim][j % kDim], geometry + j * kLanes, sizeof(V));
  }
  std::memcpy(&det, geometry + kDim * kDim * kLanes, sizeof(V));
  for (unsigned q = 0; q < n_q; ++q) {
    const double* g = ref_grad + q * N * kDim;
    V ref[kDim][kDim] = {};  // ∂u_c/∂ξ_e
    for (unsigned c = 0; c < kDim; ++c) {
      for (unsigned i = 0; i < N; ++i) {
        for (unsigned e = 0; e < kDim; ++e) ref[c][e] += u[c * N + i] * g[i * kDim + e];
      }
    }
    V grad[kDim][kDim];  // ∂u_c/∂x_d
    for (unsigned c = 0; c < kDim; ++c) {
      for (unsigned d = 0; d < kDim; ++d) {
        grad[c][d] = inv_jt[d][0] * ref[c][0] + inv_jt[d][1] * ref[c][1] + inv_jt[d][2] * ref[c][2];
      }
    }
    V p[kDim][kDim];
    stress(q, grad, det * weights[q], p);
    for (unsigned c = 0; c < kDim; ++c) {
      V s[kDim];  // Σ_d p_cd ∂ξ_e/∂x_d
      for (unsigned e = 0; e < kDim; ++e) {
        s[e] = p[c][0] * inv_jt[0][e] + p[c][1] * inv_jt[1][e] + p[c][2] * inv_jt[2][e];
      }
      for (unsigned i = 0; i < N; ++i) {
        a[c * N + i] += s[0] * g[i * kDim] + s[1] * g[i * kDim + 1] + s[2] * g[i * kDim + 2];
      }
    }
  }
  for (unsigned k = 0; k < kDim * N; ++k) std::memcpy(out + k * kLanes, &a[k], sizeof(V));
}

/// The displacement a(u, v) on V's lanes (tested_stress_lanes at a rule's Q points): the stress
/// is σ = λ tr(ε) I + 2μ ε (step-8's a(u, v)).
template <typename V, unsigned N, unsigned Q>
[[gnu::always_inline]] inline void straight_lanes(const double* in, double* out,
                                                  const double* geometry, const double* ref_grad,
                                                  const double* weights, double lambda, double mu) {
  tested_stress_lanes<V, N>(
      in, out, geometry, ref_grad, weights, Q,
      [ lambda, mu ](unsigned, const V(&grad)[kDim][kDim], V w, V(&p)[kDim][kDim])
          __attribute__((always_inline)) {
            const V lambda_trace = (lambda * w) * (grad[0][0] + grad[1][1] + grad[2][2]);
            const V mu_w = mu * w;
            for (unsigned c = 0; c < kDim; ++c) {
              for (unsigned d = 0; d < kDim; ++d) p[c][d] = mu_w * (grad[c][d] + grad[d][c]);
              p[c][c] += lambda_trace;
            }
          });
}

/// straight_lanes on a whole batch, `Width` cells at a time: SSE2 (any x86-64), AVX2 + FMA or
/// AVX-512 + FMA, each compiled for its instruction set and chosen at run time (straight_tet_isa),
/// so the project builds and runs on any x86-64.
template <typename V, unsigned Width, unsigned N, unsigned Q>
[[gnu::always_inline]] inline void straight_batch(const double* in, double* out,
                                                  const double* geometry, const double* ref_grad,
                                                  const double* weights, double lambda, double mu) {
  for (unsigned first = 0; first < kLanes; first += Width) {
    straight_lanes<V, N, Q>(in + first, out + first, geometry + first, ref_grad, weights, lambda,
                            mu);
  }
}
template <unsigned N, unsigned Q>
void straight_batch_sse2(const double* in, double* out, const double* geometry,
                         const double* ref_grad, const double* weights, double lambda, double mu) {
  straight_batch<Lanes2, 2, N, Q>(in, out, geometry, ref_grad, weights, lambda, mu);
}
template <unsigned N, unsigned Q>
[[gnu::target("avx2,fma")]] void straight_batch_avx2(const double* in, double* out,
                                                     const double* geometry, const double* ref_grad,
                                                     const double* weights, double lambda,
                                                     double mu) {
  straight_batch<Lanes4, 4, N, Q>(in, out, geometry, ref_grad, weights, lambda, mu);
}
template <unsigned N, unsigned Q>
[[gnu::target("avx512f,fma")]] void straight_batch_avx512(const double* in, double* out,
                                                          const double* geometry,
                                                          const double* ref_grad,
                                                          const double* weights, double lambda,
                                                          double mu) {
  straight_batch<Lanes8, 8, N, Q>(in, out, geometry, ref_grad, weights, lambda, mu);
}

template <unsigned N, unsigned Q>
StraightTetKernel straight_batch_for(StraightTetIsa isa) {
  switch (isa) {
    case StraightTetIsa::avx512:
      return straight_batch_avx512<N, Q>;
    case StraightTetIsa::avx2:
      return straight_batch_avx2<N, Q>;
    case StraightTetIsa::sse2:
      break;
  }
  return straight_batch_sse2<N, Q>;
}

/// The neo-Hookean tangent on V's lanes (tested_stress_lanes at the state's n_q points): the
/// stress is dP = μ H + (μ − λ ln J)(F⁻¹ H F⁻¹)ᵀ + λ tr(F⁻¹ H) F⁻ᵀ of H = ∇δu (`state` as
/// TangentTetKernel describes, from V's first lane).
template <typename V, unsigned N>
[[gnu::always_inline]] inline void tangent_lanes(const double* in, double* out,
                                                 const double* geometry, const double* state,
                                                 const double* ref_grad, const double* weights,
                                                 unsigned n_q, double lambda, double mu) {
  tested_stress_lanes<V, N>(
      in, out, geometry, ref_grad, weights, n_q,
      [ state, lambda, mu ](unsigned q, const V(&h)[kDim][kDim], V w,
                            V(&p)[kDim][kDim]) __attribute__((always_inline)) {
        const double* st = state + q * NeoHookeanTangentState::kPerPoint * kLanes;
        V f_inv[kDim][kDim], coefficient;  // F⁻¹ and μ − λ ln J
        for (unsigned j = 0; j < kDim * kDim; ++j) {
          std::memcpy(&f_inv[j / kDim][j % kDim], st + j * kLanes, sizeof(V));
        }
        std::memcpy(&coefficient, st + kDim * kDim * kLanes, sizeof(V));
        V gh[kDim][kDim];  // F⁻¹ H
        for (unsigned i = 0; i < kDim; ++i) {
          for (unsigned j = 0; j < kDim; ++j) {
            gh[i][j] = f_inv[i][0] * h[0][j] + f_inv[i][1] * h[1][j] + f_inv[i][2] * h[2][j];
          }
        }
        const V mu_w = mu * w, c_w = coefficient * w;
        const V lambda_trace = (lambda * w) * (gh[0][0] + gh[1][1] + gh[2][2]);
        for (unsigned c = 0; c < kDim; ++c) {
          for (unsigned d = 0; d < kDim; ++d) {
            // (F⁻¹ H F⁻¹)_dc
            const V ghg = gh[d][0] * f_inv[0][c] + gh[d][1] * f_inv[1][c] + gh[d][2] * f_inv[2][c];
            p[c][d] = mu_w * h[c][d] + c_w * ghg + lambda_trace * f_inv[d][c];
          }
        }
      });
}

template <typename V, unsigned Width, unsigned N>
[[gnu::always_inline]] inline void tangent_batch(const double* in, double* out,
                                                 const double* geometry, const double* state,
                                                 const double* ref_grad, const double* weights,
                                                 unsigned n_q, double lambda, double mu) {
  for (unsigned first = 0; first < kLanes; first += Width) {
    tangent_lanes<V, N>(in + first, out + first, geometry + first, state + first, ref_grad, weights,
                        n_q, lambda, mu);
  }
}
template <unsigned N>
void tangent_batch_sse2(const double* in, double* out, const double* geometry, const double* state,
                        const double* ref_grad, const double* weights, unsigned n_q, double lambda,
                        double mu) {
  tangent_batch<Lanes2, 2, N>(in, out, geometry, state, ref_grad, weights, n_q, lambda, mu);
}
template <unsigned N>
[[gnu::target("avx2,fma")]] void tangent_batch_avx2(const double* in, double* out,
                                                    const double* geometry, const double* state,
                                                    const double* ref_grad, const double* weights,
                                                    unsigned n_q, double lambda, double mu) {
  tangent_batch<Lanes4, 4, N>(in, out, geometry, state, ref_grad, weights, n_q, lambda, mu);
}
template <unsigned N>
[[gnu::target("avx512f,fma")]] void tangent_batch_avx512(
    const double* in, double* out, const double* geometry, const double* state,
    const double* ref_grad, const double* weights, unsigned n_q, double lambda, double mu) {
  tangent_batch<Lanes8, 8, N>(in, out, geometry, state, ref_grad, weights, n_q, lambda, mu);
}

template <unsigned N>
TangentTetKernel tangent_batch_for(StraightTetIsa isa) {
  switch (isa) {
    case StraightTetIsa::avx512:
      return tangent_batch_avx512<N>;
    case StraightTetIsa::avx2:
      return tangent_batch_avx2<N>;
    case StraightTetIsa::sse2:
      break;
  }
  return tangent_batch_sse2<N>;
}

/// The batch kernel for the scalar element's `n_shapes` (4: P1, 10: P2) on `isa`.
StraightTetKernel straight_batch_kernel(unsigned n_shapes, StraightTetIsa isa) {
  return n_shapes == 4 ? straight_batch_for<4, 1>(isa) : straight_batch_for<10, 4>(isa);
}

using Clock = std::chrono::steady_clock;

void copy(const dl::Vector<double>& from, MfVector& to) {
  for (unsigned i = 0; i < from.size(); ++i) to.local_element(i) = from[i];
}

void copy(const MfVector& from, dl::Vector<double>& to) {
  for (unsigned i = 0; i < to.size(); ++i) to[i] = from.local_element(i);
}

/// The serial Trilinos matrix as an Eigen one (both triangles), for CHOLMOD.
Eigen::SparseMatrix<double> to_eigen(const dl::TrilinosWrappers::SparseMatrix& m) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(m.n_nonzero_elements());
  for (const auto& e : m) {
    if (e.value() != 0.0) {
      entries.emplace_back(static_cast<int>(e.row()), static_cast<int>(e.column()), e.value());
    }
  }
  Eigen::SparseMatrix<double> out(static_cast<Eigen::Index>(m.m()),
                                  static_cast<Eigen::Index>(m.n()));
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

/// The fewest-point rule of deal.II 9.4 exact for polynomials of degree 2(degree − 1) on a tet:
/// the centroid for P1; for P2 Witherden–Vincent's 4-point rule of degree 2 (QGaussSimplex(2)
/// has 6 points, degree 3); above, QGaussSimplex(degree) (degree 2·degree − 1).
dl::Quadrature<kDim> exact_on_straight_tets(int degree) {
  if (degree == 1) return dl::QGaussSimplex<kDim>(1);
  if (degree == 2) return dl::QWitherdenVincentSimplex<kDim>(1, false);
  return dl::QGaussSimplex<kDim>(static_cast<unsigned>(degree));
}

}  // namespace

const char* to_string(StraightTetIsa isa) {
  switch (isa) {
    case StraightTetIsa::avx512:
      return "avx512";
    case StraightTetIsa::avx2:
      return "avx2";
    case StraightTetIsa::sse2:
      break;
  }
  return "sse2";
}

bool cpu_supports(StraightTetIsa isa) {
  switch (isa) {
    case StraightTetIsa::avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("fma");
    case StraightTetIsa::avx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case StraightTetIsa::sse2:
      break;
  }
  return true;
}

StraightTetIsa straight_tet_isa() {
  constexpr auto kVariable = "VESSELVERIFY_MATRIX_FREE_ISA";
  const char* asked = std::getenv(kVariable);
  if (asked == nullptr) {
    for (const auto isa : {StraightTetIsa::avx512, StraightTetIsa::avx2}) {
      if (cpu_supports(isa)) return isa;
    }
    return StraightTetIsa::sse2;
  }
  for (const auto isa : {StraightTetIsa::sse2, StraightTetIsa::avx2, StraightTetIsa::avx512}) {
    if (std::string(asked) != to_string(isa)) continue;
    if (!cpu_supports(isa)) {
      throw std::runtime_error(std::string(kVariable) + "=" + asked + ": this CPU lacks it");
    }
    return isa;
  }
  throw std::runtime_error(std::string(kVariable) + "=" + asked +
                           ": expected sse2, avx2 or avx512");
}

dl::AffineConstraints<double> homogeneous_copy(const dl::AffineConstraints<double>& constraints) {
  dl::AffineConstraints<double> out;
  out.copy_from(constraints);
  for (const auto& line : constraints.get_lines()) out.set_inhomogeneity(line.index, 0.0);
  return out;
}

bool fixes_values_only(const dl::AffineConstraints<double>& constraints) {
  const auto& lines = constraints.get_lines();
  return std::all_of(lines.begin(), lines.end(), [](const auto& l) { return l.entries.empty(); });
}

P1ToP2Embedding::P1ToP2Embedding(const dl::DoFHandler<kDim>& p2, const dl::DoFHandler<kDim>& p1,
                                 const dl::AffineConstraints<double>& p2_constraints,
                                 const dl::AffineConstraints<double>& p1_constraints,
                                 const dl::Utilities::MPI::Partitioner& p2_part,
                                 const dl::Utilities::MPI::Partitioner& p1_part)
    : from_(p2_part.locally_owned_size(), {kNone, kNone}) {
  const auto& fe2 = p2.get_fe();
  const auto& fe1 = p1.get_fe();
  // Each P2 node is a vertex of the reference tet or the midpoint of two: which P1 shapes.
  const auto& nodes = fe2.base_element(0).get_unit_support_points();
  const auto& vertices = fe1.base_element(0).get_unit_support_points();
  std::vector<std::array<unsigned, 2>> parents(nodes.size());
  for (unsigned i = 0; i < nodes.size(); ++i) {
    for (unsigned a = 0; a < vertices.size(); ++a) {
      for (unsigned b = a; b < vertices.size(); ++b) {
        if ((0.5 * (vertices[a] + vertices[b]) - nodes[i]).norm() < 1e-12) parents[i] = {a, b};
      }
    }
  }
  std::vector<dl::types::global_dof_index> fine(fe2.n_dofs_per_cell()),
      coarse(fe1.n_dofs_per_cell());
  auto cell1 = p1.begin_active();
  for (const auto& cell2 : p2.active_cell_iterators()) {
    const auto this_cell1 = cell1++;
    if (!cell2->is_locally_owned()) continue;
    cell2->get_dof_indices(fine);
    this_cell1->get_dof_indices(coarse);
    for (unsigned k = 0; k < fine.size(); ++k) {
      if (!p2_part.in_local_range(fine[k]) || p2_constraints.is_constrained(fine[k])) continue;
      const auto [c, i] = fe2.system_to_component_index(k);
      auto& from = from_[p2_part.global_to_local(fine[k])];
      for (unsigned j = 0; j < 2; ++j) {  // both, as another cell may order the edge otherwise
        const auto parent = coarse[fe1.component_to_system_index(c, parents[i][j])];
        from[j] = p1_constraints.is_constrained(parent) ? kNone : p1_part.global_to_local(parent);
      }
    }
  }
}

void P1ToP2Embedding::prolongate_and_add(MfVector& p2, const MfVector& p1) const {
  const bool had_ghosts = p1.has_ghost_elements();
  if (!had_ghosts) p1.update_ghost_values();
  for (unsigned k = 0; k < from_.size(); ++k) {
    for (const unsigned parent : from_[k]) {
      if (parent != kNone) p2.local_element(k) += 0.5 * p1.local_element(parent);
    }
  }
  if (!had_ghosts) p1.zero_out_ghost_values();
}

void P1ToP2Embedding::restrict_and_add(MfVector& p1, const MfVector& p2) const {
  p1.zero_out_ghost_values();
  for (unsigned k = 0; k < from_.size(); ++k) {
    for (const unsigned parent : from_[k]) {
      if (parent != kNone) p1.local_element(parent) += 0.5 * p2.local_element(k);
    }
  }
  p1.compress(dl::VectorOperation::add);
}

ElasticityOperator::ElasticityOperator(const dl::Mapping<kDim>& mapping,
                                       const dl::DoFHandler<kDim>& dof,
                                       const dl::AffineConstraints<double>& constraints, int degree,
                                       double lambda, double mu, unsigned threads,
                                       const NeoHookeanTangentState* tangent)
    : mapping_(mapping), constraints_(constraints), lambda_(lambda), mu_(mu), tangent_(tangent) {
  dl::MatrixFree<kDim, double>::AdditionalData data;
  data.mapping_update_flags = dl::update_gradients | dl::update_JxW_values;
  data.tasks_parallel_scheme = dl::MatrixFree<kDim, double>::AdditionalData::none;
  // On straight-sided tets (a degree-1 MappingFE) ε(u):Cε(v) is a polynomial of degree
  // 2(degree − 1): the smallest rule exact for it gives the same bilinear form as the assembled
  // path's QGaussSimplex(degree + 1) (14 points per P2 cell). deal.II 9.4's MatrixFree takes only
  // QGaussSimplex and odd Witherden–Vincent rules on tets (get_unique_face_quadratures), not the
  // 4-point one, so for P1 and P2 the kernel is our own (straight_batch) on MatrixFree's
  // one-point geometry. Curved cells keep degree + 1, as the assembly does. The finite-strain
  // tangent is not polynomial: it takes the residual's own rule (tangent_'s), so that it is the
  // residual's exact derivative.
  const auto* fe_mapping = dynamic_cast<const dl::MappingFE<kDim>*>(&mapping);
  const bool affine = fe_mapping != nullptr && fe_mapping->get_degree() == 1;
  straight_ = affine && degree <= 2;
  quadrature_ = tangent_ != nullptr ? tangent_->quadrature
                : affine            ? exact_on_straight_tets(degree)
                                    : dl::QGaussSimplex<kDim>(degree + 1);
  n_quadrature_points_ = quadrature_.size();
  if (straight_) {
    const dl::FE_SimplexP<kDim> scalar(static_cast<unsigned>(degree));
    n_shapes_ = scalar.n_dofs_per_cell();
    for (unsigned q = 0; q < quadrature_.size(); ++q) {
      for (unsigned i = 0; i < n_shapes_; ++i) {
        const dl::Tensor<1, kDim> g = scalar.shape_grad(i, quadrature_.point(q));
        for (unsigned e = 0; e < kDim; ++e) ref_grad_.push_back(g[e]);
      }
    }
    isa_ = straight_tet_isa();
    if (tangent_ != nullptr) {
      tangent_kernel_ = n_shapes_ == 4 ? tangent_batch_for<4>(isa_) : tangent_batch_for<10>(isa_);
    } else {
      kernel_ = straight_batch_kernel(n_shapes_, isa_);
    }
    mf_.reinit(mapping, dof, constraints, dl::QGaussSimplex<kDim>(1), data);
    build_batches();
    partition_batches(threads);
    return;
  }
  mf_.reinit(mapping, dof, constraints, quadrature_, data);
  if (tangent_ != nullptr) {
    const unsigned width = dl::VectorizedArray<double>::size();
    lane_cells_.assign(mf_.n_cell_batches() * width, kNoDof);
    for (unsigned b = 0; b < mf_.n_cell_batches(); ++b) {
      for (unsigned l = 0; l < mf_.n_active_entries_per_cell_batch(b); ++l) {
        lane_cells_[b * width + l] = mf_.get_cell_iterator(b, l)->active_cell_index();
      }
    }
  }
}

void ElasticityOperator::store_state(unsigned cell, double* lane) const {
  constexpr unsigned kPer = NeoHookeanTangentState::kPerPoint;
  const unsigned n_q = tangent_->n_q();
  const double* v = tangent_->values.data() + std::size_t{cell} * n_q * kPer;
  for (unsigned k = 0; k < n_q * kPer; ++k) lane[k * kLanes] = v[k];
}

std::vector<unsigned> ElasticityOperator::component_major_system_index() const {
  const auto& fe = mf_.get_dof_handler().get_fe();
  std::vector<unsigned> system_index(kDim * n_shapes_);
  for (unsigned c = 0; c < kDim; ++c) {
    for (unsigned i = 0; i < n_shapes_; ++i) {
      system_index[c * n_shapes_ + i] = fe.component_to_system_index(c, i);
    }
  }
  return system_index;
}

void ElasticityOperator::build_batches() {
  if (!fixes_values_only(constraints_)) return;
  const auto& layout = partitioner();
  const unsigned per_cell = kDim * n_shapes_;
  const std::vector<unsigned> system_index = component_major_system_index();
  const unsigned n_cells = mf_.n_cell_batches();  // one cell each: no SIMD in this deal.II
  const unsigned n_batches = (n_cells + kLanes - 1) / kLanes;
  batch_dofs_.assign(std::size_t{n_batches} * per_cell * kLanes, kNoDof);
  batch_geometry_.assign(std::size_t{n_batches} * kGeometry * kLanes, 0.0);
  Evaluation phi(mf_);
  std::vector<dl::types::global_dof_index> idx(per_cell);
  for (unsigned cell = 0; cell < n_cells; ++cell) {
    const unsigned b = cell / kLanes, l = cell % kLanes;
    mf_.get_cell_iterator(cell, 0)->get_dof_indices(idx);
    unsigned* dofs = batch_dofs_.data() + std::size_t{b} * per_cell * kLanes;
    for (unsigned k = 0; k < per_cell; ++k) {
      const auto i = idx[system_index[k]];
      if (!constraints_.is_constrained(i)) dofs[k * kLanes + l] = layout.global_to_local(i);
    }
    phi.reinit(cell);
    store_geometry(phi, batch_geometry_.data() + std::size_t{b} * kGeometry * kLanes + l);
  }
}

std::size_t ElasticityOperator::state_per_batch() const {
  return std::size_t{n_quadrature_points_} * NeoHookeanTangentState::kPerPoint * kLanes;
}

void ElasticityOperator::store_batch_state(std::size_t b, double* state) const {
  const unsigned n_cells = mf_.n_cell_batches();  // one cell each
  for (unsigned l = 0; l < kLanes && b * kLanes + l < n_cells; ++l) {
    const auto cell = static_cast<unsigned>(b * kLanes + l);
    store_state(mf_.get_cell_iterator(cell, 0)->active_cell_index(), state + l);
  }
}

template <typename Evaluation>
void ElasticityOperator::store_geometry(const Evaluation& phi, double* lane) {
  // inverse_jacobian(0)[d][e] = ∂ξ_e/∂x_d; JxW(0) = |det J|·(the one-point rule's weight 1/6).
  const auto inv_jt = phi.inverse_jacobian(0);
  for (unsigned d = 0; d < kDim; ++d) {
    for (unsigned e = 0; e < kDim; ++e) lane[(d * kDim + e) * kLanes] = inv_jt[d][e][0];
  }
  lane[kDim * kDim * kLanes] = 6.0 * phi.JxW(0)[0];
}

void ElasticityOperator::partition_batches(unsigned threads) {
  const std::size_t n_batches = batch_geometry_.size() / (kGeometry * kLanes);
  if (n_batches == 0) return;
  const unsigned per_batch = kDim * n_shapes_ * kLanes;
  // A part of fewer batches costs more to start on a thread than it saves.
  constexpr std::size_t kMinBatchesPerPart = 32;
  const std::size_t n_parts =
      std::clamp<std::size_t>(threads, 1, std::max<std::size_t>(1, n_batches / kMinBatchesPerPart));
  parts_.resize(n_parts);
  for (std::size_t p = 0; p < n_parts; ++p) {
    Part& part = parts_[p];
    part.first = n_batches * p / n_parts;
    part.end = n_batches * (p + 1) / n_parts;
    if (p == 0) continue;  // part 0 writes dst itself
    const auto begin = batch_dofs_.begin() + static_cast<std::ptrdiff_t>(part.first * per_batch);
    const auto end = batch_dofs_.begin() + static_cast<std::ptrdiff_t>(part.end * per_batch);
    part.first_dof = kNoDof;
    for (auto it = begin; it != end; ++it) {
      if (*it == kNoDof) continue;
      part.first_dof = std::min(part.first_dof, *it);
      part.end_dof = std::max(part.end_dof, *it + 1);
    }
    if (part.first_dof == kNoDof) part.first_dof = part.end_dof = 0;
    part.sum.resize(part.end_dof - part.first_dof);
  }
}

void ElasticityOperator::apply_kernel(std::size_t b, const double* in, double* out,
                                      const double* weights, const double* state) const {
  const double* geometry = batch_geometry_.data() + b * kGeometry * kLanes;
  if (tangent_kernel_ != nullptr) {
    if (state == nullptr) state = batch_state_.data() + b * state_per_batch();
    tangent_kernel_(in, out, geometry, state, ref_grad_.data(), weights, n_quadrature_points_,
                    lambda_, mu_);
  } else {
    kernel_(in, out, geometry, ref_grad_.data(), weights, lambda_, mu_);
  }
}

void ElasticityOperator::apply_batch_range(std::size_t first, std::size_t end, const MfVector& src,
                                           double* out, unsigned offset) const {
  const unsigned per_batch = kDim * n_shapes_ * kLanes;
  const double* w = quadrature_.get_weights().data();
  std::array<double, kDim * 10 * kLanes> in{}, a{};
  for (std::size_t b = first; b < end; ++b) {
    const unsigned* idx = batch_dofs_.data() + b * per_batch;
    for (unsigned j = 0; j < per_batch; ++j) {
      in[j] = idx[j] == kNoDof ? 0.0 : src.local_element(idx[j]);
    }
    apply_kernel(b, in.data(), a.data(), w);
    for (unsigned j = 0; j < per_batch; ++j) {
      if (idx[j] != kNoDof) out[idx[j] - offset] += a[j];
    }
  }
}

void ElasticityOperator::apply_batches(MfVector& dst, const MfVector& src) const {
  if (tangent_kernel_ != nullptr && batch_state_.empty()) {
    const std::size_t n_batches = batch_geometry_.size() / (kGeometry * kLanes);
    batch_state_.assign(n_batches * state_per_batch(), 0.0);
    for (std::size_t b = 0; b < n_batches; ++b) {
      store_batch_state(b, batch_state_.data() + b * state_per_batch());
    }
  }
  dst = 0.0;
  std::vector<std::thread> others;
  for (std::size_t p = 1; p < parts_.size(); ++p) {
    others.emplace_back([this, &src, &part = parts_[p]] {
      std::fill(part.sum.begin(), part.sum.end(), 0.0);
      apply_batch_range(part.first, part.end, src, part.sum.data(), part.first_dof);
    });
  }
  apply_batch_range(parts_[0].first, parts_[0].end, src, dst.begin(), 0);
  for (std::thread& t : others) t.join();
  for (std::size_t p = 1; p < parts_.size(); ++p) {
    const Part& part = parts_[p];
    for (unsigned i = part.first_dof; i < part.end_dof; ++i) {
      dst.local_element(i) += part.sum[i - part.first_dof];
    }
  }
}

template <typename Evaluation>
void ElasticityOperator::apply_tangent(Evaluation& phi) const {
  constexpr unsigned kPer = NeoHookeanTangentState::kPerPoint;
  const unsigned width = Number::size();
  const unsigned* lanes = lane_cells_.data() + phi.get_current_cell_index() * width;
  const unsigned n_q = tangent_->n_q();
  phi.evaluate(dl::EvaluationFlags::gradients);
  for (unsigned q = 0; q < phi.n_q_points; ++q) {
    dl::Tensor<2, kDim, Number> g;  // F⁻¹ (the identity on an empty lane)
    Number c = 0.0;                 // μ − λ ln J
    for (unsigned l = 0; l < width; ++l) {
      if (lanes[l] == kNoDof) {
        for (unsigned i = 0; i < kDim; ++i) g[i][i][l] = 1.0;
        continue;
      }
      const double* v = tangent_->values.data() + (std::size_t{lanes[l]} * n_q + q) * kPer;
      for (unsigned i = 0; i < kDim; ++i) {
        for (unsigned j = 0; j < kDim; ++j) g[i][j][l] = v[kDim * i + j];
      }
      c[l] = v[kDim * kDim];
    }
    const dl::Tensor<2, kDim, Number> h = phi.get_gradient(q);  // ∂δu_a/∂X_J
    const dl::Tensor<2, kDim, Number> gh = g * h;
    const Number trace_gh = dl::trace(gh);
    // dP = μ H + (μ − λ ln J)(F⁻¹ H F⁻¹)ᵀ + λ tr(F⁻¹H) F⁻ᵀ
    const dl::Tensor<2, kDim, Number> dp =
        mu_ * h + c * dl::transpose(gh * g) + (lambda_ * trace_gh) * dl::transpose(g);
    phi.submit_gradient(dp, q);
  }
  phi.integrate(dl::EvaluationFlags::gradients);
}

template <typename Evaluation>
void ElasticityOperator::apply_cell(Evaluation& phi) const {
  if (tangent_ != nullptr && !straight_) {
    apply_tangent(phi);
    return;
  }
  if (!straight_) {
    stress_divergence(phi, lambda_, mu_);
    return;
  }
  // The batch kernel on one cell: lane 0, the other lanes zero (|det J| = 0 gives them nothing).
  std::array<double, kDim * 10 * kLanes> in{}, out{};
  std::array<double, kGeometry * kLanes> geometry{};
  const unsigned per_cell = kDim * n_shapes_;
  for (unsigned k = 0; k < per_cell; ++k) in[k * kLanes] = phi.begin_dof_values()[k][0];
  store_geometry(phi, geometry.data());
  if (tangent_kernel_ != nullptr) {
    thread_local std::vector<double> state;
    state.assign(std::size_t{n_quadrature_points_} * NeoHookeanTangentState::kPerPoint * kLanes,
                 0.0);
    store_state(mf_.get_cell_iterator(phi.get_current_cell_index(), 0)->active_cell_index(),
                state.data());
    tangent_kernel_(in.data(), out.data(), geometry.data(), state.data(), ref_grad_.data(),
                    quadrature_.get_weights().data(), n_quadrature_points_, lambda_, mu_);
  } else {
    kernel_(in.data(), out.data(), geometry.data(), ref_grad_.data(),
            quadrature_.get_weights().data(), lambda_, mu_);
  }
  for (unsigned k = 0; k < per_cell; ++k) phi.begin_dof_values()[k] = out[k * kLanes];
}

void ElasticityOperator::vmult(MfVector& dst, const MfVector& src) const {
  const auto t0 = Clock::now();
  if (!batch_dofs_.empty()) {
    // The batches read src's ghosts and add into dst's, which their owners then sum.
    const bool had_ghosts = src.has_ghost_elements();
    if (!had_ghosts) src.update_ghost_values();
    apply_batches(dst, src);
    dst.compress(dl::VectorOperation::add);
    if (!had_ghosts) src.zero_out_ghost_values();
  } else {
    cell_loop(dst, src);
  }
  for (const unsigned i : mf_.get_constrained_dofs()) dst.local_element(i) = src.local_element(i);
  ++applications_;
  seconds_ += seconds_since(t0);
}

void ElasticityOperator::cell_loop(MfVector& dst, const MfVector& src) const {
  const std::function<void(const dl::MatrixFree<kDim, double>&, MfVector&, const MfVector&,
                           const std::pair<unsigned, unsigned>&)>
      cells = [this](const dl::MatrixFree<kDim, double>& mf, MfVector& out, const MfVector& in,
                     const std::pair<unsigned, unsigned>& range) {
        Evaluation phi(mf);
        for (unsigned cell = range.first; cell < range.second; ++cell) {
          phi.reinit(cell);
          phi.read_dof_values(in);
          apply_cell(phi);
          phi.distribute_local_to_global(out);
        }
      };
  mf_.cell_loop(cells, dst, src, true);
}

MfVector ElasticityOperator::diagonal() const {
  for (const auto& line : constraints_.get_lines()) {
    if (!line.entries.empty()) return diagonal_by_kernel();
  }
  if (tangent_ != nullptr) return tangent_diagonal();
  MfVector diag;
  mf_.initialize_dof_vector(diag);
  const auto& dof = mf_.get_dof_handler();
  const auto& fe = dof.get_fe();  // FESystem(FE_SimplexP(degree), 3): one base element
  dl::FEValues<kDim> values(mapping_, fe.base_element(0), quadrature_,
                            dl::update_gradients | dl::update_JxW_values);
  std::vector<dl::types::global_dof_index> idx(fe.n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    values.reinit(static_cast<dl::Triangulation<kDim>::cell_iterator>(cell));
    cell->get_dof_indices(idx);
    for (unsigned i = 0; i < idx.size(); ++i) {
      const auto [c, k] = fe.system_to_component_index(i);
      double a = 0.0;
      for (unsigned q = 0; q < values.n_quadrature_points; ++q) {
        const dl::Tensor<1, kDim> g = values.shape_grad(k, q);
        a += values.JxW(q) * ((lambda_ + mu_) * g[c] * g[c] + mu_ * (g * g));
      }
      diag(idx[i]) += a;
    }
  }
  diag.compress(dl::VectorOperation::add);
  for (const unsigned i : mf_.get_constrained_dofs()) diag.local_element(i) = 1.0;
  return diag;
}

MfVector ElasticityOperator::tangent_diagonal() const {
  constexpr unsigned kPer = NeoHookeanTangentState::kPerPoint;
  MfVector diag;
  mf_.initialize_dof_vector(diag);
  const auto& dof = mf_.get_dof_handler();
  const auto& fe = dof.get_fe();
  dl::FEValues<kDim> values(mapping_, fe.base_element(0), quadrature_,
                            dl::update_gradients | dl::update_JxW_values);
  const unsigned n_q = quadrature_.size();
  std::vector<dl::types::global_dof_index> idx(fe.n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    values.reinit(static_cast<dl::Triangulation<kDim>::cell_iterator>(cell));
    cell->get_dof_indices(idx);
    const double* state =
        tangent_->values.data() + std::size_t{cell->active_cell_index()} * n_q * kPer;
    for (unsigned i = 0; i < idx.size(); ++i) {
      const auto [c, k] = fe.system_to_component_index(i);
      double a = 0.0;
      for (unsigned q = 0; q < n_q; ++q) {
        const double* v = state + q * kPer;  // F⁻¹ row-major, then μ − λ ln J
        const dl::Tensor<1, kDim> g = values.shape_grad(k, q);
        const double f_inv_t_g = v[c] * g[0] + v[kDim + c] * g[1] + v[2 * kDim + c] * g[2];
        a += values.JxW(q) * (mu_ * (g * g) + (v[kDim * kDim] + lambda_) * f_inv_t_g * f_inv_t_g);
      }
      diag(idx[i]) += a;
    }
  }
  diag.compress(dl::VectorOperation::add);
  for (const unsigned i : mf_.get_constrained_dofs()) diag.local_element(i) = 1.0;
  return diag;
}

MfVector ElasticityOperator::diagonal_by_kernel() const {
  MfVector diag;
  mf_.initialize_dof_vector(diag);
  const std::function<void(Evaluation&)> kernel = [this](Evaluation& phi) { apply_cell(phi); };
  dl::MatrixFreeTools::compute_diagonal(mf_, diag, kernel);
  for (const unsigned i : mf_.get_constrained_dofs()) diag.local_element(i) = 1.0;
  return diag;
}

void ElasticityOperator::compute_matrix(dl::TrilinosWrappers::SparseMatrix& matrix) const {
  const auto& dof = mf_.get_dof_handler();
  if (const auto* parallel =
          dynamic_cast<const dl::parallel::TriangulationBase<kDim>*>(&dof.get_triangulation())) {
    // step-40's distributed pattern: each rank's cells' rows, sent to their owners.
    const dl::IndexSet& owned = dof.locally_owned_dofs();
    dl::IndexSet relevant;
    dl::DoFTools::extract_locally_relevant_dofs(dof, relevant);
    dl::DynamicSparsityPattern dsp(relevant);
    dl::DoFTools::make_sparsity_pattern(dof, dsp, constraints_, false);
    dl::SparsityTools::distribute_sparsity_pattern(dsp, owned, parallel->get_communicator(),
                                                   relevant);
    matrix.reinit(owned, owned, dsp, parallel->get_communicator());
  } else {
    dl::DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
    dl::DoFTools::make_sparsity_pattern(dof, dsp, constraints_, false);
    matrix.reinit(dsp);
  }
  if (batch_dofs_.empty()) {
    const std::function<void(Evaluation&)> kernel = [this](Evaluation& phi) { apply_cell(phi); };
    dl::MatrixFreeTools::compute_matrix(mf_, constraints_, matrix, kernel);
    return;
  }
  // The batches' element matrices, a column per kernel call for all kLanes cells at once: the
  // kernel on the k-th unit vector gives column k of each cell's matrix.
  const unsigned per_cell = kDim * n_shapes_;
  const std::vector<unsigned> system_index = component_major_system_index();
  const unsigned n_cells = mf_.n_cell_batches();  // one cell each: no SIMD in this deal.II
  const std::size_t n_batches = batch_geometry_.size() / (kGeometry * kLanes);
  std::array<double, kDim * 10 * kLanes> in{}, out{};
  std::vector<dl::FullMatrix<double>> cell_matrix(kLanes, dl::FullMatrix<double>(per_cell));
  std::vector<dl::types::global_dof_index> idx(per_cell), local(per_cell);
  // The tangent's values per batch as they are needed: the P1 level never applies its operator,
  // so it never holds them all.
  std::vector<double> state(tangent_kernel_ != nullptr ? state_per_batch() : 0);
  for (std::size_t b = 0; b < n_batches; ++b) {
    if (!state.empty()) store_batch_state(b, state.data());
    for (unsigned k = 0; k < per_cell; ++k) {
      std::fill(in.begin(), in.end(), 0.0);
      std::fill(in.begin() + k * kLanes, in.begin() + (k + 1) * kLanes, 1.0);
      apply_kernel(b, in.data(), out.data(), quadrature_.get_weights().data(),
                   state.empty() ? nullptr : state.data());
      for (unsigned l = 0; l < kLanes; ++l) {
        for (unsigned j = 0; j < per_cell; ++j) cell_matrix[l](j, k) = out[j * kLanes + l];
      }
    }
    for (unsigned l = 0; l < kLanes && b * kLanes + l < n_cells; ++l) {
      mf_.get_cell_iterator(static_cast<unsigned>(b * kLanes + l), 0)->get_dof_indices(idx);
      for (unsigned k = 0; k < per_cell; ++k) local[k] = idx[system_index[k]];
      constraints_.distribute_local_to_global(cell_matrix[l], local, matrix);
    }
  }
  matrix.compress(dl::VectorOperation::add);
}

void ElasticityOperator::zero_constrained(MfVector& v) const {
  for (const unsigned i : mf_.get_constrained_dofs()) v.local_element(i) = 0.0;
}

/// One V-cycle: Chebyshev pre-smoothing on the fine level, the residual restricted to P1, solved
/// there (ML-CG, CHOLMOD or one ML V-cycle), prolongated and added, Chebyshev post-smoothing.
/// Pre- and post-smoother are the same polynomial in A, the restriction is the prolongation's
/// transpose and the CHOLMOD or V-cycle coarse solve is symmetric, so the cycle is symmetric and
/// CG may use it; ML-CG's coarse solve depends on its right-hand side, hence the flexible CG. For
/// P1 (no lower degree on the mesh): one ML V-cycle alone.
class MatrixFreeElasticitySolver::VCycle {
 public:
  VCycle(const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& dof,
         const ElasticityOperator& fine, const dl::AffineConstraints<double>& fine_constraints,
         const ConstraintsFor& constraints_for, int degree, double lambda, double mu,
         const Vec3& centre, const PMultigridSettings& settings, MatrixFreeProfile& profile,
         const NeoHookeanTangentState* tangent)
      : fine_(fine), coarse_dof_(dof.get_triangulation()) {
    const ElasticityOperator* coarse = &fine;
    auto t0 = Clock::now();
    // The seconds since the last lap, for the profile.
    const auto lap = [&t0] {
      const double s = seconds_since(t0);
      t0 = Clock::now();
      return s;
    };
    if (degree > 1) {
      coarse_dof_.distribute_dofs(dl::FESystem<kDim>(dl::FE_SimplexP<kDim>(1), kDim));
      dl::AffineConstraints<double> c;
      constraints_for(coarse_dof_, c);
      c.close();
      coarse_constraints_ = homogeneous_copy(c);
      coarse_ = std::make_unique<ElasticityOperator>(mapping, coarse_dof_, coarse_constraints_, 1,
                                                     lambda, mu, solver_threads(), tangent);
      coarse = coarse_.get();
      profile.coarse_level = lap();
      if (fixes_values_only(fine_constraints) && fixes_values_only(coarse_constraints_)) {
        embedding_.emplace(dof, coarse_dof_, fine_constraints, coarse_constraints_,
                           fine.partitioner(), coarse_->partitioner());
      } else {
        transfer_.reinit_polynomial_transfer(dof, coarse_dof_, fine_constraints,
                                             coarse_constraints_);
      }
      profile.transfer = lap();

      inverse_diagonal_ = std::make_shared<dl::DiagonalMatrix<MfVector>>();
      inverse_diagonal_->get_vector() = fine.diagonal();
      for (auto& d : inverse_diagonal_->get_vector()) d = 1.0 / d;
      profile.diagonal = lap();
      Chebyshev::AdditionalData cheb;
      cheb.degree = settings.chebyshev_degree;
      cheb.smoothing_range = settings.smoothing_range;
      cheb.eig_cg_n_iterations = settings.eigenvalue_cg_steps;
      cheb.preconditioner = inverse_diagonal_;
      chebyshev_.initialize(fine, cheb);
      fine.initialize_dof_vector(residual_);
      fine.initialize_dof_vector(correction_);
      coarse->initialize_dof_vector(coarse_residual_);
      coarse->initialize_dof_vector(coarse_correction_);
      const unsigned applications_before = fine.applications();
      const double seconds_before = fine.seconds();
      chebyshev_.estimate_eigenvalues(residual_);  // here rather than in the first V-cycle
      profile.eigenvalue_estimate = lap();
      eigenvalue_applications_ = fine.applications() - applications_before;
      eigenvalue_seconds_ = fine.seconds() - seconds_before;
      profile.chebyshev_degree = settings.chebyshev_degree;
    }
    set_up_coarse_solve(mapping, degree > 1 ? coarse_dof_ : dof, *coarse, degree, centre, settings,
                        profile);
  }

  void vmult(MfVector& dst, const MfVector& src) const {
    if (!coarse_) {
      coarse_solve(dst, src);
      fine_.zero_constrained(dst);
      return;
    }
    chebyshev_.vmult(dst, src);  // pre-smoothing from zero
    fine_.zero_constrained(dst);
    fine_.vmult(residual_, dst);
    residual_.sadd(-1.0, 1.0, src);
    auto t0 = Clock::now();
    coarse_residual_ = 0.0;
    if (embedding_) {
      embedding_->restrict_and_add(coarse_residual_, residual_);
    } else {
      transfer_.restrict_and_add(coarse_residual_, residual_);
    }
    coarse_->zero_constrained(coarse_residual_);
    transfer_seconds_ += seconds_since(t0);
    coarse_solve(coarse_correction_, coarse_residual_);
    coarse_->zero_constrained(coarse_correction_);
    t0 = Clock::now();
    if (embedding_) {
      embedding_->prolongate_and_add(dst, coarse_correction_);
    } else {
      transfer_.prolongate_and_add(dst, coarse_correction_);
    }
    transfer_seconds_ += seconds_since(t0);
    fine_.zero_constrained(dst);
    fine_.vmult(residual_, dst);  // post-smoothing on the new residual
    residual_.sadd(-1.0, 1.0, src);
    chebyshev_.vmult(correction_, residual_);
    dst += correction_;
    fine_.zero_constrained(dst);
  }

  [[nodiscard]] std::size_t memory_consumption() const {
    return (coarse_ ? coarse_->memory_consumption() : 0) +
           (coarse_matrix_ ? coarse_matrix_->memory_consumption() : 0) +
           (inverse_diagonal_ ? inverse_diagonal_->memory_consumption() : 0) +
           4 * residual_.memory_consumption();
  }

  /// Whether the cycle is a fixed linear map (false for ml_cg: the outer CG must be flexible).
  [[nodiscard]] bool linear() const { return method_ != CoarseSolve::ml_cg; }

  /// The CG-time parts of `profile`: coarse solves and transfers so far.
  void add_solve_profile(MatrixFreeProfile& profile) const {
    profile.coarse_solves = coarse_solves_;
    profile.coarse_iterations = coarse_iterations_;
    profile.coarse_solve_seconds = coarse_solve_seconds_;
    profile.transfer_seconds = transfer_seconds_;
  }
  /// Fine-operator applications of the set-up's eigenvalue estimate (not the CG's), and seconds.
  [[nodiscard]] unsigned eigenvalue_applications() const { return eigenvalue_applications_; }
  [[nodiscard]] double eigenvalue_seconds() const { return eigenvalue_seconds_; }

 private:
  using Chebyshev =
      dl::PreconditionChebyshev<ElasticityOperator, MfVector, dl::DiagonalMatrix<MfVector>>;

  /// The P1 level's matrix (the fine one for P1) and its solver as `settings` say: a CHOLMOD
  /// factor (serial only) or ML with the rigid-body modes at `level_dof`'s support points.
  void set_up_coarse_solve(const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& level_dof,
                           const ElasticityOperator& coarse, int degree, const Vec3& centre,
                           const PMultigridSettings& settings, MatrixFreeProfile& profile) {
    auto t0 = Clock::now();
    coarse_matrix_ = std::make_unique<dl::TrilinosWrappers::SparseMatrix>();
    coarse.compute_matrix(*coarse_matrix_);
    profile.coarse_matrix = seconds_since(t0);
    t0 = Clock::now();
    // For P1 the "coarse" level is the fine one: a factor of it would make the matrix-free
    // operator pointless, so P1 always takes one ML V-cycle.
    method_ = degree == 1 ? CoarseSolve::ml_vcycle : settings.coarse;
    const bool distributed =
        dl::Utilities::MPI::n_mpi_processes(coarse.partitioner().get_mpi_communicator()) > 1;
    if (method_ == CoarseSolve::automatic) {
      method_ = coarse.m() <= settings.direct_coarse_max_dofs && !distributed ? CoarseSolve::cholmod
                                                                              : CoarseSolve::ml_cg;
    }
    if (method_ == CoarseSolve::cholmod && distributed) {
      throw std::invalid_argument("p-multigrid: the CHOLMOD coarse solve is serial only");
    }
    coarse_tolerance_ = settings.coarse_tolerance;
    profile.coarse_method = method_ == CoarseSolve::cholmod     ? "CHOLMOD"
                            : method_ == CoarseSolve::ml_vcycle ? "one ML V-cycle"
                                                                : "ML-CG";
    if (method_ == CoarseSolve::cholmod) {
      cholmod_ = std::make_unique<CholmodFactor>(to_eigen(*coarse_matrix_));
      coarse_matrix_.reset();
    } else {
      // The ML near-null space: the rigid-body modes at the P1 DoFs' support points.
      const DisplacementRows rows =
          displacement_rows(mapping, level_dof, level_dof.locally_owned_dofs());
      initialize_elasticity_amg(amg_, *coarse_matrix_, rows, centre, false,
                                settings.amg_rigid_body_modes, settings.amg_prolongator,
                                mode_storage_, settings.amg_aggregation_threshold, distributed);
    }
    profile.coarse_factor = seconds_since(t0);
  }

  /// x ≈ A₁⁻¹ b on the P1 level (on the fine level itself for P1).
  void coarse_solve(MfVector& x, const MfVector& b) const {
    const auto t0 = Clock::now();
    ++coarse_solves_;
    if (method_ == CoarseSolve::ml_vcycle) {
      amg_.vmult(x, b);
    } else if (method_ == CoarseSolve::ml_cg) {
      // From x = 0 to ‖b − A₁x‖ ≤ coarse_tolerance·‖b‖; the cap only guards against stagnation,
      // as any iterate is a usable coarse correction.
      dl::ReductionControl control(200, 0.0, coarse_tolerance_, false, false);
      dl::SolverCG<MfVector> cg(control);
      x = 0.0;
      try {
        cg.solve(*coarse_matrix_, x, b, amg_);
      } catch (const dl::SolverControl::NoConvergence&) {
      }
      coarse_iterations_ += control.last_step();
    } else {
      const unsigned n = b.locally_owned_size();
      Eigen::VectorXd rhs(n);
      for (unsigned i = 0; i < n; ++i) rhs[i] = b.local_element(i);
      const Eigen::VectorXd y = cholmod_->solve(rhs);
      for (unsigned i = 0; i < n; ++i) x.local_element(i) = y[i];
    }
    coarse_solve_seconds_ += seconds_since(t0);
  }

  const ElasticityOperator& fine_;
  dl::DoFHandler<kDim> coarse_dof_;
  dl::AffineConstraints<double> coarse_constraints_;
  std::unique_ptr<ElasticityOperator> coarse_;
  std::optional<P1ToP2Embedding> embedding_;         // both levels fixes_values_only
  dl::MGTwoLevelTransfer<kDim, MfVector> transfer_;  // otherwise
  std::shared_ptr<dl::DiagonalMatrix<MfVector>> inverse_diagonal_;
  Chebyshev chebyshev_;
  std::unique_ptr<CholmodFactor> cholmod_;                             // CoarseSolve::cholmod
  std::unique_ptr<dl::TrilinosWrappers::SparseMatrix> coarse_matrix_;  // ML's matrix
  dl::TrilinosWrappers::PreconditionAMG amg_;
  std::vector<double> mode_storage_;  // must outlive amg_
  mutable MfVector residual_, correction_, coarse_residual_, coarse_correction_;
  unsigned eigenvalue_applications_ = 0;
  double eigenvalue_seconds_ = 0.0;
  CoarseSolve method_ = CoarseSolve::cholmod;
  double coarse_tolerance_ = 0.0;
  mutable unsigned coarse_solves_ = 0, coarse_iterations_ = 0;
  mutable double coarse_solve_seconds_ = 0.0, transfer_seconds_ = 0.0;
};

namespace {
/// A + S: the matrix-free operator and a sparse matrix on the same (serial) DoF numbering.
struct WithAddedMatrix {
  const ElasticityOperator& a;
  const MatrixFreeElasticitySolver::AddedMatrix& s;
  void vmult(MfVector& dst, const MfVector& src) const {
    a.vmult(dst, src);
    for (Eigen::Index row = 0; row < s.outerSize(); ++row) {
      double sum = 0.0;
      for (MatrixFreeElasticitySolver::AddedMatrix::InnerIterator it(s, row); it; ++it) {
        sum += it.value() * src.local_element(static_cast<unsigned>(it.col()));
      }
      dst.local_element(static_cast<unsigned>(row)) += sum;
    }
  }
};
}  // namespace

MatrixFreeElasticitySolver::MatrixFreeElasticitySolver(
    const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& dof,
    const ConstraintsFor& constraints_for, int degree, double lambda, double mu, const Vec3& centre,
    const PMultigridSettings& settings, const NeoHookeanTangentState* tangent) {
  const auto t0 = std::chrono::steady_clock::now();
  ensure_mpi_initialized();  // Trilinos and the distributed vectors need MPI
  dl::AffineConstraints<double> c;
  constraints_for(dof, c);
  c.close();
  fine_constraints_ = homogeneous_copy(c);
  const auto t_fine = Clock::now();
  fine_ = std::make_unique<ElasticityOperator>(mapping, dof, fine_constraints_, degree, lambda, mu,
                                               solver_threads(), tangent);
  profile_.fine_operator = seconds_since(t_fine);
  profile_.quadrature_points = fine_->quadrature_points();
  preconditioner_ =
      std::make_unique<VCycle>(mapping, dof, *fine_, fine_constraints_, constraints_for, degree,
                               lambda, mu, centre, settings, profile_, tangent);
  setup_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

MatrixFreeElasticitySolver::~MatrixFreeElasticitySolver() = default;

MatrixFreeElasticitySolver::Outcome MatrixFreeElasticitySolver::solve(
    const dl::Vector<double>& b, dl::Vector<double>& u, double relative_tolerance,
    unsigned max_iterations, const AddedMatrix* added) const {
  MfVector rhs, x;
  fine_->initialize_dof_vector(rhs);
  fine_->initialize_dof_vector(x);
  copy(b, rhs);
  copy(u, x);
  const Outcome outcome = krylov(rhs, x, relative_tolerance, max_iterations, added);
  copy(x, u);
  return outcome;
}

MatrixFreeElasticitySolver::Outcome MatrixFreeElasticitySolver::solve(
    const MfVector& b, MfVector& u, double relative_tolerance, unsigned max_iterations) const {
  MfVector rhs = b;
  return krylov(rhs, u, relative_tolerance, max_iterations, nullptr);
}

MatrixFreeElasticitySolver::Outcome MatrixFreeElasticitySolver::krylov(
    MfVector& rhs, MfVector& x, double relative_tolerance, unsigned max_iterations,
    const AddedMatrix* added) const {
  fine_->zero_constrained(rhs);
  fine_->zero_constrained(x);
  dl::SolverControl control(max_iterations, relative_tolerance * rhs.l2_norm());
  const auto t0 = Clock::now();
  try {
    if (added != nullptr) {
      dl::SolverFGMRES<MfVector>(control).solve(WithAddedMatrix{*fine_, *added}, x, rhs,
                                                *preconditioner_);
    } else if (preconditioner_->linear()) {
      dl::SolverCG<MfVector>(control).solve(*fine_, x, rhs, *preconditioner_);
    } else {
      dl::SolverFlexibleCG<MfVector>(control).solve(*fine_, x, rhs, *preconditioner_);
    }
  } catch (const dl::SolverControl::NoConvergence& e) {
    std::ostringstream m;
    m << "matrix-free " << (added != nullptr ? "FGMRES" : "CG")
      << " with p-multigrid did not converge in " << e.last_step << " iterations (residual "
      << e.last_residual << "); try --solver direct or more --max-iterations";
    throw std::runtime_error(m.str());
  }
  profile_.cg += seconds_since(t0);
  return {control.last_step(), control.last_value()};
}

void MatrixFreeElasticitySolver::precondition(dl::Vector<double>& x,
                                              const dl::Vector<double>& r) const {
  MfVector rhs, y;
  fine_->initialize_dof_vector(rhs);
  fine_->initialize_dof_vector(y);
  copy(r, rhs);
  fine_->zero_constrained(rhs);
  preconditioner_->vmult(y, rhs);
  copy(y, x);
}

MatrixFreeProfile MatrixFreeElasticitySolver::profile() const {
  MatrixFreeProfile p = profile_;
  p.operator_applications = fine_->applications() - preconditioner_->eigenvalue_applications();
  p.operator_seconds = fine_->seconds() - preconditioner_->eigenvalue_seconds();
  preconditioner_->add_solve_profile(p);
  return p;
}

std::size_t MatrixFreeElasticitySolver::memory_consumption() const {
  return fine_->memory_consumption() + preconditioner_->memory_consumption();
}

}  // namespace vessel::fem::detail
