#pragma once
/// Measured outcomes kept on disk (issue 16): a model's outcomes in a scene (run, recommend), the
/// stability study's rows and hard cases. An outcome includes timings, so an entry is keyed by
/// everything that determines the outcome (the caller's key) plus the identity of the code (a hash
/// of the running executable's bytes) and of the machine (CPU model and core count): a rebuilt
/// program or another machine measures again. Each entry records when its timings were measured;
/// a caller marks the outcomes it took from the cache (TimingProvenance), and `--retime` measures
/// again and replaces the entries. The store is the project's checksummed content store
/// (meshes/foundation/content_store.hpp: entries holding their full key, atomic rename, corrupt
/// entries recomputed with a message).
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "verification/harness/options.hpp"
#include "verification/harness/outcome.hpp"

namespace vessel {

class ContentStore;  // meshes/foundation/content_store.hpp

struct OutcomeCacheStatistics {
  int hits = 0;
  int misses = 0;   ///< measured and stored (with --retime, every lookup)
  int corrupt = 0;  ///< entries found unreadable or failing their checksum, measured again
  double seconds_saved = 0.0;
};

/// A hash of the running executable's bytes (/proc/self/exe), computed once per process.
const std::string& executable_identity();
/// "CPU model string; N cores" (/proc/cpuinfo's first "model name", hardware_concurrency).
const std::string& machine_identity();

class OutcomeCache {
 public:
  /// Entries live in `dir` (empty: disabled, every outcome measured); `retime`: measure every
  /// outcome again and replace its entry. Corrupt entries are reported on `log`.
  OutcomeCache(std::filesystem::path dir, bool retime, std::ostream* log);
  ~OutcomeCache();
  OutcomeCache(const OutcomeCache&) = delete;
  OutcomeCache& operator=(const OutcomeCache&) = delete;

  [[nodiscard]] bool enabled() const;

  /// The outcome `compute()` measures (serialised by the caller), or the stored one of the same
  /// key, code and machine. `provenance` says which, and when the stored one was measured.
  std::string get(const std::string& key, const std::function<std::string()>& compute,
                  TimingProvenance& provenance);

  [[nodiscard]] OutcomeCacheStatistics statistics() const;
  /// One line: "model outcome cache (DIR): H hits, M misses, ..." (with --retime, says so).
  [[nodiscard]] std::string summary() const;

 private:
  std::unique_ptr<ContentStore> store_;
  bool retime_;
};

/// reports::timing_provenance_line over outcomes (those with a provenance: the suite's own
/// models), for summary.md.
std::string timing_provenance_line(const std::vector<ModelOutcome>& outcomes);

/// The outcomes one model produces in run_models at one ν and level (every magnitude), its
/// natural frequencies and its VTU field files (path relative to the fields directory → bytes).
struct ModelRun {
  std::vector<ModelOutcome> outcomes;
  std::vector<ModalOutcome> modes;
  std::vector<std::pair<std::string, std::string>> field_files;
};
std::string serialise(const ModelRun& run);
ModelRun deserialise_model_run(std::string_view bytes);  ///< throws std::exception if unreadable

/// A file's bytes, for keys ("(unreadable)" if it cannot be opened).
std::string file_contents(const std::filesystem::path& path);

/// A hash of a mesh's nodes (exact), tets, triangles and groups, for keys.
std::string mesh_key(const TetMesh& mesh);

/// The key of a model's run: the scene's definition apart from its other models (vessel, levels,
/// material, supports, loads, budget, modes, reference choice), the model's definition (with the
/// contents of its calibration and network files), ν, level, the magnitudes run, the model mesh
/// and the harness settings that change outcomes (repeats, ramp updates, which fields are written).
std::string model_run_key(const Scene& scene, const ModelSpec& spec, double nu, int level,
                          const std::vector<double>& magnitudes, const TetMesh& mesh,
                          const HarnessOptions& options);

}  // namespace vessel
