#include "verification/harness/distributed_references.hpp"

#include <iomanip>
#include <memory>

#include "fem_reference/distributed_cache.hpp"
#include "verification/harness/references.hpp"
#include "verification/scene_problems.hpp"

namespace vessel {

namespace {

/// The scene's reference meshes on every rank: rank 0 reads or generates them all (scene_meshes,
/// the model levels included, so that the serial run finds them in the mesh cache) and sends the
/// reference levels; the other ranks resolve the scene on the fine mesh as rank 0 did.
std::unique_ptr<SceneReferences> reference_meshes(const Scene& scene, const HarnessOptions& o,
                                                  bool root, std::ostream& log) {
  std::unique_ptr<SceneReferences> r;
  {
    TetMesh fine = fem::make_mesh_on_rank0([&] {
      r = scene_meshes(scene, o, log);
      return r->fine_mesh;
    });
    if (!root) {
      r = std::make_unique<SceneReferences>();
      r->fine_mesh = std::move(fine);
      r->scene = resolve_file_vessel(scene, r->fine_mesh);
      r->at_nu.resize(r->scene.poisson_ratios.size());
    }
  }
  const auto receive = [&](std::unique_ptr<TetMesh>& slot) {
    TetMesh m = fem::make_mesh_on_rank0([&] { return *slot; });
    if (!root) slot = std::make_unique<TetMesh>(std::move(m));
  };
  if (r->scene.reference_level > 0) receive(r->coarse_mesh);
  if (r->scene.reference_level > 1) receive(r->coarsest_mesh);
  return r;
}

}  // namespace

ReferenceJobSummary solve_references_into_cache(const std::vector<Scene>& scenes,
                                                const HarnessOptions& o, bool root,
                                                std::ostream& log) {
  ReferenceJobSummary summary;
  for (const Scene& scene : scenes) {
    log << "scene " << scene.name << "\n";
    const std::unique_ptr<SceneReferences> r = reference_meshes(scene, o, root, log);
    const Scene& s = r->scene;
    for (std::size_t k = 0; k < s.poisson_ratios.size(); ++k) {
      for (const ReferenceSolve& solve : reference_solves(*r, k)) {
        const fem::CacheFill fill = fem::fill_solution_cache(
            root ? o.solution_cache : nullptr, *solve.mesh, solve.problem);
        log << "  level " << solve.level << ", nu = " << s.poisson_ratios[k] << ": ";
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
