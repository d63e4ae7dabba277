#pragma once
/// An XPBD Cosserat rod: position- and orientation-based Cosserat rods (Kugelstadt & Schömer,
/// SCA 2016) with compliance (XPBD, Macklin, Müller & Chentanez 2016). The state is CORDE's
/// (centreline points, a quaternion per edge, the same dof layout); per time step h the
/// constraint blocks
///   stretch–shear  Γ_j = (P_{j+1} − P_j)/l_j − d3(q_j), compliance 1/(κ l_j),
///   bend–twist     Ω_i = (2/l̄_i) Im(q̄_{i−1} q_i),    compliance diag(EI, EI, GJ)⁻¹/l̄_i,
/// are solved for the step's multipliers λ (Δλ = −(J W Jᵀ + α/h²)⁻¹ (C + α λ/h²), Δx = W Jᵀ Δλ,
/// quaternions renormalised), either block by block in Gauss–Seidel sweeps or all blocks at once
/// (`XpbdSolver::direct`: one block-tridiagonal Cholesky per iteration of the chain-ordered blocks
/// taken two by two, as Deul et al. 2018's direct solver for rods).
///
/// The quaternion columns of each block's Jacobian are projected onto the unit sphere's tangent
/// space, J_q (I − q qᵀ): no correction (and no carried force) goes into |q|, which the
/// renormalisation would undo while λ kept it (without it the carried multipliers diverge).
///
/// Multipliers are carried from step to step (`warm_start`): a step starts from the last step's
/// λ (as a force, rescaled by h²) and the prediction includes that force, x̃ = x + h v +
/// h² W (f + Jᵀ λ). A converged step is XPBD's step either way; a steady state with v = 0 is a
/// fixed point only if C + α λ = 0 on every block and f + Jᵀ λ = 0, which is the static
/// equilibrium of the energy whatever the number of iterations. Restarting λ from zero every step
/// (`warm_start = false`, Macklin et al.'s algorithm) leaves a steady state that depends on the
/// sweep count and the step (tests/rods/test_xpbd.cpp measures both). Warm starts need the
/// direct solver: with Gauss–Seidel sweeps the carried multipliers diverged (measured), so that
/// combination is refused.
///
/// With warm starts the frames' mass gets the diagonal of the carried force's geometric stiffness
/// (h² K added; Andrews, Teichmann & Kry 2017): the warm start applies that force along the
/// step's initial directions, and without the term the light frames diverged (the α = 3
/// cantilever at N = 32 and 64, h = 10 ms). A steady state does not depend on the masses.
///
/// Its energy is CordeRod(layout, κ, inextensible = false)'s. The frames carry the segment's
/// rotary inertia ρA l³/12: with the section's ρI l alone they are ~10⁷ times lighter than the
/// points and the sweeps diverge. An optional rigid lumen adds one-sided, frictionless node
/// contacts g(P) ≥ 0 (no compliance; their multipliers kept ≥ 0, so the wall never pulls),
/// projected after each sweep, or before each direct iteration (a step ends on the direct
/// solve; the carried contact force in the prediction keeps the penetration at rounding level).
#include <array>
#include <utility>
#include <vector>

#include "msm/rods/block_tridiagonal_cholesky.hpp"
#include "msm/rods/corde_rod.hpp"
#include "msm/rods/rigid_wall.hpp"

namespace vessel::msm::rods {

enum class XpbdSolver { gauss_seidel, direct };

struct XpbdOptions {
  int iterations = 2;     ///< direct iterations, or Gauss–Seidel sweeps, per step
  double damping = 0.02;  ///< velocity damping per step (fraction removed)
  XpbdSolver solver = XpbdSolver::direct;
  /// Carry the multipliers from step to step (see above). Direct solver only: with Gauss–Seidel
  /// sweeps the carried multipliers diverge (measured), so that combination is refused.
  bool warm_start = true;
};

class XpbdRod {
 public:
  XpbdRod(RodLayout layout, double alignment = 0.0, XpbdOptions options = {});

  /// One step of length h under the dead loads `force` (per dof; positions only).
  void step(double h, const VectorXd& force);
  /// Steps until the largest position change in a step is ≤ tolerance·L (or max_steps);
  /// returns the number of steps taken.
  int relax(double h, const VectorXd& force, double tolerance, int max_steps);

  /// Nodes first_node..last_node must stay inside `lumen` (kept by reference; null: no wall).
  void set_wall(const RigidLumen* lumen, int first_node, int last_node);
  /// The wall's force on each node, N (≥ 0; zero off the wall), from the carried multipliers.
  [[nodiscard]] std::vector<double> wall_forces() const;
  /// Replaces the state (velocities and multipliers reset); quaternions renormalised.
  void set_state(const VectorXd& x);

  [[nodiscard]] const VectorXd& state() const { return x_; }
  [[nodiscard]] const CordeRod& energy_model() const { return model_; }
  [[nodiscard]] int tip_node() const { return model_.layout().tip_node; }
  [[nodiscard]] const XpbdOptions& options() const { return options_; }

 private:
  /// One constraint block: 3 rows on up to 10 dofs (stretch–shear: P_j, P_{j+1}, q_j;
  /// bend–twist: q_{i−1}, q_i).
  struct Block {
    bool stretch = true;
    int dofs_used = 10;
    std::array<int, 10> dofs{};
    double length = 0.0;         ///< l_j or l̄_i
    Eigen::Vector3d compliance;  ///< α per row (before division by h²)
  };
  using BlockJacobian = Eigen::Matrix<double, 3, 10>;

  void build_blocks();
  void build_couplings();
  void evaluate(const Block& b, Eigen::Vector3d& c, BlockJacobian& J) const;
  /// x += W Jᵀ dl for block b (dl: 3 entries).
  void apply(const Block& b, const BlockJacobian& J, const double* dl);
  /// Block a's rows of J W Jᵀ + α/h² (its diagonal block and its couplings to blocks a+1, a+2)
  /// and of the right-hand side into the direct solver; a = the block count: the dummy.
  void assemble(int a, double inverse_h2);
  void gauss_seidel_sweep(double h);
  void direct_iteration(double h);
  void project_contacts();
  void predict(double h, const VectorXd& force);
  void stabilise_quaternion_masses(double h);

  CordeRod model_;
  XpbdOptions options_;
  VectorXd x_, v_, inverse_mass_;
  std::vector<double> quaternion_mass_;        ///< per edge, per component (zero: held)
  std::vector<Block> blocks_;                  ///< in chain order: bt_1, ss_1, bt_2, ss_2, ...
  std::vector<Eigen::Vector3d> lambda_;        ///< the step's multipliers (λ, scaled by h²)
  std::vector<Eigen::Vector3d> force_lambda_;  ///< carried multipliers as forces (λ/h²)
  /// Columns width wide from col_a in one block's Jacobian and col_b in another's on the same
  /// dofs (from `dof`) of one inverse mass. On positions (only stretch–shear blocks have
  /// them) each column is ±e_k/l, one nonzero in the row of the dof's component, so the run's
  /// product is diagonal.
  struct Shared {
    int col_a = 0, col_b = 0, width = 0, dof = 0;
    bool position = false;
  };
  /// A block's own columns in runs of one inverse mass (for J W Jᵀ).
  std::vector<std::vector<Shared>> own_runs_;
  /// For blocks a and a+d (d = 1, 2): their shared columns.
  std::vector<std::array<std::vector<Shared>, 2>> couplings_;
  std::vector<BlockJacobian> jacobians_;
  std::vector<Eigen::Vector3d> residuals_;
  /// The direct solver's J W Jᵀ + α/h², blocks in pairs; a pair's first block and the next
  /// pair's second are three apart and do not couple (the zero corner).
  BlockTridiagonalCholesky<6, 3> system_;
  VectorXd rhs_;
  const RigidLumen* lumen_ = nullptr;
  int wall_first_ = 0, wall_last_ = -1;
  std::vector<double> contact_lambda_;        ///< per node, the step's (scaled by h²)
  std::vector<double> contact_force_lambda_;  ///< per node, carried (λ/h²)
  // Per-step scratch, kept to avoid allocating each step.
  VectorXd previous_, scratch_;
  std::vector<double> quaternion_stiffness_;
};

}  // namespace vessel::msm::rods
