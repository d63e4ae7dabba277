#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>

#include "verification/harness/external_model.hpp"
#include "verification/harness/metrics.hpp"
#include "verification/harness/model_readout.hpp"
#include "verification/harness/model_runs.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

namespace {

/// A dynamic outside model's QoI history (its history.csv) beside the FEM transient, sampled to
/// at most kHistorySamples + 1 points.
History outside_history(const ExternalAnswer& a, const ReferenceSolvers& ref, const Vec3& probe,
                        const ModelSpec& spec, const msm::Problem& problem, double magnitude) {
  History h;
  const std::size_t n = a.history_time_s.size();
  const std::size_t every = std::max<std::size_t>(1, n / kHistorySamples);
  for (std::size_t k = 0; k < n; ++k) {
    if (k % every != 0 && k + 1 != n) continue;
    h.time_s.push_back(a.history_time_s[k]);
    h.model_mm.push_back(a.history_u[k].norm() * 1e3);
  }
  ModelSpec as_run = spec;  // add_reference_history reads the run's dt and steps from the solver
  as_run.solver.dt = spec.external.dt;
  as_run.solver.steps = spec.external.steps;
  as_run.damping = 0.0;
  add_reference_history(h, ref, probe, as_run, problem, magnitude);
  return h;
}

}  // namespace

void run_outside_model(const Scene& s, const ModelSpec& spec, double nu, const TetMesh& mesh,
                       const ReferenceSolvers& ref, const fem::ElasticityResult& fine,
                       const HarnessOptions& o, Progress& progress, ModelOutcome base,
                       SceneResult& result) {
  const ExchangeNetwork network = exchange_network(s, spec, mesh, base.level, nu);
  const std::vector<Vec3>& nodes = network.built.network.nodes;
  const bool external = spec.kind == ModelKind::external;
  std::filesystem::path root = spec.external.directory;
  if (external) {
    const std::filesystem::path exchange =
        o.exchange_dir.empty() ? std::filesystem::temp_directory_path() /
                                     ("vesselverify-exchange-" + std::to_string(getpid()))
                               : o.exchange_dir;
    root = exchange / file_stem(s.name) / file_stem(spec.name);
  }
  std::ostringstream detail;
  if (external) {
    detail << "external:";
    for (const auto& a : spec.external.command) detail << " " << a;
  } else {
    detail << "displacements from " << spec.external.directory.string();
  }
  detail << "; " << network.description;
  if (spec.external.steps > 0) {
    detail << "; dynamic, " << spec.external.steps << " steps of " << spec.external.dt << " s";
  }
  base.detail = detail.str();
  base.nodes = nodes.size();
  const ReferenceAtPoints ref_here = reference_at(ref, nodes);
  const ReadOut at = read_out(s, base.level, nodes, result.qoi_point);
  for (const double mag : s.load.magnitudes) {
    progress.begin(spec.name + " at " + std::to_string(mag) + " (" + to_string(s.load.kind) + ", " +
                   to_string(spec.kind) + ")");
    ModelOutcome out = base;
    out.magnitude = mag;
    try {
      const ExchangeProblem p =
          exchange_problem(network, s, spec, mesh, base.level, nu, mag, result.qoi_point);
      out.unknowns = free_unknowns(p.problem);
      ExternalAnswer answer;
      if (external) {
        const std::filesystem::path dir = write_exchange_case(root, p);
        ProcessResult process;
        answer = run_external_case(spec.external, dir, nodes.size(), &process);
        out.solve_seconds = process.wall_seconds;
        out.timing_source = "process";
      } else {
        answer = read_external_answer(root / p.id, nodes.size());
        out.timing_source = "none";
      }
      if (answer.solve_seconds) {
        out.solve_seconds = *answer.solve_seconds;
        out.setup_seconds = answer.setup_seconds.value_or(0.0);
        out.timing_source = "simulator";
      }
      if (!answer.history_time_s.empty() && spec.external.steps > 0) {
        out.history = outside_history(answer, ref, nodes[at.qoi], spec, p.problem, mag);
      }
      out.max_strain = largest_edge_strain(nodes, network.cells, answer.u);
      std::vector<Vec3> loads;
      if (s.load.kind == LoadKind::contact) loads = p.loads;
      finish_outcome(out, s, nodes, answer.u, ref_here, mag, at, fine.max_abs_principal_strain,
                     result.qoi_point, loads, spec.external.steps, spec.external.dt);
      if (wants_fields(o, s, mag, fine.max_abs_principal_strain)) {
        write_model_fields(o, s, out, nodes, network.cells, answer.u, scaled(ref_here.u, mag));
      }
    } catch (const ExternalModelError& e) {
      out.ok = false;
      out.failure = e.what();
      if (o.log) *o.log << "      FAILED: " << e.what() << "\n";
    }
    result.outcomes.push_back(out);
    progress.end();
  }
}

}  // namespace vessel
