/// `vesselverify reference`: the scenes' static references solved over the MPI ranks into the
/// FEM solution cache, for a serial `run` (gate, recommend) on the same cache to restore.
#include <iostream>
#include <memory>
#include <streambuf>

#include "fem_reference/distributed_elasticity.hpp"
#include "meshes/foundation/errors.hpp"
#include "verification/cli/cache_options.hpp"
#include "verification/cli/commands.hpp"
#include "verification/harness/distributed_references.hpp"
#include "verification/harness/harness.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::cli {

namespace {

struct ReferenceOptions {
  std::vector<std::string> scenes;
  CacheOptions cache;
  bool quick = false;
  std::vector<double> poisson_ratios;
  int reference_level = -1;
};

/// Discards what is written to it: the non-root ranks' std::cout.
struct NullBuffer : std::streambuf {
  int overflow(int c) override { return c; }
};

void run(const ReferenceOptions& o) {
  if (o.cache.no_cache) {
    throw InputError("reference: --no-cache leaves nothing for the serial run: the job's only "
                     "output is the FEM solution cache");
  }
  const fem::MpiSession mpi;
  const bool root = mpi.rank() == 0;
  static NullBuffer null_buffer;
  std::streambuf* const cout_buffer = std::cout.rdbuf();
  if (!root) std::cout.rdbuf(&null_buffer);
  struct Restore {
    std::streambuf* buffer;
    ~Restore() { std::cout.rdbuf(buffer); }
  } restore{cout_buffer};

  // The references as `run` would solve them with the same options (its --quick, --nu and
  // --reference-level; the other sweeps of `run` change the models, not the references).
  std::vector<Scene> scenes;
  for (const auto& f : o.scenes) scenes.push_back(read_scene(f));
  for (Scene& s : scenes) solve_guidewire_load(s);  // the load's point sets the references' patch
  for (Scene& s : scenes) {
    if (o.quick) s = quick_variant(std::move(s));
    if (!o.poisson_ratios.empty()) s.poisson_ratios = o.poisson_ratios;
    if (o.reference_level >= 0) s.reference_level = o.reference_level;
  }
  HarnessOptions h;
  h.cache_dir = o.cache.mesh_dir();
  const auto solution_cache = o.cache.solution_cache(std::cout);
  h.solution_cache = solution_cache.get();
  std::cout << "reference job on " << mpi.size() << " MPI rank(s), cache "
            << solution_cache->directory().string() << "\n";
  const ReferenceJobSummary done = solve_references_into_cache(scenes, h, root, std::cout);
  std::cout << "references: " << done.solved << " solved and stored, " << done.cached
            << " already in the cache\n";
}

}  // namespace

void add_reference_command(CLI::App& app) {
  auto o = std::make_shared<ReferenceOptions>();
  CLI::App* cmd = app.add_subcommand(
      "reference",
      "Solve the scenes' FEM references (P2, Taylor-Hood for nu >= 0.49: the fine level, the "
      "level below for the Richardson uncertainty and the one below that for its order) over the "
      "MPI ranks into the FEM solution cache; a serial 'run' with the same options and cache "
      "then reads them instead of solving. Modal references, FEM transients and finite-strain "
      "references stay with the serial run. Rank 0 meshes and prints.\n"
      "Examples:\n"
      "  mpirun -np 4 vesselverify reference verification/scenes/contact_straight.toml\n"
      "  vesselverify run verification/scenes/contact_straight.toml");
  cmd->add_option("scenes", o->scenes, "Scene files (TOML)")->required();
  add_cache_options(*cmd, o->cache);
  cmd->add_flag("--quick", o->quick, "The references of 'run --quick' (reference level 1)");
  cmd->add_option("--nu", o->poisson_ratios,
                  "The references of 'run --nu' at these Poisson's ratios instead of the scenes'")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--reference-level", o->reference_level,
                  "The references of 'run --reference-level' at this level instead of the "
                  "scene's")
      ->check(CLI::Range(0, kMaxMeshLevel));
  cmd->callback([o] { run(*o); });
}

}  // namespace vessel::cli
