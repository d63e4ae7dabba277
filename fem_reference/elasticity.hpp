#pragma once
/// The FEM reference: small-strain isotropic linear elasticity on a vessel TetMesh with deal.II
/// simplex elements (P1, P2, Taylor–Hood P2–P1 for ν → 0.5). Plain data only: deal.II stays inside
/// fem_reference's .cpp files and its private detail/ headers (pimpl), so including this header
/// compiles no deal.II. SI units throughout.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "meshes/supports.hpp"
#include "meshes/surface_loads.hpp"
#include "meshes/tet_mesh.hpp"

namespace vessel::fem {

/// Isotropic linear-elastic material.
struct Material {
  double youngs_modulus = 14.24e3;  ///< E, Pa (vessel wall, Wang Bin et al. via seed 000)
  double poisson_ratio = 0.3;       ///< ν, dimensionless, in [0, 0.5]
  double density = 1060.0;          ///< ρ, kg/m³
  /// Lamé's first parameter λ = Eν / ((1+ν)(1−2ν)), Pa (infinite at ν = 0.5).
  [[nodiscard]] double lambda() const;
  /// Shear modulus μ = E / (2(1+ν)), Pa.
  [[nodiscard]] double mu() const;
};

/// Displacement-only (P1 or P2) or mixed displacement–pressure (Taylor–Hood P2–P1).
enum class Formulation { automatic, displacement, mixed };
/// direct: CHOLMOD (displacement) or UMFPACK (mixed); cg_amg: CG with AMG (displacement only);
/// gmres_block: FGMRES with a block-triangular AMG / pressure-mass preconditioner (mixed only);
/// matrix_free: CG on the matrix-free operator with a P2 → P1 p-multigrid, ML-CG on P1 (AMG for
/// P1 itself) (displacement only; no P2 matrix is assembled).
/// The values are part of the FEM solution cache's key: append, never renumber.
enum class LinearSolver { automatic, direct, cg_amg, gmres_block, matrix_free };

/// A Dirichlet condition on the nodes of a boundary group (a dim-2 physical group).
struct DirichletCondition {
  enum class Kind {
    clamped,  ///< all three components prescribed: u = value(x) (zero when value is empty)
    roller    ///< only u[component] = 0, the others free (the plane-strain end of a straight tube)
  };
  std::string group;
  Kind kind = Kind::clamped;
  int component = 2;                       ///< roller: 0, 1, 2 for x, y, z
  std::function<Vec3(const Vec3&)> value;  ///< clamped: prescribed u(x), m

  /// All components held: u = value(x) on the group (u = 0 without a value).
  static DirichletCondition clamped(std::string group,
                                    std::function<Vec3(const Vec3&)> value = {}) {
    return {std::move(group), Kind::clamped, 0, std::move(value)};
  }
  /// u[component] = 0 on the group, the other components free.
  static DirichletCondition roller(std::string group, int component) {
    return {std::move(group), Kind::roller, component, {}};
  }
};

/// u[component] = 0 at the mesh node at `point` (within 1e-6 of a typical element length;
/// InputError otherwise). Used to remove the rigid-body modes that rollers leave free. The same
/// type as the supports' pins (meshes/supports.hpp), e.g. vessel::tube_in_plane_pins.
using PointConstraint = Pin;

/// Uniform pressure p (Pa) on a boundary group: traction −p n (n outward).
struct PressureLoad {
  std::string group;
  double pressure = 0.0;
};

/// A boundary group whose exact surface is known: with a quadratic element its P2 geometry nodes
/// (edge midpoints) are moved onto the surface by `project` (isoparametric MappingFEField), so the
/// curved wall is represented to O(h³) instead of the straight-sided tets' O(h²).
struct CurvedSurface {
  std::string group;
  std::function<Vec3(const Vec3&)> project;  ///< closest point on the exact surface, m
};

/// The straight tube's walls: cylinders r = a (inner_wall) and r = b (outer_wall) about the z axis.
std::vector<CurvedSurface> tube_curved_walls(double inner_radius, double outer_radius);

struct SolverOptions {
  int degree = 1;  ///< displacement element degree, 1 or 2 (the mixed element is always P2–P1)
  Formulation formulation = Formulation::automatic;
  /// automatic: mixed Taylor–Hood when ν ≥ this (and always at ν = 0.5). Below 0.49 P2
  /// displacement elements do not lock appreciably, while the saddle-point system costs minutes
  /// and gigabytes at reference levels (docs/measurements/fem_measurements.md). The one default the harness,
  /// the scenes and the `fem` command (--mixed-threshold) use.
  double mixed_threshold = 0.49;
  LinearSolver solver = LinearSolver::automatic;
  /// automatic: direct at or below this many DoFs (CHOLMOD for the displacement system, UMFPACK
  /// for the mixed one), else CG-AMG. Measured on this machine (2 cores for CHOLMOD's OpenBLAS,
  /// idle, contact, P2 level 1): unstructured tube 211k DoFs CHOLMOD 13.7 s vs AMG-CG 23.4 s
  /// (152 iterations); structured tube 231k, 35.6 s vs 46.0 s; structured arch, clamped, 272k
  /// (`vesselverify fem --vessel arch --structured --level 1 --degree 2 --bc clamped`), 40.6 s
  /// and 3.6 GB peak vs 48.9 s (245 iterations) and 1.2 GB. On one core AMG-CG wins from ~230k
  /// (docs/physics/fem_reference.md). The factor's memory grows faster than AMG's (~n^4/3):
  /// about 6 GB at this limit, so two references solved side by side fit a 24 GB machine.
  std::size_t direct_max_dofs = 400000;
  /// automatic, mixed system: UMFPACK at or below this many DoFs, else gmres_block. Measured
  /// (docs/measurements/fem_measurements.md): level 0 (34–47k DoFs) UMFPACK 4–11 s vs FGMRES 8–21 s; level 1
  /// (214k / 241k) UMFPACK 102 s, 4.6 GB / 426 s, 13.4 GB vs FGMRES 51 s / 216 s at ~2 GB (contact).
  std::size_t direct_max_mixed_dofs = 100000;
  /// automatic, the linear reference's P2 displacement system on straight-sided tets solved once
  /// (not keep_factor): the matrix-free p-multigrid CG from this many DoFs, where it overtook
  /// CHOLMOD on this machine (docs/measurements/solver_switch.md,
  /// scripts/measure_solver_switch.py); 0: never. It changes the answer only within
  /// cg_relative_tolerance, so it is not part of the solution cache's key (a reference the
  /// distributed job stored serves the serial run).
  std::size_t matrix_free_min_dofs = 14000;
  /// CG-AMG: give ML all six rigid-body modes (translations and rotations) as near-null space;
  /// false: only the three translations (deal.II's AdditionalData::constant_modes).
  bool amg_rigid_body_modes = true;
  /// matrix_free, P2: the P1 level of the p-multigrid solved exactly by a CHOLMOD factor at or
  /// below this many P1 DoFs, above by CG with ML to a relative residual of 0.1 (measured in
  /// docs/measurements/matrix_free_multigrid.md). Changes the answer only within the CG
  /// tolerance, so it is not part of the solution cache's key.
  std::size_t matrix_free_direct_coarse_max_dofs = 0;
  double cg_relative_tolerance = 1e-10;  ///< ‖r‖ ≤ tol·‖b‖ for CG and FGMRES
  /// gmres_block: Krylov basis size before FGMRES restarts (memory: 2 × this many vectors).
  unsigned gmres_restart = 100;
  unsigned max_iterations = 5000;
  /// direct (CHOLMOD) displacement solve: keep the factor for the next solve of the identical
  /// matrix (solve_spd_cholmod_keeping_factor: the references of several loads on one vessel
  /// factorise once). Changes no result, so it is not part of the solution cache's key. Off by
  /// default: a timed FEM model must pay for its factorisation each time.
  bool keep_factor = false;
};

/// The solver a system gets and why (the request, or `automatic`'s rule and its numbers).
struct SolverChoice {
  LinearSolver solver = LinearSolver::direct;
  std::string reason;
};

struct ElasticityProblem {
  Material material;
  std::vector<DirichletCondition> dirichlet;
  std::vector<PointConstraint> point_constraints;
  std::vector<PressureLoad> pressures;
  /// From vessel::contact_patch (shared with mass-spring): each patch's traction is integrated at
  /// its quadrature points, Σ_q w_q t·v(ξ_q), so the applied force is Σ_q w_q t exactly.
  std::vector<TractionPatch> patches;
  /// Curved geometry for degree 2 (ignored for P1). A traction patch's points then sit at the same
  /// parameter points of the curved faces with their flat-triangle weights (its force unchanged);
  /// pressure is integrated over the curved faces, whose area differs from the flat ones' by O(h²).
  std::vector<CurvedSurface> curved_surfaces;
  Vec3 gravity = Vec3::Zero();  ///< m/s²; body force ρg
  /// Optional extra body force density b(x), N/m³ (manufactured solutions); added to ρg.
  std::function<Vec3(const Vec3&)> body_force;
  SolverOptions options;
};

/// Reaction force (N) exerted by the supports of one constrained group on the body.
struct GroupReaction {
  std::string group;
  Vec3 force = Vec3::Zero();
};

/// Wall-clock seconds per phase.
struct PhaseTimings {
  double setup = 0.0;  ///< triangulation, DoFs, constraints, sparsity
  double assembly = 0.0;
  double solve = 0.0;
  double postprocess = 0.0;  ///< nodal values, energy, strains, reactions
};

/// Where the matrix-free solve (LinearSolver::matrix_free) spent its wall-clock seconds: the
/// set-up's parts, then the CG's. Zero for the other solvers.
struct MatrixFreeProfile {
  double fine_operator = 0.0;  ///< MatrixFree::reinit on the fine DoFs (mapping data, indices)
  double coarse_level = 0.0;   ///< P1 DoFHandler, its constraints and MatrixFree::reinit
  double transfer = 0.0;       ///< the P2 → P1 transfer's set-up
  double diagonal = 0.0;       ///< diag(A) for Chebyshev
  double eigenvalue_estimate = 0.0;  ///< Chebyshev's λ_max(D⁻¹A) by CG steps
  double coarse_matrix = 0.0;        ///< the P1 matrix (MatrixFreeTools::compute_matrix)
  double coarse_factor = 0.0;  ///< CHOLMOD's analysis and factorisation of it (or ML's set-up)
  std::string coarse_method;   ///< how the P1 level is solved: "CHOLMOD", "ML-CG", "one ML V-cycle"
  unsigned coarse_iterations = 0;  ///< ML-CG: inner CG iterations, all P1 solves together
  double cg = 0.0;             ///< the CG iterations, all of them
  unsigned operator_applications = 0;  ///< fine A·v in the CG (smoother, residuals, CG's own)
  double operator_seconds = 0.0;       ///< of cg: in those applications
  unsigned coarse_solves = 0;          ///< P1 solves (one per V-cycle)
  double coarse_solve_seconds = 0.0;   ///< of cg: in those
  double transfer_seconds = 0.0;       ///< of cg: restriction and prolongation
  unsigned chebyshev_degree = 0;       ///< matrix-vector products per smoothing step
  unsigned quadrature_points = 0;      ///< per cell, of the fine operator
};

struct ElasticityResult {
  std::string element;  ///< "P1", "P2" or "P2-P1 (Taylor-Hood)"
  bool curved = false;  ///< quadratic geometry on the curved surfaces
  Formulation formulation = Formulation::displacement;  ///< the one used
  LinearSolver solver = LinearSolver::direct;           ///< the one used
  std::string solver_reason;  ///< why: requested, or automatic's rule (SolverChoice)
  unsigned iterations = 0;  ///< CG or FGMRES iterations (0 for direct)
  double inner_iterations = 0.0;  ///< gmres_block: mean CG iterations per pressure-mass solve
  std::size_t n_dofs = 0;
  std::size_t n_pressure_dofs = 0;       ///< mixed only: how many of n_dofs are pressure's
  std::vector<Vec3> nodal_displacement;  ///< at every TetMesh node, m
  std::vector<GroupReaction> reactions;  ///< one per Dirichlet group, in order of first mention
  Vec3 applied_load = Vec3::Zero();      ///< ∫ traction dA + ∫ ρg dV, N
  double strain_energy = 0.0;            ///< ½∫σ:ε dV, J
  double max_principal_strain = 0.0;  ///< largest eigenvalue of ε over the mesh (quadrature points)
  double max_abs_principal_strain = 0.0;  ///< largest |eigenvalue| of ε: the linear-regime flag
  /// Per tet, at its centroid: ε and σ as (xx, yy, zz, xy, yz, xz), dimensionless and Pa.
  std::vector<std::array<double, 6>> tet_strain;
  std::vector<std::array<double, 6>> tet_stress;
  PhaseTimings timings;
  MatrixFreeProfile matrix_free;  ///< solver matrix_free only
};

/// Natural frequencies and mode shapes: K x = ω² M x with the consistent mass matrix, on the
/// problem's constraints (made homogeneous; loads are ignored).
struct ModalResult {
  std::vector<double> frequencies_hz;  ///< f = ω / 2π, ascending
  /// Per mode, the displacement at every TetMesh node, scaled so that max |u| = 1.
  std::vector<std::vector<Vec3>> mode_shapes;
  std::size_t n_dofs = 0;  ///< unconstrained DoFs of the eigenproblem
  double seconds = 0.0;    ///< assembly and eigensolve
};

/// The FEM transient of a step load (Newmark, average acceleration β = 1/4, γ = 1/2): the
/// problem's loads (and any prescribed Dirichlet values) applied at t = 0 to a body at rest,
/// M ü + C u̇ + K u = f with the consistent mass matrix and C = α M.
struct TransientOptions {
  double dt = 1e-4;                 ///< s (> 0, else InputError)
  int steps = 100;                  ///< (> 0)
  double mass_damping = 0.0;        ///< α (1/s): C = α M
  std::vector<Vec3> probe_points;   ///< where the history is recorded (evaluated like displacement_at)
  double outside_tolerance = 1e-9;  ///< as displacement_at
};

struct TransientResult {
  std::vector<double> time;                           ///< s, time[0] = 0 (rest), size steps+1
  std::vector<std::vector<Vec3>> probe_displacement;  ///< [step][probe], m
  std::vector<Vec3> final_nodal_displacement;         ///< at every TetMesh node, m
  double setup_seconds = 0.0;                         ///< mass/stiffness assembly + factorisation
  double seconds_per_step = 0.0;
  std::size_t n_dofs = 0;
  /// Per step (size steps+1), J, on the unconstrained DoFs: ½ u̇ᵀM u̇, ½ uᵀK u and fᵀu. Without
  /// damping, kinetic + strain − load_work stays 0 (the scheme conserves it exactly).
  std::vector<double> kinetic_energy, strain_energy, load_work;
};

/// The displacement system on its unconstrained DoFs, K u = f: what a simulator running linear FEM
/// factorises once and solves at every update (the constraints condensed, prescribed values moved
/// into f).
struct FreeDisplacementSystem {
  Eigen::SparseMatrix<double> K;  ///< N/m, symmetric positive definite, both triangles stored
  Eigen::VectorXd f;              ///< N
  std::vector<int> free_index;    ///< per DoF (this solver's numbering) its row, −1 if constrained
  /// Per TetMesh node, the rows of its x, y and z displacement (−1 where constrained).
  std::vector<std::array<int, 3>> node_rows;
  /// Per row, its DoF's support point (m, through the solver's mapping: a P2 row on a curved wall
  /// lies on the curved surface) and displacement component (0–2): where a field's interpolant
  /// takes the row's value (interpolate_rows). Filled by HyperelasticSolver::free_dofs and
  /// ElasticitySolver::set_row_points, not by free_displacement_system (a simulator's set-up,
  /// timed, does not pay for them).
  std::vector<Vec3> row_points;
  std::vector<int> row_components;
};

/// The rows of `system` of the field's interpolant: row r takes field(row_points[r]) in its
/// component (m). For a start state on a mesh from a displacement known elsewhere (another mesh's).
Eigen::VectorXd interpolate_rows(const FreeDisplacementSystem& system,
                                 const std::function<Vec3(const Vec3&)>& field);

/// Solves a linear-elastic problem on one mesh and keeps the solution for point evaluation.
class ElasticitySolver {
 public:
  /// Validates the problem (InputError naming the parameter or group: E ≤ 0, ν ∉ [0, 0.5],
  /// ν = 0.5 with the displacement formulation, degree ∉ {1, 2}, a missing group, a point
  /// constraint off the mesh's nodes) and builds the deal.II triangulation from the mesh.
  ElasticitySolver(const TetMesh& mesh, ElasticityProblem problem);
  ~ElasticitySolver();
  ElasticitySolver(const ElasticitySolver&) = delete;
  ElasticitySolver& operator=(const ElasticitySolver&) = delete;

  /// Assembles and solves; returns the result (also kept in result()).
  const ElasticityResult& solve();

  /// Assembles the displacement formulation's system on its unconstrained DoFs (no solve; does
  /// not need solve()). InputError for the mixed formulation (its system is indefinite).
  [[nodiscard]] FreeDisplacementSystem free_displacement_system() const;
  /// Fills `system`'s row_points and row_components (`system` from free_displacement_system()).
  void set_row_points(FreeDisplacementSystem& system) const;

  [[nodiscard]] const ElasticityResult& result() const;

  /// A u by the matrix-free operator (N per DoF), for u (m) in this solver's DoF numbering: the
  /// stiffness a(u, v) on the unconstrained DoFs, the identity on the constrained ones. The same
  /// bilinear form free_displacement_system() assembles (compare them on its free rows).
  /// Displacement formulation only (InputError for the mixed one); does not need solve().
  [[nodiscard]] std::vector<double> matrix_free_product(const std::vector<double>& u) const;
  /// diag(A) of the matrix-free operator (N/m per DoF; 1 on the constrained DoFs), as the
  /// multigrid's Chebyshev smoother gets it. Displacement formulation only.
  [[nodiscard]] std::vector<double> matrix_free_diagonal() const;
  /// A u (N per DoF) by the sparse matrix MatrixFreeTools::compute_matrix builds from the
  /// matrix-free operator's cell kernel, as the multigrid's P1 level gets it; u (m) zero on the
  /// constrained DoFs. Displacement formulation only.
  [[nodiscard]] std::vector<double> matrix_free_matrix_product(const std::vector<double>& u) const;
  /// The P2 multigrid's P1 → P2 prolongation P (detail::P1ToP2Embedding) against deal.II's
  /// MGTwoLevelTransfer::reinit_polynomial_transfer on this solver's P2 DoFs: max |P x − P' x|
  /// and max |Pᵀ y − P'ᵀ y| for random x, y (zero on the constrained DoFs), each relative to the
  /// largest entry of P' x resp. P'ᵀ y. P2 displacement formulation only.
  [[nodiscard]] std::array<double, 2> matrix_free_transfer_difference(unsigned seed) const;

  /// The solved DoF values (displacement, and pressure for the mixed formulation), in this
  /// solver's DoF numbering, which depends only on the mesh and the problem. Requires solve().
  [[nodiscard]] std::vector<double> solution_dofs() const;
  /// Puts the solver in the state solve() would leave it in, from a result and DoF values that
  /// an earlier solve() of the same mesh and problem produced (fem::SolutionCache): no assembly,
  /// no solve. std::invalid_argument if the DoF count differs from this solver's.
  const ElasticityResult& restore(ElasticityResult result, const std::vector<double>& dofs);

  /// The FE displacement (m) at arbitrary points inside the mesh (within a relative tolerance of
  /// 1e-9 of the element size). Throws InputError naming the first point outside. Requires solve().
  /// `outside_tolerance` (barycentric, dimensionless) also accepts points that far outside the
  /// nearest tet, evaluated by extending its polynomial: a node on an exact curved wall lies outside
  /// the straight-sided tets by up to the chord's sagitta (a few % of a tet's height).
  [[nodiscard]] std::vector<Vec3> displacement_at(const std::vector<Vec3>& points,
                                                  double outside_tolerance = 1e-9) const;

  /// The `count` lowest natural frequencies (shift-invert Lanczos, Spectra, on the displacement
  /// formulation; InputError for the mixed one). Does not need solve(). Without constraints the
  /// six rigid-body modes come first with f ≈ 0.
  [[nodiscard]] ModalResult modes(int count = 10) const;

  /// The response to the problem's loads applied as a step at t = 0 on a body at rest (Newmark
  /// average acceleration, unconditionally stable, no numerical damping). K + (4/dt² + 2α/dt) M
  /// is factorised once (CHOLMOD) and reused. Displacement formulation only (InputError for the
  /// mixed one, for density ≤ 0, dt ≤ 0, steps ≤ 0, α < 0, a probe outside the mesh). Does not
  /// need solve().
  [[nodiscard]] TransientResult transient(const TransientOptions& options) const;

  /// ‖u_h − u‖_L2 / ‖u‖_L2 over the mesh, integrated with a quadrature two orders above the
  /// element's. Requires solve().
  [[nodiscard]] double relative_l2_error(const std::function<Vec3(const Vec3&)>& exact) const;

  /// Volume of the discrete domain, m³ (the tets', or the curved cells' with curved surfaces).
  [[nodiscard]] double domain_volume() const;

 private:
  /// The finite-strain reference reuses this solver's discretisation (triangulation, DoFs,
  /// supports, loads, linear solvers, point evaluation) and assembles its own tangent.
  friend class HyperelasticSolver;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Convenience: ElasticitySolver(mesh, problem).solve().
ElasticityResult solve_elasticity(const TetMesh& mesh, const ElasticityProblem& problem);

std::string to_string(Formulation f);
std::string to_string(LinearSolver s);

}  // namespace vessel::fem
