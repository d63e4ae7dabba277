#pragma once
/// The local–global solver of Liu, Bargteil, O'Brien & Kavan 2013, "Fast Simulation of
/// Mass-Spring Systems" (ACM TOG 32(6)), the mass-spring case of Projective Dynamics (Bouaziz
/// et al. 2014): for Hooke springs, ½k(|x_a − x_b| − l)² = min over |d| = l of ½k|x_a − x_b − d|²
/// (Liu et al.'s key identity), so with the spring directions d as extra unknowns the objective is
/// quadratic in the positions. The matrix of that quadratic (M/h² + C/h + L for implicit Euler, L
/// for statics, L the spring Laplacian) does not depend on the state and is factorised once; each
/// iteration is a local step (per spring the optimal d) and a global step (one CHOLMOD solve).
///
/// The formulas follow the paper's; its equation numbers are not cited because its text could not
/// be retrieved here to check them (the search tools returned only abstracts and summaries).
///
/// Restrictions, each refused with InputError: the form must be a plain SpringModel (not another
/// Form, e.g. one with a volume term), every spring Hooke (no bilinear law), no axial spring
/// damping (point damping is constant and is kept exactly); a node's three dofs are fixed together
/// and carry one mass.
#include <Eigen/Core>
#include <functional>
#include <memory>

#include "msm/form/form.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/static_solver.hpp"

namespace vessel::msm {

/// Spring directions d, one column per spring (m).
using SpringDirections = Eigen::Matrix3Xd;

/// The prefactored system of one problem, one time step h (h = 0: statics), and its two steps.
/// Objective (J), with the fixed nodes at their rest positions:
///   statics:        g(x, d) = Σ_s ½k_s|x_a − x_b − d_s|² − f_extᵀ(x − x0)
///   implicit Euler: g(x, d) = (1/2h²)(x − y)ᵀM(x − y) + (1/2h)(x − x_n)ᵀC(x − x_n)
///                             + Σ_s ½k_s|x_a − x_b − d_s|²,   y = x_n + h v_n + h² M⁻¹ f_ext
/// (Liu et al.'s implicit Euler objective ½(x − y)ᵀM(x − y) + h²E(x) divided by h², plus
/// constant point damping C). min over d of g(x, d) is the total potential Π(x) (statics) or the
/// implicit Euler step's objective (dynamics).
class LocalGlobalSystem {
 public:
  /// Set-up: checks the problem (InputError as above), assembles A = L (+ M/h² + C/h) on the free
  /// nodes and factorises it. InputError if A is singular (statics: a part of the network not
  /// held by a fixed node).
  LocalGlobalSystem(const Problem& problem, double h, const std::string& solver_name);
  ~LocalGlobalSystem();
  LocalGlobalSystem(const LocalGlobalSystem&) = delete;
  LocalGlobalSystem& operator=(const LocalGlobalSystem&) = delete;

  /// Local step (Liu et al.): per spring d_s = l_s (x_a − x_b)/|x_a − x_b|, the d with
  /// |d| = l_s closest to x_a − x_b. A zero-length spring keeps its previous direction (or its
  /// rest direction if d has no columns yet).
  void local_step(const VectorXd& x, SpringDirections& d) const;

  /// The constant part b of the global step's right-hand side: f_ext (statics) or
  /// M y/h² + C x_n/h (implicit Euler), per dof.
  [[nodiscard]] VectorXd constant_rhs(const VectorXd& x_n, const VectorXd& v_n) const;

  /// Global step (Liu et al.'s (M + h²L)x = h²Jd + My, divided by h²): x minimising g(·, d),
  /// i.e. the solution of A x = b + J d on the free nodes (J = Σ k_s A_s S_sᵀ ⊗ I3), fixed nodes
  /// at rest. One CHOLMOD solve with three right-hand sides.
  void global_step(const SpringDirections& d, const VectorXd& b, VectorXd& x) const;

  /// ∇_x g(x, d) on the free dofs (zero on fixed ones), N. With d = local_step(x) this is the
  /// gradient of Π (statics) or of the implicit Euler step's objective.
  void objective_gradient(const VectorXd& x, const SpringDirections& d, const VectorXd& b,
                          VectorXd& g) const;

  /// g(x, d), J (up to a constant independent of x and d).
  [[nodiscard]] double objective(const VectorXd& x, const SpringDirections& d, const VectorXd& x_n,
                                 const VectorXd& v_n) const;

  [[nodiscard]] double setup_seconds() const { return setup_seconds_; }
  [[nodiscard]] double time_step() const { return h_; }
  /// Round-off floor of the gradient norm, N: ε·max A_ii·(model size)·√n (static Newton's).
  [[nodiscard]] double roundoff() const { return roundoff_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const Problem* problem_;
  double h_;
  double setup_seconds_ = 0.0;
  double roundoff_ = 0.0;
};

struct LocalGlobalOptions {
  int iterations = 10;  ///< integrator: local–global iterations per step (fixed, as in Liu et al.)
  /// Statics: converged when ‖∇Π‖ on the free dofs ≤ tolerance·max(‖f_ext‖, force_scale) (the
  /// static Newton solver's criterion).
  double tolerance = 1e-8;
  double force_scale = 1e-12;    ///< N
  int max_iterations = 100'000;  ///< statics
  /// Called after every local and every global step with (iteration, is_global_step, x, objective
  /// g(x, d) in J); may be empty. Statics only (tests of the monotone decrease).
  std::function<void(int, bool, const VectorXd&, double)> on_half_step;
};

/// Static equilibrium by local–global iterations from `start` (rest if empty) until the gradient
/// tolerance (or the round-off floor, LocalGlobalSystem::roundoff). iterations counts local–global
/// iterations; numeric_factorisations is 1; factorisation_seconds is the set-up (assembly and
/// factorisation); seconds the whole solve. Throws std::runtime_error if max_iterations pass
/// without convergence, InputError as LocalGlobalSystem.
StaticResult solve_static_local_global(const Problem& problem,
                                       const LocalGlobalOptions& options = {},
                                       const VectorXd& start = VectorXd());

/// Implicit Euler by local–global iterations (Liu et al. 2013): `options.iterations` per step from
/// x_n + h v_n. dynamic.dt, dynamic.steps and dynamic.on_step are used (the other
/// DynamicOptions are Newton's). setup_seconds: assembly and factorisation; seconds: the steps.
/// DivergenceError if the state becomes non-finite.
DynamicResult integrate_local_global(const Problem& problem, const DynamicOptions& dynamic,
                                     const LocalGlobalOptions& options = {},
                                     const VectorXd& x0 = VectorXd(),
                                     const VectorXd& v0 = VectorXd());

/// One implicit Euler step solved by Newton to convergence (solve_static on the incremental
/// potential E(x) + (1/2h²)(x − x_n − h v_n)ᵀM(·) + (1/2h)(x − x_n)ᵀC(x − x_n) − f_extᵀx, C the
/// damping Jacobian at rest, exact for point damping): the reference the local–global integrator
/// is measured against. Returns x_{n+1}.
VectorXd implicit_euler_step_newton(const Problem& problem, const VectorXd& x_n,
                                    const VectorXd& v_n, double h,
                                    const StaticOptions& options = {});

}  // namespace vessel::msm
