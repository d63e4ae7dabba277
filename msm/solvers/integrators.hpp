#pragma once
/// Time integrators on a Problem (m ẍ = −∇E(x) + f_damping(x, ẋ) + f_ext, fixed dofs held), with
/// divergence detection, and dynamic relaxation to the static answer.
#include <array>
#include <functional>
#include <stdexcept>
#include <string>

#include "msm/form/divergence_error.hpp"
#include "msm/form/form.hpp"
#include "msm/solvers/pcg.hpp"

namespace vessel::msm {

enum class Integrator {
  explicit_euler,    ///< seed 000 eq. (3.7): x₁ = x₀ + h v₀, v₁ = v₀ + h a(x₀, v₀)
  symplectic_euler,  ///< v₁ = v₀ + h a(x₀, v₀), x₁ = x₀ + h v₁
  verlet,            ///< velocity Verlet
  implicit_euler,    ///< backward Euler linearised per step (Baraff & Witkin 1998), CHOLMOD
};
/// Every integrator, in declaration order (for sweeps over all of them).
inline constexpr std::array<Integrator, 4> kAllIntegrators{
    Integrator::explicit_euler, Integrator::symplectic_euler, Integrator::verlet,
    Integrator::implicit_euler};
Integrator parse_integrator(const std::string& name);
std::string to_string(Integrator integrator);

/// Implicit Euler's matrix A = M + h D + h² K (stiffness K, damping Jacobian D).
enum class ImplicitMatrix {
  current_state,     ///< "implicit-euler": K and D at the step's state, refactorised every step
  rest_prefactored,  ///< "implicit-euler-rest": K and D at rest, factorised once at set-up; each
                     ///< step assembles the right-hand side and does one solve (as simulators do)
  rest_pcg,  ///< "implicit-euler-rest-pcg": the same A at rest, assembled once, never factorised;
             ///< each step solves it by preconditioned conjugate gradients (pcg.hpp) started from
             ///< the previous step's Δv, to DynamicOptions::pcg's relative residual tolerance
  current_pcg,  ///< "implicit-euler-pcg": K and D at the step's state, as implicit-euler, assembled
                ///< every step and solved by the same warm-started PCG instead of a factorisation
                ///< (Vega FEM's implicit backward Euler with Jacobi-PCG does the same)
};
// rest_prefactored is not unconditionally stable: the part of the stiffness that K at rest lacks
// (K(x) − K(rest), e.g. the surface membrane's tension-borne transverse stiffness, zero at rest) is
// integrated explicitly. On the level-0 surface models it diverged at the default 10× critical
// step (step 7–10) but ran at 1 ms; on the volume model it ran at both.

struct DynamicOptions {
  Integrator integrator = Integrator::symplectic_euler;
  double dt = 1e-4;  ///< s
  int steps = 100;
  /// Divergence when the total energy exceeds |H₀| + blowup_factor·scale, scale the larger of
  /// |H₀| and ‖f_ext‖·(bounding-box diagonal) (an upper bound of the loads' work).
  double blowup_factor = 1e3;
  bool project_psd = true;  ///< implicit Euler: PSD-projected stiffness
  ImplicitMatrix implicit_matrix = ImplicitMatrix::current_state;  ///< implicit Euler
  PcgOptions pcg;  ///< implicit-euler-rest-pcg: tolerance, iteration limit, preconditioner
  /// Called after every step with (step, x, v); may be empty.
  std::function<void(int, const VectorXd&, const VectorXd&)> on_step;
};

struct DynamicResult {
  VectorXd x;
  VectorXd v;
  int steps = 0;
  double seconds = 0.0;        ///< the steps, s (set-up excluded)
  double setup_seconds = 0.0;  ///< before the first step, s (implicit-euler-rest: assembly and
                               ///< factorisation at rest)
  int numeric_factorisations = 0;  ///< CHOLMOD numeric factorisations (implicit Euler)
  double factor_entries = 0.0;     ///< implicit Euler: numbers stored in the Cholesky factor
  long linear_iterations = 0;      ///< implicit Euler by PCG: CG iterations over all steps
  int max_linear_iterations = 0;   ///< implicit Euler by PCG: most CG iterations in one step
  double energy = 0.0;  ///< total energy ½vᵀMv + Π(x) at the end, J
};

/// Total mechanical energy ½ vᵀ M v + Π(x), J.
double total_energy(const Problem& problem, const VectorXd& x, const VectorXd& v);

/// Integrates from (x0, v0) (rest and zero if empty). Throws InputError for dt ≤ 0 or steps < 0,
/// DivergenceError on blow-up (no result returned), std::runtime_error if implicit Euler's PCG
/// (implicit-euler-pcg, implicit-euler-rest-pcg) does not reach its tolerance within its iteration limit.
DynamicResult integrate(const Problem& problem, const DynamicOptions& options,
                        const VectorXd& x0 = VectorXd(), const VectorXd& v0 = VectorXd());

/// Upper bound of the highest angular frequency ω_max of the linearised undamped system at rest
/// (Gershgorin: ω² ≤ max_i Σ_j |K_ij| / m_i), rad/s; the critical step of symplectic Euler and
/// Verlet is 2/ω_max, so 2/bound is a safe step.
double max_frequency_bound(const Problem& problem);

struct RelaxationOptions {
  double tolerance = 1e-8;  ///< stop when ‖∇Π‖ ≤ tolerance·‖f_ext‖ on free dofs
  int max_steps = 2'000'000;
  double safety = 0.9;  ///< dt = safety·2/ω_max bound
};
struct RelaxationResult {
  VectorXd x;
  int steps = 0;
  double residual = 0.0;
  double dt = 0.0;
  double seconds = 0.0;
};
/// Dynamic relaxation: damped leapfrog (symplectic Euler) with Underwood's (1983) adaptive
/// mass-proportional damping c = 2ω₀ (ω₀ from the Rayleigh quotient of the current displacement)
/// at dt = safety·2/ω_max, until the residual tolerance. Throws std::runtime_error if it does not
/// get there, DivergenceError if it blows up.
RelaxationResult dynamic_relaxation(const Problem& problem, const RelaxationOptions& options = {});

}  // namespace vessel::msm
