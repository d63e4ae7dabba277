#pragma once
/// Calibration files (schema "vesselverify.calibration", version 1): the stiffness factors that
/// `vesselverify calibrate` fitted to the FEM reference (msm/calibration/stiffness_fit.hpp), with
/// the model and mesh they belong to, the loads they were fitted on and the fit's errors. A
/// scene's mass-spring model refers to one with `calibration = "file.json"` (relative to the
/// scene file); its network is then built as usual and the factors applied
/// (apply_scene_calibration).
///
/// Granularities: "groups" (a factor per spring class and κ; msm::group_parameters),
/// "wall_layers" (a factor per spring class by direction and layer through the wall, and a κ per
/// half of the wall; msm::wall_layer_parameters), "edge_types" (the same with the edge's type,
/// diagonals apart), "per_section_spring" (a factor per spring of a cross-section, shared by
/// its images along the centreline; msm::per_section_spring_parameters) and "per_spring" (a
/// factor per spring and κ, or κ per half of the wall: "kappa_factors").
/// The mesh hash must match the model's mesh, unless the model says `calibration_transfer =
/// true`, which a group or wall-layer calibration allows (its classes are defined by the
/// vessel's geometry) and a per-spring one refuses (its factors are indexed by the springs of one
/// mesh).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/calibration/stiffness_fit.hpp"
#include "msm/model/build_network.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// A content hash of a tet mesh: FNV-1a over its node positions rounded to 1 nm and its tets,
/// as 16 hex digits. A regenerated or cached copy of the same mesh has the same hash.
std::string mesh_hash(const TetMesh& mesh);

/// One load a calibration was fitted on (or checked against).
struct CalibrationLoad {
  std::string name;
  LoadKind kind = LoadKind::contact;
  double magnitude = 0.0;    ///< N, Pa or g
  Vec3 point = Vec3::Zero();  ///< contact only, m
};

/// A fit's error on one case: the relative L2 error of the linearised model (what the fit saw)
/// before and after.
struct CalibrationFitCase {
  std::string name;
  double relative_l2_before = 0.0;
  double relative_l2_after = 0.0;
};

struct Calibration {
  /// "groups" | "wall_layers" | "edge_types" | "per_section_spring" | "per_spring"
  std::string granularity = "groups";
  // The model it applies to.
  std::string scene;       ///< scene name it was fitted on
  std::string model;       ///< the scene's model name
  std::string model_kind;  ///< "volume_msm" | "surface_msm"
  std::string stiffness;   ///< the model's stiffness rule
  bool volume_term = false;
  std::string volume_moduli = "golec";  ///< the volume term's (E_s, κ) rule; golec if absent
  double poisson_ratio = 0.0;
  double youngs_modulus = 0.0;  ///< Pa
  // The mesh it belongs to.
  std::string mesh_hash;
  std::string vessel;  ///< describe(vessel) at the fitted level
  int level = 0;
  std::size_t nodes = 0, springs = 0, tets = 0;
  // The factors: exp(θ) per parameter, in the order of `names`.
  std::vector<std::string> names;
  std::vector<double> factors;
  // The fit.
  std::string method;  ///< how it was fitted (linearised at rest, L-BFGS, regulariser)
  double smoothness = 0.0, ridge = 0.0;
  double objective_before = 0.0, objective_after = 0.0;
  int iterations = 0;
  std::string stop_reason;
  std::vector<CalibrationLoad> training_loads;
  std::vector<CalibrationFitCase> fit_cases;
};

/// Writes the file atomically (JSON).
void write_calibration(const std::filesystem::path& path, const Calibration& c);
/// Reads and validates a calibration file; InputError naming the file and key for a missing file,
/// bad JSON, another schema or version, a missing or mistyped key, non-positive factors.
Calibration read_calibration(const std::filesystem::path& path);

/// Records fitted parameters θ of `params` in c: their names, and exp(θ) as factors.
void set_calibration_parameters(Calibration& c, const msm::StiffnessParameters& params,
                                const Eigen::VectorXd& theta);

/// Applies a calibration to a network built for `spec` on `mesh` (vessel at the model's level,
/// ν): checks that the calibration was fitted for this kind of model (kind, stiffness rule,
/// volume term, ν, E) and this mesh (hash; or, with `transfer`, a group calibration on any
/// mesh), then scales the springs and κ. InputError naming `source` and the key otherwise.
void apply_calibration(const Calibration& c, const std::string& source, msm::BuiltNetwork& built,
                       const TetMesh& mesh, const VesselParams& vessel, const ModelSpec& spec,
                       double youngs_modulus, double nu, bool transfer);

/// The stiffness parameterisation and log factors θ a calibration describes on `built`. For
/// wall_layers and edge_types, a class of `built` that the file lacks (a layer the fitted mesh
/// had no edges in: e.g. radial edges in the middle third on a level-0 mesh) takes the geometric
/// mean of the same direction's factors in the other layers; a direction the file lacks
/// altogether is an InputError.
std::pair<msm::StiffnessParameters, Eigen::VectorXd> calibration_parameters(
    const Calibration& c, const std::string& source, const msm::BuiltNetwork& built,
    const VesselParams& vessel);

}  // namespace vessel
