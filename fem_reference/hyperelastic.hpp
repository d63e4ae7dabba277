#pragma once
/// The finite-strain FEM reference: hyperelastic statics, total Lagrangian, on the same mesh,
/// supports, loads, elements and linear solvers as the linear reference (ElasticitySolver, whose
/// discretisation it reuses). Compressible neo-Hookean with P1 or P2 displacement, or a mixed
/// displacement–pressure form with Taylor–Hood P2–P1 for ν → 0.5 (and ν = 0.5). Newton with a
/// line search, adaptive load stepping. Plain data only (no deal.II). SI units. The formulas are
/// derived in docs/physics/finite_strain.md.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fem_reference/elasticity.hpp"

namespace vessel::fem {

using Mat3 = Eigen::Matrix3d;
/// A fourth-order tensor A_{aJbL} as a 9×9 matrix, row 3a+J, column 3b+L.
using Mat9 = Eigen::Matrix<double, 9, 9>;

/// Compressible neo-Hookean: Ψ(F) = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)², I₁ = tr FᵀF, J = det F
/// (e.g. Bonet & Wood, Nonlinear Continuum Mechanics for FE Analysis, 2nd ed., eq. 6.27). Its
/// linearisation at F = I is linear elasticity with the same λ, μ.
struct NeoHookean {
  double mu = 0.0;      ///< shear modulus μ, Pa
  double lambda = 0.0;  ///< Lamé's λ, Pa (infinite at ν = 0.5: mixed form only)

  static NeoHookean of(const Material& m) { return {m.mu(), m.lambda()}; }

  /// Ψ(F), J/m³ (+∞ if J ≤ 0).
  [[nodiscard]] double energy(const Mat3& F) const;
  /// The first Piola–Kirchhoff stress with the volumetric part given by a pressure field p:
  /// P = μ (F − F⁻ᵀ) − p F⁻ᵀ. The compressible form has p = −λ ln J.
  [[nodiscard]] static Mat3 stress_at_pressure(const Mat3& F, double p, double mu);
  /// ∂P/∂F at fixed p: μ δ_ab δ_JL + (μ + p) F⁻¹_Jb F⁻¹_La.
  [[nodiscard]] static Mat9 tangent_at_pressure(const Mat3& F, double p, double mu);
  /// P = ∂Ψ/∂F = μ (F − F⁻ᵀ) + λ ln J F⁻ᵀ.
  [[nodiscard]] Mat3 stress(const Mat3& F) const;
  /// ∂P/∂F: tangent_at_pressure(F, −λ ln J) + λ F⁻ᵀ ⊗ F⁻ᵀ.
  [[nodiscard]] Mat9 tangent(const Mat3& F) const;
};

struct HyperelasticOptions {
  /// Load stepping: the problem's loads (tractions, pressures, gravity, body force, prescribed
  /// displacements) all scale with one load factor s from 0 to `target_load_factor`.
  double target_load_factor = 1.0;
  double initial_step = 1.0;  ///< first increment of s
  double min_step = 1e-4;     ///< give up when a failed increment would be smaller
  double max_step = 1.0;
  double growth = 1.5;  ///< increment × this after a step that took ≤ fast_iterations
  int fast_iterations = 4;
  int max_newton_iterations = 25;
  int max_line_search = 10;  ///< halvings of the Newton step before the step fails
  /// Converged when the residual's norm (free DoFs) ≤ this × the internal force's norm (all
  /// DoFs, i.e. loads and reactions), or the Newton update is at round-off.
  double residual_tolerance = 1e-9;
  /// true: pressure acts on the deformed surface (traction −p n da); false: a dead load on the
  /// reference surface (as the linear reference applies it).
  bool follower_pressure = true;
  /// Load factors (ascending, in (0, target_load_factor]) where a load step must end: the
  /// continuation records its state there (HyperelasticResult::checkpoints) and calls the
  /// observer given to solve(). One continuation then serves a ladder of loads.
  std::vector<double> checkpoints;
  /// true: after each converged step, test whether the wall has passed through itself
  /// (find_self_penetration, meshes/self_contact.hpp); such a state is no equilibrium of the
  /// real vessel, which would touch itself first, and this reference models no contact. The step
  /// is then rejected like a Newton failure, so the continuation stops at the largest load
  /// without it, to within min_step (HyperelasticResult::self_contact).
  bool stop_at_self_contact = true;
};

/// The state of a continuation at one of HyperelasticOptions::checkpoints.
struct Checkpoint {
  double load_factor = 0.0;
  int load_steps = 0;         ///< accepted steps so far
  int rejected_steps = 0;     ///< so far
  int newton_iterations = 0;  ///< so far, accepted and rejected steps
  double seconds = 0.0;       ///< assembly + linear solves so far, s
  std::vector<Vec3> nodal_displacement;  ///< at every TetMesh node, m
};

/// One accepted load step.
struct LoadStep {
  double load_factor = 0.0;
  int newton_iterations = 0;
  double residual = 0.0;  ///< relative residual at convergence
};

struct HyperelasticResult {
  std::string element;  ///< "P1", "P2" or "P2-P1 (Taylor-Hood)"
  Formulation formulation = Formulation::displacement;
  LinearSolver solver = LinearSolver::direct;  ///< the one used for the Newton systems
  std::string solver_reason;  ///< why: requested, or automatic's rule (SolverChoice)
  std::size_t n_dofs = 0;
  /// The largest load factor at which equilibrium was found, and whether it is the target.
  double load_factor = 0.0;
  bool completed = false;
  std::string stop_reason;         ///< empty when completed; else why the load could not go on
  /// The continuation stopped because the next load would make the wall pass through itself.
  bool self_contact = false;
  std::vector<LoadStep> steps;     ///< accepted steps
  int rejected_steps = 0;          ///< increments halved after a Newton failure
  int newton_iterations = 0;       ///< total, accepted and rejected steps
  unsigned linear_iterations = 0;  ///< total CG / FGMRES iterations (0 for direct)
  /// solver matrix_free: the p-multigrid's set-up and Krylov parts summed over the Newton systems
  /// (coarse_method and the counts of the last).
  MatrixFreeProfile matrix_free;
  std::vector<Vec3> nodal_displacement;  ///< at load_factor, at every TetMesh node, m
  std::vector<Checkpoint> checkpoints;   ///< those reached, in order
  double strain_energy = 0.0;            ///< ∫Ψ dV, J
  /// Largest |eigenvalue| of the Green–Lagrange strain E = ½(FᵀF − I) at quadrature points.
  double max_abs_principal_strain = 0.0;
  double min_jacobian = 1.0;  ///< smallest J = det F at quadrature points
  PhaseTimings timings;       ///< assembly and solve summed over all Newton iterations
};

/// The wall's strain energy and its derivatives on the unconstrained DoFs at a displacement, for
/// a problem solved outside the solver (a wire pressed into the wall: verification/contact/).
struct FreeHyperelasticState {
  bool admissible = true;  ///< false when an element is inverted (J ≤ 0): energy +∞
  double energy = 0.0;     ///< ∫Ψ dV, J
  Eigen::VectorXd gradient;             ///< ∂/∂u of the energy on the free DoFs (internal forces), N
  /// Its Hessian on the free DoFs, N/m (FreeTangents exact, both)
  Eigen::SparseMatrix<double> tangent;
  /// The Hessian with each cell's tangent projected onto the positive semidefinite cone before
  /// assembly, N/m (FreeTangents projected, both)
  Eigen::SparseMatrix<double> projected_tangent;
  /// Green–Lagrange, at quadrature points (free_state's with_strain; 0 otherwise)
  double max_abs_principal_strain = 0.0;
  double min_jacobian = 1.0;
};

/// The Hessians free_state assembles.
enum class FreeTangents {
  none,
  exact,      ///< FreeHyperelasticState::tangent
  projected,  ///< FreeHyperelasticState::projected_tangent
  both,       ///< both, from one pass over the cells
};

/// Solves a hyperelastic problem on one mesh (the ElasticityProblem's supports, loads, elements
/// and solver options; its Material's E, ν give μ, λ).
class HyperelasticSolver {
 public:
  /// InputError for what ElasticitySolver rejects, and for bad options.
  HyperelasticSolver(const TetMesh& mesh, ElasticityProblem problem,
                     HyperelasticOptions options = {});
  ~HyperelasticSolver();
  HyperelasticSolver(const HyperelasticSolver&) = delete;
  HyperelasticSolver& operator=(const HyperelasticSolver&) = delete;

  /// Called at each checkpoint reached, with the solver at that equilibrium (displacement_at
  /// reads it) and the checkpoint's record. A non-empty return stops the continuation there with
  /// that reason (result: completed false, load_factor the checkpoint's).
  using CheckpointObserver =
      std::function<std::string(const HyperelasticSolver&, const Checkpoint&)>;

  /// Load stepping with Newton from u = 0; returns the result (also kept in result()). When the
  /// target cannot be reached the result holds the last equilibrium and the reason.
  const HyperelasticResult& solve(const CheckpointObserver& observer = {});
  [[nodiscard]] const HyperelasticResult& result() const;

  /// The displacement (m) at points inside the mesh, as ElasticitySolver::displacement_at.
  [[nodiscard]] std::vector<Vec3> displacement_at(const std::vector<Vec3>& points,
                                                  double outside_tolerance = 1e-9) const;
  /// ‖u_h − u‖_L2 / ‖u‖_L2, as ElasticitySolver::relative_l2_error.
  [[nodiscard]] double relative_l2_error(const std::function<Vec3(const Vec3&)>& exact) const;

  /// The displacement (m) at points inside the mesh of the free rows u_free (free_dofs()' rows;
  /// the constrained DoFs at zero): the elements' shape functions there, as displacement_at.
  /// InputError for a point outside the mesh beyond `outside_tolerance` (barycentric).
  [[nodiscard]] std::vector<Vec3> free_displacement_at(const Eigen::VectorXd& u_free,
                                                       const std::vector<Vec3>& points,
                                                       double outside_tolerance = 1e-9) const;
  /// The unconstrained DoFs' layout as ElasticitySolver::free_displacement_system gives it
  /// (free_index, node_rows; K and f left empty). InputError for the mixed formulation, loads, or
  /// supports that prescribe a non-zero displacement: free_state() is the energy of a wall held
  /// at zero and loaded only from outside.
  [[nodiscard]] FreeDisplacementSystem free_dofs() const;
  /// Per cell (deal.II's active cell order), the free rows of its displacement DoFs: which rows
  /// share an element, for smoothing a field over the mesh.
  [[nodiscard]] std::vector<std::vector<int>> free_rows_per_cell() const;
  /// The cells (as free_rows_per_cell numbers them) inverted at u_free: J = det F ≤ 0 at one of
  /// their quadrature points, where free_state's energy is +∞.
  [[nodiscard]] std::vector<int> inverted_cells(const Eigen::VectorXd& u_free) const;
  /// The strain energy, its gradient and the Hessians `tangents` asks for at the displacement
  /// u_free (m, one value per free row; the constrained DoFs at zero), and with_strain the
  /// largest principal strain. An inverted element gives admissible = false. Requires what
  /// free_dofs() requires. The projected Hessian has each cell's tangent projected onto the
  /// positive semidefinite cone before assembly (its negative eigenvalues set to zero), so it is
  /// positive semidefinite where a compressed or buckling wall's exact one is not: the projected
  /// Newton of minimisers (Teran et al. 2005, "Robust quasistatic finite elements and flesh
  /// simulation"). The Hessians are assembled straight into the free rows' compressed columns
  /// (their pattern and each cell's positions in it built on first use).
  [[nodiscard]] FreeHyperelasticState free_state(const Eigen::VectorXd& u_free,
                                                 FreeTangents tangents = FreeTangents::none,
                                                 bool with_strain = false) const;

  [[nodiscard]] std::size_t n_dofs() const;
  /// Per DoF: its component (0–2 displacement, 3 the mixed form's pressure).
  [[nodiscard]] std::vector<unsigned> dof_components() const;
  /// The residual R(u) = f_int(u) − f_ext(u, s) at DoF values u (size n_dofs) and load factor s,
  /// on every DoF (no constraints applied), and its tangent ∂R/∂u as dense columns: for tests of
  /// the tangent against finite differences of the residual (small meshes only).
  [[nodiscard]] std::vector<double> residual(const std::vector<double>& u, double s) const;
  [[nodiscard]] std::vector<std::vector<double>> tangent_columns(const std::vector<double>& u,
                                                                 double s) const;
  /// The tangent at DoF values u applied to v by the matrix-free operator the solver matrix-free
  /// uses (displacement form; the follower pressure's faces left out): v's constrained entries
  /// read as zero, those rows returned as v's. For tests against tangent_columns.
  [[nodiscard]] std::vector<double> matrix_free_tangent_product(const std::vector<double>& u,
                                                                const std::vector<double>& v) const;
  /// The diagonal of that operator at u (the Chebyshev smoother's; 1 on constrained DoFs).
  [[nodiscard]] std::vector<double> matrix_free_tangent_diagonal(
      const std::vector<double>& u) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vessel::fem
