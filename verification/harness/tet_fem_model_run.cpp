#include <Eigen/SVD>
#include <algorithm>
#include <exception>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/edge_pair_term.hpp"
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

/// The largest principal strain magnitude max |σ_i(F) − 1| over the tets (σ_i the singular values
/// of F: the principal stretches, so the measure ignores rotations and equals the linear principal
/// strain at small strain).
double max_principal_stretch_strain(const msm::TetTerm& term, const TetMesh& mesh,
                                    const Eigen::VectorXd& x) {
  double largest = 0.0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    std::array<Vec3, 4> corners;
    for (int c = 0; c < 4; ++c) corners[c] = x.segment<3>(3 * mesh.tets[e][c]);
    const msm::Mat3 F = msm::deformation_gradient(corners, term.rest_shapes()[e]);
    const Eigen::Vector3d s = Eigen::JacobiSVD<msm::Mat3>(F).singularValues();
    largest = std::max(largest, (s.array() - 1.0).abs().maxCoeff());
  }
  return largest;
}

/// XPBD FEM stepped from rest to its steady state, `repeats` times afresh: set-up (the solver's
/// construction) and the whole run's time (median), and the steps it took. runtime_error if the
/// run is not steady after spec.tet_fem.max_steps steps.
Eigen::VectorXd timed_xpbd(const msm::Problem& p, const msm::TetTerm& term, const ModelSpec& spec,
                           int repeats, ModelOutcome& out, long& steps) {
  std::vector<double> setups, runs;
  Eigen::VectorXd x;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    XpbdFemUpdater xpbd(p, term, spec.tet_fem);
    setups.push_back(xpbd.setup_seconds());
    const msm::UpdateResult r = xpbd.update(p.external_force);
    runs.push_back(r.seconds);
    steps = r.iterations;
    x = xpbd.state();
  }
  out.setup_seconds += median(setups);
  out.solve_seconds = median(runs);
  return x;
}

/// One load: the problem at `out.magnitude`, solved (timed) and compared with `ref_here`.
void run_tet_fem_load(const Scene& s, const ModelSpec& spec, const msm::TetTerm& term,
                      const TetMesh& mesh, const ReferenceAtPoints& ref_here, const ReadOut& at,
                      double ref_strain_unit, const Vec3& qoi_point, const HarnessOptions& o,
                      ModelOutcome& out) {
  const double mag = out.magnitude;
  const msm::Problem p = tet_mesh_problem(s, term, mesh, mag);
  out.unknowns = free_unknowns(p);
  const MemoryProbe solve_memory;
  Eigen::VectorXd x;
  long steps = 0;
  double dt = 0.0;
  if (spec.kind == ModelKind::corotational_fem) {
    // Static Newton with the consistent tangent, warm-started along the load ramp as a simulator
    // updates (msm/solvers/updates.hpp).
    UpdateSequence seq = timed_updates(p, msm::parse_solver("static"), o.ramp_updates, o.repeats);
    out.setup_seconds += seq.setup_seconds;
    out.solve_seconds = seq.update_seconds;
    out.updates = seq.updates;
    out.iterations_per_update = seq.iterations_per_update;
    out.factorisations_per_update = seq.factorisations_per_update;
    x = std::move(seq.x);
  } else {
    x = timed_xpbd(p, term, spec, o.repeats, out, steps);
    dt = spec.tet_fem.dt;
    out.detail += ", steady after " + std::to_string(steps) + " steps";
  }
  out.memory_mib = std::max(out.memory_mib, solve_memory.added_mib());
  out.max_strain = max_principal_stretch_strain(term, mesh, x);
  const std::vector<Vec3> u = displacements(x, mesh.nodes);
  std::vector<Vec3> loads;
  if (s.load.kind == LoadKind::contact) loads = per_node(p.external_force);
  finish_outcome(out, s, mesh.nodes, u, ref_here, mag, at, ref_strain_unit, qoi_point, loads, steps,
                 dt);
  if (wants_fields(o, s, mag, ref_strain_unit)) {
    write_model_fields(o, s, out, mesh.nodes, tet_cells(mesh.tets), u, scaled(ref_here.u, mag));
  }
}

}  // namespace

std::string tet_fem_detail(const ModelSpec& spec) {
  if (spec.kind == ModelKind::corotational_fem) {
    return "corotational P1 (Müller & Gross 2004), static Newton, consistent tangent";
  }
  const TetFemSpec& t = spec.tet_fem;
  std::ostringstream d;
  d << "XPBD stable neo-Hookean P1 (Macklin & Müller 2021), dt = " << t.dt << " s, " << t.iterations
    << " sweeps/step, to steady state";
  return d.str();
}

void run_tet_fem_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                       const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                       const HarnessOptions& o, Progress& progress, ModelOutcome base,
                       SceneResult& result) {
  const auto record_failure = [&](const std::string& why) {
    for (const double mag : s.load.magnitudes) {
      ModelOutcome out = base;
      out.magnitude = mag;
      out.failure = why;
      result.outcomes.push_back(out);
    }
    if (o.log) *o.log << "      FAILED: " << why << "\n";
  };
  if (std::string why = model_refusal(spec, s.youngs_modulus, nu); !why.empty()) {
    record_failure(why);
    return;
  }
  const MemoryProbe setup_memory;
  Stopwatch setup;
  std::unique_ptr<msm::TetTerm> term;
  try {
    term = tet_fem_term(spec, mesh, s.youngs_modulus, nu);
  } catch (const std::exception& e) {
    record_failure(e.what());
    return;
  }
  base.setup_seconds = setup.seconds();
  base.memory_mib = setup_memory.added_mib();
  base.detail = tet_fem_detail(spec);
  base.nodes = mesh.nodes.size();
  if (s.modes.count > 0) {  // at rest both energies' Hessians are linear P1's stiffness
    const msm::Problem at_rest = tet_mesh_problem(s, *term, mesh, 0.0);
    result.model_modes.push_back(msm_model_modes(at_rest, base, s.modes.count));
  }
  const ReferenceAtPoints ref_here = reference_at(ref, mesh.nodes);
  const ReadOut at = read_out(s, base.level, mesh.nodes, result.qoi_point);
  for (const double mag : s.load.magnitudes) {
    progress.begin(spec.name + " at " + std::to_string(mag) + " (" + to_string(s.load.kind) + ")");
    ModelOutcome out = base;
    out.magnitude = mag;
    try {
      const JudgingReference judge = judging_reference(ref, s, ref_here, mesh.nodes,
                                                       fine.max_abs_principal_strain, mag);
      if (judge.finite_strain) out.reference = "finite-strain";
      run_tet_fem_load(s, spec, *term, mesh, judge.at_points, at, judge.strain_unit,
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
