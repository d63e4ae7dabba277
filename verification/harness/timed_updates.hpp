#pragma once
/// Static and linear models timed as a simulator runs them (msm/solvers/updates.hpp): prepared
/// once, then warm-started updates of a load ramp; linear FEM by the same procedure.
#include <Eigen/Core>
#include <memory>

#include "msm/fem/tet_term.hpp"
#include "msm/fem/xpbd_fem.hpp"
#include "msm/form/form.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/updates.hpp"
#include "verification/scene.hpp"

namespace vessel::fem {
class ElasticitySolver;
}

namespace vessel {

/// A static or linear mass-spring model timed as a simulator runs it (msm/solvers/updates.hpp):
/// prepared once, then `updates` updates whose loads ramp to the problem's external_force
/// (f·k/updates, k = 1 … updates), each from the previous state. `repeats` times afresh.
struct UpdateSequence {
  Eigen::VectorXd x;            ///< the last update's state, at the full load, m
  double setup_seconds = 0.0;   ///< msm::prepare_updates, median over the repeats, s
  double update_seconds = 0.0;  ///< median over every update of every repeat, s
  int updates = 0;
  double iterations_per_update = 0.0;      ///< mean over the last repeat
  double factorisations_per_update = 0.0;  ///< mean over the last repeat (set-up excluded)
};
/// InputError if the solver has no prepared updates (msm::supports_updates) or updates < 1.
UpdateSequence timed_updates(const msm::Problem& problem, const msm::SolverSpec& solver,
                             int updates, int repeats);

/// Linear FEM timed by the procedure that times the mass-spring models (timed_updates with the
/// "linear" updater): its system on the free DoFs as a Form (msm::QuadraticForm), factorised once
/// at set-up (with, for a load on few DoFs such as a contact patch, the responses to them: Cotin
/// et al. 1999's precomputation, as for the springs' linear models), then each update of the
/// load ramp.
struct FemUpdates {
  double setup_seconds = 0.0;   ///< assembly of K and f, factorisation and responses, s
  double update_seconds = 0.0;  ///< median update, s
};
FemUpdates timed_fem_updates(const fem::ElasticitySolver& solver, int updates, int repeats);

/// XPBD FEM (msm/fem/xpbd_fem.hpp) run as a simulator runs it: prepared once (the constraints'
/// compliances and the rest shape's multipliers; setup_seconds), then each update steps from the
/// state it holds under the new load until steady (spec.settle_relative_change,
/// XpbdFem::relax), its UpdateResult::iterations the steps taken. `energy`: the stable
/// neo-Hookean term of the problem's mesh (tet_fem_term), whose tets and Lamé parameters the
/// constraints carry. An update not steady after spec.max_steps steps throws
/// std::runtime_error naming the keys.
class XpbdFemUpdater final : public msm::Updater {
 public:
  XpbdFemUpdater(const msm::Problem& problem, const msm::TetTerm& energy, const TetFemSpec& spec);
  msm::UpdateResult update(const Eigen::VectorXd& external_force) override;
  [[nodiscard]] int factorisations() const override { return 0; }

 private:
  TetFemSpec spec_;
  std::unique_ptr<msm::XpbdFem> xpbd_;
};

}  // namespace vessel
