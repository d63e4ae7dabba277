#pragma once
/// One entry for every mass-spring solver: static Newton, the linearised model, dynamic
/// relaxation, the time integrators and seed 002's position-based dynamics (XPBD). A SolverSpec
/// says which and with what settings; `solve` runs it on a Problem. The command line, the scenes
/// and the studies name solvers with the strings of `kSolverNames`.
#include <array>
#include <functional>
#include <string>
#include <variant>

#include "msm/form/form.hpp"
#include "msm/pbd/constraints.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

enum class SolverKind {
  static_newton,  ///< "static": Newton on the total potential
  linear,         ///< "linear": the stiffness at rest, one solve
  relaxation,     ///< "relaxation": dynamic relaxation to equilibrium
  integrator,     ///< a time integrator (explicit/symplectic Euler, Verlet, implicit Euler)
  pbd,            ///< "pbd": seed 002's constraints with XPBD (surface models)
  local_global,   ///< "local-global": Liu et al. 2013's local–global iterations to equilibrium
  local_global_euler,  ///< "local-global-euler": implicit Euler, a fixed number of local–global
                       ///< iterations per step (Liu et al. 2013), one prefactored matrix
};

/// Seed 002's position-based model: constraint families and XPBD settings.
struct PbdSettings {
  int iterations = 10;              ///< Gauss–Seidel sweeps per step
  double velocity_damping = 0.01;   ///< fraction of the velocity removed per step, [0, 1)
  double bending_compliance = 0.0;  ///< 1/(N·m), dihedral and angle constraints
  bool dihedral = true;             ///< bending by the dihedral angle
  bool angle = false;               ///< the seed's simplified angle constraint
};

/// Liu et al. 2013's local–global solver (local_global.hpp).
struct LocalGlobalSettings {
  int iterations = 10;  ///< local-global-euler: local–global iterations per step (>= 1)
  int max_iterations = 100'000;  ///< local-global (statics): iterations before giving up
};

struct SolverSpec {
  SolverKind kind = SolverKind::static_newton;
  Integrator integrator = Integrator::symplectic_euler;  ///< kind integrator
  /// Integrator implicit_euler: "implicit-euler" (current_state), "implicit-euler-pcg",
  /// "implicit-euler-rest" or "implicit-euler-rest-pcg".
  ImplicitMatrix implicit_matrix = ImplicitMatrix::current_state;
  PcgOptions pcg;  ///< implicit-euler-pcg, implicit-euler-rest-pcg
  double dt = 0.0;  ///< s, integrator and pbd; 0: automatic (resolved_time_step)
  long steps = 0;   ///< integrator and pbd: number of steps (> 0)
  StaticOptions static_options;  ///< static_newton
  PbdSettings pbd;               ///< pbd
  LocalGlobalSettings local_global;  ///< local_global, local_global_euler

  /// Time-stepping solvers (integrators and PBD): compared over time and at their final state.
  [[nodiscard]] bool is_dynamic() const {
    return kind == SolverKind::integrator || kind == SolverKind::pbd ||
           kind == SolverKind::local_global_euler;
  }
};

/// Every solver name: the static ones, then the integrators, then PBD, then Liu et al. 2013's
/// local–global solvers (statics and implicit Euler). "implicit-euler-rest" is implicit Euler with
/// the matrix at rest, factorised once (ImplicitMatrix::rest_prefactored); "implicit-euler-rest-pcg"
/// the same step solved by warm-started preconditioned CG (ImplicitMatrix::rest_pcg);
/// "implicit-euler-pcg" implicit Euler's step at the current state solved by that CG
/// (ImplicitMatrix::current_pcg).
inline constexpr std::array<const char*, 13> kSolverNames{
    "static",         "linear",         "relaxation",          "explicit-euler", "symplectic-euler",
    "verlet",         "implicit-euler", "implicit-euler-pcg",  "implicit-euler-rest",
    "implicit-euler-rest-pcg",          "pbd",                 "local-global",
    "local-global-euler"};
/// The solver of a name in kSolverNames (dt, steps and options left at their defaults).
/// InputError listing the names otherwise.
SolverSpec parse_solver(const std::string& name);
/// The name parse_solver reads.
std::string to_string(const SolverSpec& spec);

/// Fraction of the critical-step bound an explicit integrator runs at by default.
inline constexpr double kExplicitStepFraction = 0.5;
/// Multiple of the undamped critical-step bound implicit Euler (Newton or local–global) runs at
/// by default: stable at any step; 10× keeps its numerical damping moderate.
inline constexpr double kImplicitStepMultiple = 10.0;

/// The time step a dynamic solver runs with, s: spec.dt if set; otherwise
/// - explicit integrators: kExplicitStepFraction × the critical-step bound, which is the undamped
///   bound 2/ω_max (Gershgorin, max_frequency_bound) or, for a damped model (non-zero damping
///   Jacobian at rest), the smaller of it and the guaranteed damped step
///   (guaranteed_critical_step, critical_step.hpp: explicit and symplectic Euler; with the lowest
///   mode taken as ω = 0, a wider and still proven rectangle). Velocity Verlet has no proven
///   damped bound and keeps the undamped one; where the guaranteed step is 0 (explicit Euler with
///   an undamped dof: unstable at every step) the undamped one is kept too;
/// - implicit Euler and local-global-euler: kImplicitStepMultiple × 2/ω_max (Gershgorin);
/// - PBD: 1 ms (seed 002's frame time).
double resolved_time_step(const Problem& problem, const SolverSpec& spec);

/// What a solve did, by solver family (StaticResult for static and linear).
using SolveDetail = std::variant<StaticResult, RelaxationResult, DynamicResult, PbdResult>;

struct SolveResult {
  VectorXd x;            ///< final positions, m
  double seconds = 0.0;  ///< the solver's own time (after set-up, for implicit-euler-rest)
  double dt = 0.0;       ///< s, dynamic solvers: the step used
  SolveDetail detail;
};

/// Called after every step of a dynamic solver with (step, x).
using StepObserver = std::function<void(int, const VectorXd&)>;

/// Runs the solver on the problem. `network` is needed by PBD (its constraints are built on the
/// surface network's springs and triangles; InputError if null or not a surface network); the
/// other solvers work on problem.form alone. Errors as the solvers throw them: InputError for bad
/// settings, DivergenceError for a blow-up, std::runtime_error for no convergence.
SolveResult solve(const Problem& problem, const SolverSpec& spec,
                  const SpringNetwork* network = nullptr, const StepObserver& on_step = {});

}  // namespace vessel::msm
