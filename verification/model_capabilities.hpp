#pragma once
/// What each model of a scene can run and what it needs, asked before any work: by the scene
/// check (read_scene) and by the harness before it builds a model. The limits are the models' own
/// (msm: hybrid_refusal, homogenised_refusal, edge_pair_refusal), never restated here.
#include <filesystem>
#include <string>
#include <vector>

#include "verification/scene.hpp"

namespace vessel {

/// Why `spec` cannot run the material (E in Pa, ν), or "" if it can. Mass-spring models with a
/// ν-limited term: the hybrid volume term (Golec et al. 2020), its homogenised rule (the range
/// every mesh shares; a mesh's own floor below ν = 1/4 is found when the model is fitted, and the
/// model then fails alone), the edge pairs (ν < 0.5), the P1 tet models corotational_fem and
/// xpbd_fem (ν in [0, 0.5)). FEM models are checked by the FEM code
/// itself (P1 and P2 in displacement form cannot take ν = 0.5: recorded as failed).
std::string model_refusal(const ModelSpec& spec, double youngs_modulus, double nu);

/// A file a model reads: the scene key naming it and its path (resolved against the scene).
struct RequiredFile {
  std::string key;  ///< e.g. "calibration", "file"
  std::filesystem::path path;
};

/// The files `spec` reads when it runs: a calibration file, a spring-network file.
std::vector<RequiredFile> required_files(const ModelSpec& spec);

/// Opens and validates every model's required files (a calibration file is read as `run` reads
/// it, a network file likewise); InputError naming the scene file, the model, the key, the file
/// and what is wrong. read_scene calls it, so `vesselverify scene` finds what `run` would.
void check_model_inputs(const Scene& scene);

}  // namespace vessel
