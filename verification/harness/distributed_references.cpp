#include "verification/harness/distributed_references.hpp"

#include <iomanip>
#include <memory>

#include "fem_reference/distributed_cache.hpp"
#include "fem_reference/distributed_elasticity.hpp"
#include "verification/harness/references.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

ReferenceJobSummary solve_references_into_cache(const std::vector<Scene>& scenes,
                                                const HarnessOptions& o, bool root,
                                                std::ostream& log) {
  ReferenceJobSummary summary;
  const TetMesh none;
  const fem::ElasticityProblem no_problem;
  for (const Scene& scene : scenes) {
    // Rank 0 alone reads or generates the meshes (scene_meshes, the model levels included, so
    // that the serial run finds them in the mesh cache) and makes the problems; the solver sends
    // each other rank its part.
    std::unique_ptr<SceneReferences> r;
    std::vector<std::vector<ReferenceSolve>> solves;  // per ν (rank 0)
    fem::run_on_rank0([&] {
      log << "scene " << scene.name << "\n";
      r = scene_meshes(scene, o, log);
      for (std::size_t k = 0; k < r->scene.poisson_ratios.size(); ++k)
        solves.push_back(reference_solves(*r, k));
    });
    std::vector<int> count;  // solves per ν, rank 0's on every rank
    for (const auto& at_nu : solves) count.push_back(static_cast<int>(at_nu.size()));
    count = fem::broadcast_from_rank0(std::move(count));
    for (std::size_t k = 0; k < count.size(); ++k) {
      for (int i = 0; i < count[k]; ++i) {
        const ReferenceSolve* solve = root ? &solves[k][static_cast<std::size_t>(i)] : nullptr;
        const fem::CacheFill fill =
            fem::fill_solution_cache(root ? o.solution_cache : nullptr, solve ? *solve->mesh : none,
                                     solve ? solve->problem : no_problem);
        if (!root) continue;
        log << "  level " << solve->level << ", nu = " << r->scene.poisson_ratios[k] << ": ";
        if (fill.was_cached) {
          ++summary.cached;
          log << "already in the cache\n";
          continue;
        }
        ++summary.solved;
        const fem::ElasticityResult& f = fill.fem;
        log << f.element << ", " << f.n_dofs << " DoFs on " << fill.n_ranks << " rank(s), "
            << fem::to_string(f.solver) << " " << f.iterations << " iterations, "
            << std::setprecision(3) << fill.seconds << " s (solve " << f.timings.solve
            << " s), stored\n"
            << std::setprecision(6);
      }
    }
  }
  return summary;
}

}  // namespace vessel
