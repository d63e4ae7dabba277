#pragma once
/// What a harness run is asked to do beyond the scene: caches, progress, repeats, fields, jobs.
#include <filesystem>
#include <ostream>

namespace vessel::fem {
class SolutionCache;
}

namespace vessel {

class OutcomeCache;  // verification/harness/outcome_cache.hpp

/// Updates of the load ramp static and linear mass-spring models are timed on (timed_updates).
inline constexpr int kRampUpdates = 8;

struct HarnessOptions {
  std::filesystem::path cache_dir;  ///< generated meshes (empty: no cache)
  /// FEM references solved once and kept on disk (nullptr: each solved afresh). The FEM models
  /// the scene times (P1, P2 as models) are always solved: their time is a measurement.
  fem::SolutionCache* solution_cache = nullptr;
  /// The models' outcomes (timings included) kept on disk per model, ν and level, keyed by their
  /// definition and by the executable and machine (nullptr: every model measured). Models outside
  /// the suite (external, displacements) are always run.
  OutcomeCache* outcome_cache = nullptr;
  std::ostream* log = nullptr;      ///< progress; nullptr for none
  int repeats = 1;                  ///< timed repeats of each model solve (median reported)
  /// Static and linear mass-spring models: updates in the timed load ramp (timed_updates).
  int ramp_updates = kRampUpdates;
  /// Run the models only at the budget's load (Budget::magnitude, else the representative load:
  /// the largest magnitude within the reference's linear regime, else the smallest), per ν.
  bool budget_load_only = false;
  /// VTU fields for ParaView (model and reference displacement and their difference at the
  /// model's nodes) written under fields_dir/<scene>/, one file per model, ν and level; empty:
  /// none. Only at the representative load (budget_magnitude()) unless fields_every_load.
  std::filesystem::path fields_dir;
  bool fields_every_load = false;
  /// run_scenes: FEM references solved this many at a time before the models (> 1), each sparse
  /// factorisation with cores / jobs threads; the models always run one at a time, because their
  /// set-up and update times are measurements. 1: scene after scene, each ν's reference just
  /// before its models.
  int jobs = 1;
  /// Models of kind `external`: their case folders go under exchange_dir/<scene>/<model>/<case>
  /// (verification/harness/external_model.hpp); empty: a folder under the system's temporary directory.
  std::filesystem::path exchange_dir;
  /// Guidewire scenes with coupling = "contact": the contact mesh's element size near the wire's
  /// contact, m (0: the scene's contact_fine_size).
  double contact_fine_size = 0.0;
};

}  // namespace vessel
