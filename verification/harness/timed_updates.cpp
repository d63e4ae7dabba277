#include "verification/harness/timed_updates.hpp"

#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fem_reference/elasticity.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/form/quadratic_form.hpp"
#include "msm/solvers/updates.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

UpdateSequence timed_updates(const msm::Problem& problem, const msm::SolverSpec& solver,
                             int updates, int repeats) {
  if (!msm::supports_updates(solver)) {
    throw InputError("solver " + msm::to_string(solver) +
                     ": the harness times prepared updates of static and linear solvers only");
  }
  if (updates < 1) {
    throw InputError("updates: expected a load ramp of >= 1 updates, got " +
                     std::to_string(updates));
  }
  UpdateSequence seq;
  seq.updates = updates;
  std::vector<double> setups, times;
  for (int rep = 0; rep < std::max(1, repeats); ++rep) {
    const std::unique_ptr<msm::Updater> up = msm::prepare_updates(problem, solver);
    setups.push_back(up->setup_seconds());
    int iterations = 0, factorisations = 0;
    for (int k = 1; k <= updates; ++k) {
      const Eigen::VectorXd f =
          problem.external_force * (static_cast<double>(k) / static_cast<double>(updates));
      const msm::UpdateResult r = up->update(f);
      times.push_back(r.seconds);
      iterations += r.iterations;
      factorisations += r.factorisations;
    }
    seq.iterations_per_update = static_cast<double>(iterations) / updates;
    seq.factorisations_per_update = static_cast<double>(factorisations) / updates;
    seq.x = up->state();
  }
  seq.setup_seconds = median(setups);
  seq.update_seconds = median(times);
  return seq;
}

FemUpdates timed_fem_updates(const fem::ElasticitySolver& solver, int updates, int repeats) {
  Stopwatch assembly;
  fem::FreeDisplacementSystem sys = solver.free_displacement_system();
  const auto n = sys.f.size();
  const msm::QuadraticForm form(std::move(sys.K), Eigen::VectorXd::Zero(n));
  msm::Problem p;
  p.form = &form;
  p.rest = Eigen::VectorXd::Zero(n);  // the state is the displacement on the free DoFs
  p.external_force = std::move(sys.f);
  p.mass = Eigen::VectorXd::Ones(n);  // unused by a static answer
  p.fixed.assign(static_cast<std::size_t>(n), 0);
  const double assembly_seconds = assembly.seconds();
  const UpdateSequence seq = timed_updates(p, msm::parse_solver("linear"), updates, repeats);
  return {assembly_seconds + seq.setup_seconds, seq.update_seconds};
}

XpbdFemUpdater::XpbdFemUpdater(const msm::Problem& problem, const msm::TetTerm& energy,
                               const TetFemSpec& spec)
    : spec_(spec) {
  const Stopwatch setup;
  std::vector<Vec3> nodes(static_cast<std::size_t>(problem.rest.size() / 3));
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    nodes[i] = problem.rest.segment<3>(3 * static_cast<Eigen::Index>(i));
  }
  msm::XpbdFemOptions xo;
  xo.iterations = spec.iterations;
  xo.damping = spec.velocity_damping;
  xpbd_ = std::make_unique<msm::XpbdFem>(nodes, energy.elements(), energy.lame(), problem.mass,
                                         problem.fixed, xo);
  x_ = xpbd_->state();
  setup_seconds_ = setup.seconds();
}

msm::UpdateResult XpbdFemUpdater::update(const Eigen::VectorXd& external_force) {
  if (external_force.size() != x_.size()) {
    throw InputError("XPBD FEM update: expected " + std::to_string(x_.size()) +
                     " load entries, got " + std::to_string(external_force.size()));
  }
  const Stopwatch run;
  const int steps = xpbd_->relax(spec_.dt, external_force, spec_.settle_relative_change,
                                 static_cast<int>(spec_.max_steps));
  msm::UpdateResult r;
  r.seconds = run.seconds();
  r.iterations = steps;
  x_ = xpbd_->state();
  if (steps >= spec_.max_steps) {
    std::ostringstream why;
    why << "xpbd_fem: not steady after max_steps = " << spec_.max_steps << " steps of dt = "
        << spec_.dt << " s (a node still moves farther in a step than settle_relative_change = "
        << spec_.settle_relative_change << " of the largest displacement)";
    throw std::runtime_error(why.str());
  }
  return r;
}

}  // namespace vessel
