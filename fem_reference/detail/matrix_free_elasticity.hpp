#pragma once
/// Private to fem_reference: the displacement stiffness of small-strain isotropic elasticity, or
/// the compressible neo-Hookean tangent at a displacement, applied without a matrix (deal.II
/// MatrixFree + FEEvaluation on FE_SimplexP P1/P2 tets, the project's own batched kernel on
/// straight-sided ones), and the solver built on it: CG preconditioned by a two-level p-multigrid,
/// P2 smoothed by Chebyshev on the operator's diagonal, the P1 level (same mesh) solved on the P1
/// matrix (computed cell by cell from the same kernel) by ML-CG, a CHOLMOD factor or one ML
/// V-cycle. Serial or on a parallel::fullydistributed triangulation (each rank its own cells;
/// vectors in MatrixFree's local numbering, owned DoFs then ghosts). What deal.II 9.4 supports on
/// simplices: docs/measurements/dealii_simplex_support.md.
#include <deal.II/base/subscriptor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/matrix_free/matrix_free.h>
#include <deal.II/multigrid/mg_transfer_global_coarsening.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "fem_reference/detail/amg.hpp"
#include "fem_reference/detail/common.hpp"
#include "fem_reference/elasticity.hpp"

namespace vessel::fem::detail {

using MfVector = dl::LinearAlgebra::distributed::Vector<double>;

/// The straight-tet cell kernel on a batch of cells (the .cpp's straight_batch).
using StraightTetKernel = void (*)(const double* in, double* out, const double* geometry,
                                   const double* ref_grad, const double* weights, double lambda,
                                   double mu);

/// The neo-Hookean tangent's straight-tet kernel on a batch (the .cpp's tangent_batch): as
/// StraightTetKernel, with the batch's NeoHookeanTangentState values at its n_q points
/// [(q·kPerPoint + j)·lanes + l].
using TangentTetKernel = void (*)(const double* in, double* out, const double* geometry,
                                  const double* state, const double* ref_grad,
                                  const double* weights, unsigned n_q, double lambda, double mu);

/// The instruction set the straight-tet kernel runs in: a batch of 8 cells as four SSE2, two
/// AVX2 (+ FMA) or one AVX-512 (+ FMA) register per quantity.
enum class StraightTetIsa { sse2, avx2, avx512 };
[[nodiscard]] const char* to_string(StraightTetIsa isa);
/// Whether this CPU has `isa` (and FMA for avx2, avx512).
[[nodiscard]] bool cpu_supports(StraightTetIsa isa);
/// The widest instruction set this CPU has, or the one the environment's
/// VESSELVERIFY_MATRIX_FREE_ISA names (sse2, avx2, avx512: the tests check every variant and
/// measurements compare them); std::runtime_error naming the variable for another value or one
/// this CPU lacks.
[[nodiscard]] StraightTetIsa straight_tet_isa();

/// The compressible neo-Hookean tangent's coefficients at a displacement (the finite-strain
/// reference's displacement form, Ψ = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²): at quadrature point q
/// of the cell with active index c, F⁻¹ row-major at values[(c·n_q + q)·kPerPoint + 3i + j] and
/// μ − λ ln J at [... + 9]. The tangent's action on H = ∇δu is then
/// dP = μ H + (μ − λ ln J) (F⁻¹ H F⁻¹)ᵀ + λ tr(F⁻¹ H) F⁻ᵀ (NeoHookean::tangent contracted with H);
/// at u = 0 it is σ(ε(δu)) of linear elasticity.
struct NeoHookeanTangentState {
  static constexpr unsigned kPerPoint = kDim * kDim + 1;
  dl::Quadrature<kDim> quadrature;  ///< the residual's cell rule (the assembled path's)
  std::vector<double> values;
  [[nodiscard]] unsigned n_q() const { return quadrature.size(); }
};

/// A(u) = ∫ σ(u) : ε(v) dV with σ = λ tr(ε) I + 2μ ε (Pa, so A u is in N for u in m), evaluated
/// cell by cell on straight-sided tets at the fewest-point rule exact for the integrand's degree
/// 2(degree − 1) (P2: 4 points) and on curved ones at the assembled path's
/// QGaussSimplex(degree + 1), so both compute the same bilinear form to rounding. `constraints`
/// must be homogeneous (their pattern only): A acts on the unconstrained DoFs and as the identity
/// on the constrained ones.
class ElasticityOperator : public dl::Subscriptor {
 public:
  /// `threads`: the batched kernel's cells are cut into that many contiguous parts, one per
  /// thread (fewer on a small mesh); the other paths are serial.
  /// `tangent` (kept by reference): the operator is instead the neo-Hookean tangent
  /// ∫ dP(∇δu) : ∇v dV at that state, on the state's quadrature (the batched kernel on
  /// straight-sided tets, on `threads`; FEEvaluation, serial, on curved ones).
  ElasticityOperator(const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& dof,
                     const dl::AffineConstraints<double>& constraints, int degree, double lambda,
                     double mu, unsigned threads = 1,
                     const NeoHookeanTangentState* tangent = nullptr);

  /// dst = A src; counted in applications() and seconds(). On several ranks src's ghosts are
  /// updated here (and left as they were found).
  void vmult(MfVector& dst, const MfVector& src) const;
  void Tvmult(MfVector& dst, const MfVector& src) const { vmult(dst, src); }
  void initialize_dof_vector(MfVector& v) const { mf_.initialize_dof_vector(v); }
  /// The DoFs this rank holds in a vector: its owned ones, then the ghosts its cells touch.
  [[nodiscard]] const dl::Utilities::MPI::Partitioner& partitioner() const {
    return *mf_.get_vector_partitioner();
  }
  [[nodiscard]] dl::types::global_dof_index m() const { return mf_.get_dof_handler().n_dofs(); }
  [[nodiscard]] dl::types::global_dof_index n() const { return m(); }
  /// A's entry (i, i) (Chebyshev's interface; only the diagonal is available): diagonal()[i].
  [[nodiscard]] double el(unsigned i, unsigned j) const {
    if (i != j) throw std::logic_error("ElasticityOperator::el: only diagonal entries");
    if (diagonal_.size() == 0) diagonal_ = diagonal();
    return diagonal_.local_element(i);
  }
  /// diag(A) (1 on constrained DoFs). With Dirichlet constraints only, per DoF (component c of
  /// shape N) A_ii = Σ_cells Σ_q w_q ((λ + μ)(∂_c N)² + μ |∇N|²) by FEValues of the scalar
  /// element: one pass over the cells instead of MatrixFreeTools::compute_diagonal's one kernel
  /// evaluation per cell DoF (30 for P2); with other constraints compute_diagonal.
  [[nodiscard]] MfVector diagonal() const;
  /// The assembled A (the constrained rows and columns zero but for a positive diagonal), into
  /// `matrix` on `dof`'s full sparsity pattern: from the batched kernel, kLanes cells per call,
  /// where it runs; otherwise MatrixFreeTools::compute_matrix.
  void compute_matrix(dl::TrilinosWrappers::SparseMatrix& matrix) const;
  /// Sets v to 0 on the constrained DoFs.
  void zero_constrained(MfVector& v) const;
  [[nodiscard]] std::size_t memory_consumption() const {
    std::size_t sums = 0;
    for (const Part& p : parts_) sums += p.sum.capacity() * sizeof(double);
    return mf_.memory_consumption() + batch_dofs_.capacity() * sizeof(unsigned) +
           (batch_geometry_.capacity() + batch_state_.capacity()) * sizeof(double) + sums;
  }
  /// vmult calls so far, and their wall-clock seconds.
  [[nodiscard]] unsigned applications() const { return applications_; }
  [[nodiscard]] double seconds() const { return seconds_; }
  [[nodiscard]] unsigned quadrature_points() const { return n_quadrature_points_; }
  /// The straight-tet kernel's instruction set (meaningful where it runs: P1, P2 on straight
  /// tets) and the threads its application runs on.
  [[nodiscard]] StraightTetIsa isa() const { return isa_; }
  [[nodiscard]] unsigned threads() const {
    return std::max(1U, static_cast<unsigned>(parts_.size()));
  }

 private:
  /// diag(A) by MatrixFreeTools::compute_diagonal (any constraints).
  [[nodiscard]] MfVector diagonal_by_kernel() const;
  /// One cell's A_e u_e in place on phi's dof values (an FEEvaluation; defined in the .cpp).
  template <typename Evaluation>
  void apply_cell(Evaluation& phi) const;
  /// dst = A src by MatrixFree's cell loop, one FEEvaluation cell at a time (apply_cell).
  void cell_loop(MfVector& dst, const MfVector& src) const;
  /// straight_ with constraints that only fix values: batch_dofs_ (local indices) and
  /// batch_geometry_ from MatrixFree's cells, in its order (otherwise left empty).
  void build_batches();
  /// The neo-Hookean tangent on phi's cell batch: dP(∇δu) tested with ∇v at tangent_'s points.
  template <typename Evaluation>
  void apply_tangent(Evaluation& phi) const;
  /// tangent_'s values of `cell` (an active index) into one lane of a batch's state.
  void store_state(unsigned cell, double* lane) const;
  /// diag(A) of the tangent: per DoF (component c of shape N, g = ∇N) at each point
  /// μ|g|² + (μ − λ ln J + λ)((F⁻ᵀ g)_c)², by FEValues of the scalar element.
  [[nodiscard]] MfVector tangent_diagonal() const;
  /// phi's J⁻ᵀ and |det J| into one lane of a batch's geometry.
  template <typename Evaluation>
  static void store_geometry(const Evaluation& phi, double* lane);
  /// Per component-major local DoF k = c·N + i (the batches' order), the cell's DoF index.
  [[nodiscard]] std::vector<unsigned> component_major_system_index() const;
  /// out = the batch b's cells' A_e in (kernel_ or tangent_kernel_ on `state`, by default the
  /// batch's in batch_state_), the batches' layout.
  void apply_kernel(std::size_t b, const double* in, double* out, const double* weights,
                    const double* state = nullptr) const;
  /// Doubles of one batch's tangent values, and batch b's lanes' values into `state`.
  [[nodiscard]] std::size_t state_per_batch() const;
  void store_batch_state(std::size_t b, double* state) const;
  /// The batches cut into `threads` contiguous parts and the DoF range each writes.
  void partition_batches(unsigned threads);
  /// dst = A src (free rows; constrained rows zero) by kernel_ on the batches, one thread per
  /// part.
  void apply_batches(MfVector& dst, const MfVector& src) const;
  /// out[i − offset] += (A src)_i of the batches [first, end).
  void apply_batch_range(std::size_t first, std::size_t end, const MfVector& src, double* out,
                         unsigned offset) const;

  dl::MatrixFree<kDim, double> mf_;
  const dl::Mapping<kDim>& mapping_;
  dl::Quadrature<kDim> quadrature_;  // the integrand's rule (MatrixFree's one point if straight_)
  bool straight_ = false;            // P1/P2 on straight-sided tets: straight_batch
  unsigned n_shapes_ = 0;            // straight_: the scalar element's shape functions
  std::vector<double> ref_grad_;     // straight_: their reference gradients at quadrature_
  StraightTetKernel kernel_ = nullptr;  // straight_: for isa_
  TangentTetKernel tangent_kernel_ = nullptr;  // straight_ and tangent_: for isa_
  StraightTetIsa isa_ = StraightTetIsa::sse2;
  /// A thread's share of the batches and the DoFs they write, [first_dof, end_dof): part 0 adds
  /// into dst, every other into its own `sum` (as parts share DoFs), added to dst after.
  struct Part {
    std::size_t first = 0, end = 0;
    unsigned first_dof = 0, end_dof = 0;
    mutable std::vector<double> sum;
  };
  std::vector<Part> parts_;
  static constexpr unsigned kNoDof = ~0u;
  // straight_ and batchable: each batch's cells' DoF indices in the vectors' local numbering
  // [(b·3N + k)·lanes + l] (cell l of batch b, component-major local DoF k; kNoDof where
  // constrained or padding) and their
  // geometry [(b·10 + j)·lanes + l] (J⁻ᵀ row-major, then |det J|).
  std::vector<unsigned> batch_dofs_;
  std::vector<double> batch_geometry_;
  /// straight_, tangent_ and batchable: the batches' tangent_ values
  /// [((b·n_q + q)·kPerPoint + j)·lanes + l], gathered at the first application.
  mutable std::vector<double> batch_state_;
  const dl::AffineConstraints<double>& constraints_;
  double lambda_, mu_;
  const NeoHookeanTangentState* tangent_ = nullptr;
  /// tangent_ on curved cells (FEEvaluation): per cell batch and lane, the cell's active index
  /// (kNoDof for an empty lane).
  std::vector<unsigned> lane_cells_;
  mutable MfVector diagonal_;  // el()'s, on first use
  unsigned n_quadrature_points_ = 0;
  mutable unsigned applications_ = 0;
  mutable double seconds_ = 0.0;
};

/// Whether `constraints` only fix values (no entries tie a DoF to others): then a cell's
/// constrained DoFs can be dropped from its vector entries.
bool fixes_values_only(const dl::AffineConstraints<double>& constraints);

/// The P1 → P2 prolongation on one mesh as nodal interpolation (exact, as P1 ⊂ P2): a P2 vertex
/// DoF takes its P1 DoF's value, an edge-midpoint DoF the mean of its edge's two; the restriction
/// is the transpose. The operator MGTwoLevelTransfer::reinit_polynomial_transfer builds for this
/// pair, as two index reads per P2 DoF. Both levels' constraints fixes_values_only: constrained
/// DoFs are read and written as zero. On several ranks each rank maps its owned P2 DoFs (whose
/// P1 parents are on its own cells: owned or ghosts of `p1_part`).
class P1ToP2Embedding {
 public:
  /// `p2`, `p1`: FESystem(FE_SimplexP(2 resp. 1), 3) on the same triangulation; `p2_part`,
  /// `p1_part`: the vectors' layouts (the levels' ElasticityOperator::partitioner()).
  P1ToP2Embedding(const dl::DoFHandler<kDim>& p2, const dl::DoFHandler<kDim>& p1,
                  const dl::AffineConstraints<double>& p2_constraints,
                  const dl::AffineConstraints<double>& p1_constraints,
                  const dl::Utilities::MPI::Partitioner& p2_part,
                  const dl::Utilities::MPI::Partitioner& p1_part);
  /// p2 += P p1 (p1's ghosts updated here).
  void prolongate_and_add(MfVector& p2, const MfVector& p1) const;
  /// p1 += Pᵀ p2 (p1's ghost contributions sent to their owners).
  void restrict_and_add(MfVector& p1, const MfVector& p2) const;

 private:
  static constexpr unsigned kNone = ~0u;
  // Per owned P2 DoF (local index) the two P1 DoFs it averages, local indices (the same one twice
  // at a vertex); kNone where either level constrains the DoF.
  std::vector<std::array<unsigned, 2>> from_;
};

/// The constraints' pattern with zero inhomogeneities (what MatrixFree and the transfer need).
dl::AffineConstraints<double> homogeneous_copy(const dl::AffineConstraints<double>& constraints);

/// How the V-cycle solves on the P1 level. `cholmod`: exactly, by a CHOLMOD factor of the P1
/// matrix, so the two-level iteration count depends on the smoother alone, not on the level.
/// `ml_vcycle`: approximately, by one ML V-cycle (memory of the hierarchy only, but its error
/// grows with the level and the outer iterations with it). `ml_cg`: CG preconditioned by ML to
/// a relative residual of PMultigridSettings::coarse_tolerance: an inexact but level-independent
/// coarse solve; the outer CG is then the flexible one (the preconditioner is not a fixed linear
/// map). `automatic`: cholmod up to direct_coarse_max_dofs P1 DoFs, else ml_cg
/// (docs/measurements/matrix_free_multigrid.md).
enum class CoarseSolve { automatic, cholmod, ml_vcycle, ml_cg };

/// Settings of the p-multigrid V-cycle.
struct PMultigridSettings {
  unsigned chebyshev_degree = 4;      ///< matrix-vector products per smoothing step
  double smoothing_range = 20.0;      ///< Chebyshev smooths [λ_max / range, λ_max] of D⁻¹A
  unsigned eigenvalue_cg_steps = 20;  ///< CG steps of Chebyshev's λ_max(D⁻¹A) estimate
  CoarseSolve coarse = CoarseSolve::automatic;
  std::size_t direct_coarse_max_dofs = 0;  ///< automatic: CHOLMOD on P1 up to this many P1 DoFs
  /// ml_cg: ‖r₁‖ ≤ this·‖b₁‖ on the P1 level. Structured P2 tube, levels 0, 1, 2, outer × inner
  /// CG iterations: at 1e-2 35 × 279, 32 × 454, 30 × 695; at 1e-1 36 × 162, 33 × 258, 32 × 526
  /// (level 2 CG about 8% less work; at 0.2 and 0.5 level 1 needs 34 and 39 outer iterations).
  double coarse_tolerance = 0.1;
  bool amg_rigid_body_modes = true;  ///< ml_vcycle: ML near-null space, all six rigid-body modes
  /// ML on the P1 level. Smoothed aggregation (threshold 0.02) with ML-CG to 0.1 at P2 level 2:
  /// 544 inner iterations against plain's 526, each dearer, and a 290 MB larger peak.
  AmgProlongator amg_prolongator = AmgProlongator::plain;
  /// ML's aggregation threshold on the P1 level (none: the prolongator's default,
  /// default_aggregation_threshold). 0.02 against plain aggregation's default 0.1 on the P1 level
  /// of the structured tube's P2 level 2 (1.73 M DoFs, ν 0.3): 331 inner CG iterations over the
  /// 31–32 P1 solves against 526, the solve 37.7 s against 52.8 s; 0.05 took 682 (load 0.8–1.0).
  std::optional<double> amg_aggregation_threshold = 0.02;
};

/// The wall's displacement system, set up once, solved for many right-hand sides: the P2 (or P1)
/// matrix-free operator on the fine DoFs, and below it (for P2) the P1 DoFs of the same mesh, the
/// P2 → P1 transfer and ML (or CHOLMOD) on the assembled P1 matrix. Callers that solve the same
/// wall under many loads (contact active sets, Newton steps with a fixed stiffness) construct it
/// once and call solve() per load; set-up dominates when the loads are few. Given a
/// NeoHookeanTangentState, both levels are that tangent (a finite-strain Newton system).
///
/// The right-hand side is the assembled one on the unconstrained DoFs (N): loads, and −A u₀ of
/// the prescribed values u₀; its constrained entries are ignored. solve() returns the solution
/// with zeros on the constrained DoFs: the caller distributes the constraints' values.
class MatrixFreeElasticitySolver {
 public:
  /// The supports as constraints on any displacement DoFHandler of the mesh (P1 or P2).
  using ConstraintsFor =
      std::function<void(const dl::DoFHandler<kDim>&, dl::AffineConstraints<double>&)>;
  /// `dof` holds FESystem(FE_SimplexP(degree), 3) on a conforming tet mesh; `constraints_for`
  /// builds the supports on it and on the P1 level (inhomogeneities are dropped here). `centre`
  /// (m): the rotation centre of the AMG's rigid-body modes. `mapping` and `dof` must outlive this.
  MatrixFreeElasticitySolver(const dl::Mapping<kDim>& mapping, const dl::DoFHandler<kDim>& dof,
                             const ConstraintsFor& constraints_for, int degree, double lambda,
                             double mu, const Vec3& centre, const PMultigridSettings& settings = {},
                             const NeoHookeanTangentState* tangent = nullptr);
  ~MatrixFreeElasticitySolver();

  /// A matrix added to the operator, on the full DoF numbering, zero on constrained rows and
  /// columns: the follower pressure's (unsymmetric) share of the finite-strain tangent.
  using AddedMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  struct Outcome {
    unsigned iterations = 0;
    double residual = 0.0;  ///< final ‖r‖₂, N
  };
  /// Solves A u = b by preconditioned CG to ‖r‖ ≤ relative_tolerance·‖b‖ (runtime_error when
  /// max_iterations pass first). `u` (m) is the initial guess on entry.
  /// With `added` = S: (A + S) u = b by FGMRES, preconditioned by the same V-cycle on A.
  Outcome solve(const dl::Vector<double>& b, dl::Vector<double>& u, double relative_tolerance,
                unsigned max_iterations, const AddedMatrix* added = nullptr) const;
  /// The same on vectors of initialize_dof_vector's layout (any number of ranks; no `added`).
  Outcome solve(const MfVector& b, MfVector& u, double relative_tolerance,
                unsigned max_iterations) const;
  /// `v` in the fine operator's layout (owned DoFs and ghosts), zero.
  void initialize_dof_vector(MfVector& v) const { fine_->initialize_dof_vector(v); }

  /// x = one V-cycle of the preconditioner applied to r (zero on the constrained DoFs): an
  /// approximate A⁻¹ for a block preconditioner (the Taylor–Hood system's displacement block).
  void precondition(dl::Vector<double>& x, const dl::Vector<double>& r) const;

  [[nodiscard]] const ElasticityOperator& fine_operator() const { return *fine_; }
  /// Wall-clock seconds the constructor took (operators, transfer, diagonal, coarse solver).
  [[nodiscard]] double setup_seconds() const { return setup_seconds_; }
  /// The set-up's parts and, after solve(), the CG's (summed over the solves so far).
  [[nodiscard]] MatrixFreeProfile profile() const;
  /// Bytes held: both operators' MatrixFree data, the diagonal and the vectors (not the CHOLMOD
  /// factor or ML's hierarchy, which their libraries do not report).
  [[nodiscard]] std::size_t memory_consumption() const;

 private:
  class VCycle;
  /// CG (FGMRES with `added`) on rhs with the initial guess and result x, both in the fine
  /// operator's layout (rhs's constrained entries zeroed here).
  Outcome krylov(MfVector& rhs, MfVector& x, double relative_tolerance, unsigned max_iterations,
                 const AddedMatrix* added) const;
  dl::AffineConstraints<double> fine_constraints_;
  std::unique_ptr<ElasticityOperator> fine_;
  std::unique_ptr<VCycle> preconditioner_;
  double setup_seconds_ = 0.0;
  mutable MatrixFreeProfile profile_;
};

}  // namespace vessel::fem::detail
