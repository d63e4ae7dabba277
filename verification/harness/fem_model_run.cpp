#include <algorithm>
#include <exception>

#include "meshes/surface_loads.hpp"
#include "verification/harness/memory.hpp"
#include "verification/harness/modal.hpp"
#include "verification/harness/model_readout.hpp"
#include "verification/harness/model_runs.hpp"
#include "verification/harness/timed_updates.hpp"
#include "verification/harness/timing.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

void run_fem_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                   const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                   const HarnessOptions& o, ModelOutcome base, SceneResult& result) {
  try {
    const MemoryProbe memory;
    Stopwatch setup;
    fem::ElasticityProblem problem = fem_problem(s, mesh, nu, spec.degree);
    problem.options.formulation = fem::Formulation::displacement;
    fem::ElasticitySolver solver(mesh, problem);
    const double construction = setup.seconds();
    const int updates = std::max(1, o.ramp_updates);
    const FemUpdates timed = timed_fem_updates(solver, updates, std::max(1, o.repeats));
    base.setup_seconds = construction + timed.setup_seconds;
    base.solve_seconds = timed.update_seconds;
    base.updates = updates;
    const fem::ElasticityResult r = solver.solve();  // the answer: the reference code's own solve
    base.memory_mib = memory.added_mib();
    base.detail = r.element + ", " + fem::to_string(r.solver);
    base.nodes = mesh.nodes.size();
    base.unknowns = r.n_dofs;
    // Natural frequencies (scene's [modes]): after the timed solves, outside their measurements.
    if (s.modes.count > 0) result.model_modes.push_back(fem_model_modes(solver, base, s.modes.count));
    const ReferenceAtPoints ref_here = reference_at(ref, mesh.nodes);
    const ReadOut at = read_out(s, base.level, mesh.nodes, result.qoi_point);
    std::vector<Vec3> unit_loads;  // the indentation's weights: contact loads only
    if (s.load.kind == LoadKind::contact) unit_loads = surface_nodal_loads(s, mesh, 1.0);
    for (const double mag : s.load.magnitudes) {
      ModelOutcome out = base;
      out.magnitude = mag;
      out.max_strain = r.max_abs_principal_strain * mag;
      const std::vector<Vec3> u = scaled(r.nodal_displacement, mag);
      finish_outcome(out, s, mesh.nodes, u, ref_here, mag, at, fine.max_abs_principal_strain,
                     result.qoi_point, scaled(unit_loads, mag), 0, 0.0);
      if (wants_fields(o, s, mag, fine.max_abs_principal_strain)) {
        write_model_fields(o, s, out, mesh.nodes, tet_cells(mesh.tets), u,
                           scaled(ref_here.u, mag));
      }
      result.outcomes.push_back(out);
    }
  } catch (const std::exception& e) {
    for (const double mag : s.load.magnitudes) {
      ModelOutcome out = base;
      out.magnitude = mag;
      out.failure = e.what();
      result.outcomes.push_back(out);
    }
    if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
  }
}

}  // namespace vessel
