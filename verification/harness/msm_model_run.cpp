#include <algorithm>
#include <exception>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <variant>

#include "meshes/foundation/errors.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/formats/network_file.hpp"
#include "msm/model/roi.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/updates.hpp"
#include "verification/harness/memory.hpp"
#include "verification/harness/modal.hpp"
#include "verification/harness/model_readout.hpp"
#include "verification/harness/model_runs.hpp"
#include "verification/harness/timed_updates.hpp"
#include "verification/harness/timing.hpp"
#include "verification/model_capabilities.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

namespace {

/// What is solved for one load: the whole network, or its region of interest (the nodes beyond R
/// held and their unknowns removed: verification/roi).
struct SolvedSystem {
  const msm::Problem* problem = nullptr;
  const msm::MassSpringModel* model = nullptr;
  const msm::SpringNetwork* network = nullptr;
  Eigen::Index qoi = -1;  ///< the QoI node in the solved problem (−1 if the region holds it)
  std::unique_ptr<msm::RoiNetwork> roi;
  std::unique_ptr<msm::MassSpringModel> roi_model;
  std::unique_ptr<msm::Problem> roi_problem;

  /// Positions of the whole network from the solved ones (held nodes at rest).
  [[nodiscard]] Eigen::VectorXd to_full(const Eigen::VectorXd& x, const msm::Problem& full) const {
    if (!roi) return x;
    Eigen::VectorXd x_full = full.rest;
    for (std::size_t k = 0; k < roi->full_index.size(); ++k) {
      x_full.segment<3>(3 * static_cast<Eigen::Index>(roi->full_index[k])) =
          x.segment<3>(3 * static_cast<Eigen::Index>(k));
    }
    return x_full;
  }
};

SolvedSystem solved_system(const msm::Problem& full, const msm::MassSpringModel& model,
                           const msm::BuiltNetwork& built, const ModelSpec& spec,
                           const Vec3& qoi_point, std::size_t qoi) {
  const msm::SpringNetwork& network = built.network;
  SolvedSystem sys{&full, &model, &network, static_cast<Eigen::Index>(qoi), {}, {}, {}};
  if (spec.roi_radius <= 0.0) return sys;
  const std::vector<char> held = msm::held_nodes(full, qoi_point, spec.roi_radius);
  sys.roi = std::make_unique<msm::RoiNetwork>(
      msm::restrict_network(network, held, built.terms.bending_rigidity.has_value()));
  sys.roi_model =
      msm::make_model(sys.roi->network, built.terms, spec.damping);
  sys.roi_problem =
      std::make_unique<msm::Problem>(msm::restrict_problem(full, *sys.roi, held, *sys.roi_model));
  sys.problem = sys.roi_problem.get();
  sys.model = sys.roi_model.get();
  sys.network = &sys.roi->network;
  const auto& index = sys.roi->full_index;
  const auto it = std::find(index.begin(), index.end(), static_cast<int>(qoi));
  sys.qoi = it == index.end() ? -1 : it - index.begin();
  return sys;
}

/// Solves `repeats` times (median time into out.solve_seconds, a solver's own set-up such as
/// implicit-euler-rest's factorisation added to out.setup_seconds); a dynamic solver's QoI
/// history (kHistorySamples samples) goes into out.history. Returns the solved positions.
Eigen::VectorXd timed_solve(const SolvedSystem& sys, const ModelSpec& spec, const Vec3& qoi_rest,
                            int repeats, ModelOutcome& out) {
  std::vector<double> times, setups;
  Eigen::VectorXd x;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    msm::StepObserver on_step;
    if (spec.solver.is_dynamic()) {
      out.history = {};
      out.history.time_s.push_back(0.0);  // at rest
      out.history.model_mm.push_back(0.0);
      const long every = std::max(1L, spec.solver.steps / kHistorySamples);
      on_step = [&](int step, const Eigen::VectorXd& xs) {
        if (step % every != 0 && step != spec.solver.steps) return;
        out.history.time_s.push_back(step * spec.solver.dt);
        out.history.model_mm.push_back(
            sys.qoi < 0 ? 0.0 : (xs.segment<3>(3 * sys.qoi) - qoi_rest).norm() * 1e3);
      };
    }
    Stopwatch solve;
    msm::SolveResult r = msm::solve(*sys.problem, spec.solver, sys.network, on_step);
    const double wall = solve.seconds();
    // SolveResult::seconds excludes a solver's own set-up (implicit-euler-rest): count it there.
    const auto* dyn = std::get_if<msm::DynamicResult>(&r.detail);
    const double setup = dyn ? dyn->setup_seconds : 0.0;
    times.push_back(wall - setup);
    setups.push_back(setup);
    x = std::move(r.x);
  }
  out.solve_seconds = median(times);
  out.setup_seconds += median(setups);
  return x;
}

/// A mass-spring model's description in results: topology, rules, solver, region.
std::string msm_detail(const std::string& topology, const ModelSpec& spec) {
  std::ostringstream d;
  if (spec.kind == ModelKind::network) {  // its springs and masses are the file's own
    d << topology << ", " << msm::to_string(spec.solver);
  } else if (spec.edge_pairs) {  // no springs, so no stiffness rule
    d << topology << ", " << msm::to_string(spec.mass) << " masses, "
      << msm::to_string(spec.solver);
  } else {
    d << topology << ", " << msm::to_string(spec.stiffness) << " stiffness, "
      << msm::to_string(spec.mass) << " masses, " << msm::to_string(spec.solver);
  }
  if (spec.roi_radius > 0.0) d << ", region of interest R = " << spec.roi_radius * 1e3 << " mm";
  if (!spec.calibration.empty()) d << ", calibrated (" << spec.calibration.filename().string() << ")";
  return d.str();
}

/// One load of a mass-spring model: build its problem, solve (timed), compare.
void run_msm_load(const Scene& s, const ModelSpec& spec, const msm::BuiltNetwork& built,
                  const msm::MassSpringModel& model, const TetMesh& mesh, const ReferenceSolvers& ref,
                  const ReferenceAtPoints& ref_here, const ReadOut& at, double ref_strain_unit,
                  const Vec3& qoi_point, const HarnessOptions& o, ModelOutcome& out) {
  const std::vector<Vec3>& nodes = built.network.nodes;
  const double mag = out.magnitude;
  const msm::Problem full = msm_problem(s, model, built, mesh, mag);
  const SolvedSystem sys = solved_system(full, model, built, spec, qoi_point, at.qoi);
  out.unknowns = free_unknowns(*sys.problem);
  const MemoryProbe solve_memory;
  Eigen::VectorXd x_solved;
  if (msm::supports_updates(spec.solver)) {
    UpdateSequence seq = timed_updates(*sys.problem, spec.solver, o.ramp_updates, o.repeats);
    out.setup_seconds += seq.setup_seconds;
    out.solve_seconds = seq.update_seconds;
    out.updates = seq.updates;
    out.iterations_per_update = seq.iterations_per_update;
    out.factorisations_per_update = seq.factorisations_per_update;
    x_solved = std::move(seq.x);
  } else {
    x_solved = timed_solve(sys, spec, nodes[at.qoi], o.repeats, out);
  }
  out.memory_mib = std::max(out.memory_mib, solve_memory.added_mib());
  // The FEM transient beside the history (computed once per scene and ν, then cached) costs the
  // reference's time and memory, not the model's: outside the measurements above.
  if (!out.history.time_s.empty()) {
    add_reference_history(out.history, ref, nodes[at.qoi], spec, *sys.problem, mag);
  }
  out.max_strain = sys.model->max_strain(x_solved);
  const std::vector<Vec3> u = displacements(sys.to_full(x_solved, full), nodes);
  std::vector<Vec3> loads;
  if (s.load.kind == LoadKind::contact) loads = per_node(full.external_force);
  finish_outcome(out, s, nodes, u, ref_here, mag, at, ref_strain_unit, qoi_point, loads,
                 spec.solver.steps, spec.solver.dt);
  if (wants_fields(o, s, mag, ref_strain_unit)) {
    write_model_fields(o, s, out, nodes, network_cells(built.network), u, scaled(ref_here.u, mag));
  }
}

/// The model's outcome at every load recorded as failed with `why`: a ν the model refuses, or a
/// network that could not be built (a calibration file gone bad since the scene was read, a
/// homogenised rule below its mesh's floor), as P1 is at ν = 0.5: the other models still run.
void record_failure(const Scene& s, const ModelOutcome& base, const std::string& why,
                    SceneResult& result) {
  for (const double mag : s.load.magnitudes) {
    ModelOutcome out = base;
    out.magnitude = mag;
    out.failure = why;
    result.outcomes.push_back(out);
  }
}

}  // namespace

void run_msm_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                   const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                   const HarnessOptions& o, Progress& progress, ModelOutcome base,
                   SceneResult& result) {
  // A ν the model refuses is recorded as failed, as P1 is at ν = 0.5, not fatal to the run.
  const MemoryProbe setup_memory;
  Stopwatch setup;  // the homogenised rule's fit is part of the set-up
  VesselParams vessel = s.vessel;
  vessel.level = base.level;
  if (std::string why = model_refusal(spec, s.youngs_modulus, nu); !why.empty()) {
    record_failure(s, base, why, result);
    return;
  }
  std::optional<msm::BuiltNetwork> built_or;
  try {
    built_or.emplace(scene_network(s, spec, mesh, vessel, nu));
  } catch (const std::exception& e) {
    record_failure(s, base, e.what(), result);
    if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
    return;
  }
  const msm::BuiltNetwork& built = *built_or;
  if (spec.kind == ModelKind::network) {
    // The reference is read at the network's rest positions: every node must lie in its mesh
    // (within the evaluation's own tolerance), else the run stops naming them.
    msm::require_nodes_inside(built.network.nodes, *ref.fine_mesh, kOutsideTolerance,
                              s.source.string() + ": model " + spec.name + ": " + built.file);
  }
  const auto model_ptr = msm::make_model(built, spec.damping);
  const msm::MassSpringModel& model = *model_ptr;
  base.setup_seconds = setup.seconds();
  base.memory_mib = setup_memory.added_mib();
  base.detail = msm_detail(built.topology, spec);
  base.roi_radius = spec.roi_radius;
  base.nodes = built.network.nodes.size();
  if (s.modes.count > 0) {
    // Natural frequencies (scene's [modes]) of the whole model with the scene's supports (a
    // region of interest is a solve-time restriction, not another vessel), outside the timings.
    const msm::Problem at_rest = msm_problem(s, model, built, mesh, 0.0);
    result.model_modes.push_back(msm_model_modes(at_rest, base, s.modes.count));
  }
  const ReferenceAtPoints ref_here = reference_at(ref, built.network.nodes);
  const ReadOut at = read_out(s, base.level, built.network.nodes, result.qoi_point);
  for (const double mag : s.load.magnitudes) {
    progress.begin(spec.name + " at " + std::to_string(mag) + " (" + to_string(s.load.kind) + ")");
    ModelOutcome out = base;
    out.magnitude = mag;
    try {
      const JudgingReference judge = judging_reference(ref, s, ref_here, built.network.nodes,
                                                       fine.max_abs_principal_strain, mag);
      if (judge.finite_strain) out.reference = "finite-strain";
      run_msm_load(s, spec, built, model, mesh, ref, judge.at_points, at, judge.strain_unit,
                   result.qoi_point, o, out);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      out.ok = false;
      out.failure = e.what();
      if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
    }
    result.outcomes.push_back(out);
    progress.end();
  }
}

}  // namespace vessel
