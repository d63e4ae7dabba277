#include "verification/harness/modal.hpp"

#include "msm/dynamics/natural_frequencies.hpp"
#include "verification/scene_problems.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

int modal_reference_level(const Scene& s) {
  return s.modes.reference_level >= 0 ? s.modes.reference_level : s.reference_level;
}

ModalOutcome reference_modes(const Scene& s, double nu, const TetMesh& mesh, int level) {
  ModalOutcome out;
  out.model = "reference";
  out.kind = "fem";
  out.poisson_ratio = nu;
  out.level = level;
  out.detail = "P2, displacement formulation, consistent mass";
  try {
    Stopwatch clock;
    fem::ElasticityProblem problem = fem_problem(s, mesh, nu, 2);
    problem.options.formulation = fem::Formulation::displacement;
    const fem::ElasticitySolver solver(mesh, problem);
    const fem::ModalResult r = solver.modes(s.modes.count);
    out.frequencies_hz = r.frequencies_hz;
    out.dofs = r.n_dofs;
    out.seconds = clock.seconds();  // set-up included: it is done for the modes alone
    out.ok = true;
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

ModalOutcome fem_model_modes(const fem::ElasticitySolver& solver, const ModelOutcome& base,
                             int count) {
  ModalOutcome out;
  out.model = base.model;
  out.kind = base.kind;
  out.poisson_ratio = base.poisson_ratio;
  out.level = base.level;
  out.detail = base.detail + ", consistent mass";
  try {
    const fem::ModalResult r = solver.modes(count);
    out.frequencies_hz = r.frequencies_hz;
    out.dofs = r.n_dofs;
    out.seconds = r.seconds;
    out.ok = true;
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

ModalOutcome msm_model_modes(const msm::Problem& problem, const ModelOutcome& base, int count) {
  ModalOutcome out;
  out.model = base.model;
  out.kind = base.kind;
  out.poisson_ratio = base.poisson_ratio;
  out.level = base.level;
  out.detail = base.detail + "; K at rest, lumped masses";
  try {
    msm::NaturalFrequencyOptions o;
    o.count = count;
    const msm::NaturalFrequencies f = msm::natural_frequencies(problem, o);
    out.frequencies_hz = f.frequencies_hz;
    out.mechanisms = f.mechanisms;
    out.dofs = static_cast<std::size_t>(f.free_dofs);
    out.seconds = f.seconds;
    out.ok = true;
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

}  // namespace vessel
