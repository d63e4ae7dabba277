#pragma once
/// A model run as a simulator runs it: prepare once (assembly, symbolic and numeric
/// factorisation), then update many times, each update taking the new external load and
/// returning the new state from the previous one. The harness times the two apart (set-up, and
/// the steady-state time per update); `msm::solve` (solve.hpp) stays the one-shot cold solve.
///
/// - "linear": K at rest factorised once (CHOLMOD); each update one solve, x = x0 + K⁻¹f, or,
///   for a load on the dofs the prepared problem's own load acts on (a contact patch), the
///   superposition of the responses to those dofs' unit loads, solved for at set-up (where their
///   number × the dofs does not exceed the factor's entries).
/// - "static": modified Newton warm-started from the previous update's state. Each update first
///   iterates with the factorisation it already holds (K at rest after prepare, later the last one
///   Newton made) while the residual falls by at least `contraction` per iteration; where it does
///   not, it refactorises once with the exact Hessian at the state reached and goes on (the
///   Shamanskii variant; skipped for good once that Hessian was indefinite, as on a wrinkling
///   membrane); where that fails too (indefinite, or still not contracting), full
///   Newton (solve_static) takes over from the state reached. The stopping test is
///   solve_static's, so an update ends at the solver's tolerance either way.
///
/// Another solver with a prefactored matrix (e.g. a local–global solver) plugs in as one more
/// Updater made by prepare_updates from its SolverSpec.
#include <memory>

#include "msm/form/form.hpp"
#include "msm/solvers/solve.hpp"

namespace vessel::msm {

/// What one update did.
struct UpdateResult {
  double seconds = 0.0;    ///< wall-clock time of the update, s
  int iterations = 0;      ///< Newton iterations (modified and full); 1 for the linear model
  int reused_iterations = 0;  ///< of those, modified-Newton ones with the factorisation held
                              ///< from before the update (none made during it)
  int factorisations = 0;  ///< CHOLMOD numeric factorisations made during the update
  /// ‖∇Π‖ on the free dofs at the end, N (static Newton; 0 where the update does not compute it,
  /// the linear model's solve being exact to round-off)
  double residual = 0.0;
  /// linear: the update superposed the responses precomputed at set-up for the dofs its load
  /// acts on, instead of a solve (LinearUpdater, updates.cpp)
  bool superposed = false;
};

/// Settings of the updates (static Newton's own settings come from SolverSpec::static_options).
struct UpdateOptions {
  /// Modified Newton keeps the factorisation while ‖∇Π‖ falls at least by this factor per
  /// iteration; a slower fall (or a rise) hands over to full Newton. 0.5: a refactorisation costs
  /// tens of solves at the sizes here, so a linear rate of 1/2 is still the cheaper path.
  double contraction = 0.5;
  int max_reused_iterations = 50;  ///< modified-Newton iterations per update at most
};

class Updater {
 public:
  virtual ~Updater() = default;
  Updater(const Updater&) = delete;
  Updater& operator=(const Updater&) = delete;

  /// Applies the nodal load `external_force` (N, per dof; entries on fixed dofs ignored) and
  /// advances the state to the model's answer for it. Throws InputError for a vector of the wrong
  /// size, std::runtime_error where the solver fails (as solve_static does).
  virtual UpdateResult update(const VectorXd& external_force) = 0;
  /// The state after the last update (rest positions before the first), m.
  [[nodiscard]] const VectorXd& state() const { return x_; }
  /// Set-up: assembly and factorisation at rest, s.
  [[nodiscard]] double setup_seconds() const { return setup_seconds_; }
  /// CHOLMOD numeric factorisations so far, set-up included.
  [[nodiscard]] virtual int factorisations() const = 0;

 protected:
  Updater() = default;
  VectorXd x_;
  double setup_seconds_ = 0.0;
};

/// Whether prepare_updates supports the solver: "static" and "linear". Dynamic solvers are run
/// step by step (their time per update is the time per step × the steps one update period
/// needs; verification/harness/budget.hpp's time_per_update); dynamic relaxation has no prepared form.
[[nodiscard]] bool supports_updates(const SolverSpec& spec);

/// Prepares the updates of `problem` with the solver of `spec`. Each update brings its own load;
/// the problem's external_force only says which dofs loads will act on ("linear" precomputes
/// the responses to them; a zero external_force precomputes none). The problem's form must outlive the updater. InputError naming the
/// solver if supports_updates(spec) is false.
std::unique_ptr<Updater> prepare_updates(const Problem& problem, const SolverSpec& spec,
                                         const UpdateOptions& options = {});

}  // namespace vessel::msm
