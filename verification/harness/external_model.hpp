#pragma once
/// Models outside the suite (scene kinds `external` and `displacements`; issue 15 item 3): the
/// exchange through which a user's own simulator is verified exactly as a built-in model is.
///
/// For each case (ν, level, load magnitude) the suite writes a case folder: `problem.vtu` (the
/// nodes at rest, m; the cells; point data `load_N` (consistent nodal loads, N), `fixed` (1 per
/// held component), `mass_kg` (lumped consistent masses)) and `manifest.json` (schema
/// `vesselverify.exchange`, verification/exchange.schema.json: units, material, the case, the
/// analysis, what to write back). The simulator answers in the same folder with
/// `displacements.csv` (`node,ux,uy,uz`, m) or `displacements.vtu` (point data `displacement`),
/// optionally `timing.json` (its own `setup_seconds`, `solve_seconds`) and, for dynamic problems,
/// `history.csv` (`time_s,ux,uy,uz` of the manifest's qoi_node). The nodes and loads are those
/// the built-in mass-spring models get (verification/scene_problems.hpp: msm_problem on a volume
/// or wall-surface network), so the comparison is the harness's own.
#include <array>
#include <filesystem>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshes/foundation/process.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/vtu_io.hpp"
#include "msm/model/build_network.hpp"
#include "msm/form/form.hpp"
#include "verification/scene.hpp"

namespace vessel {

inline constexpr const char* kExchangeSchema = "vesselverify.exchange";
inline constexpr int kExchangeSchemaVersion = 1;

/// Names of the files in a case folder.
namespace exchange_files {
inline constexpr const char* manifest = "manifest.json";
inline constexpr const char* problem = "problem.vtu";
inline constexpr const char* displacements_csv = "displacements.csv";
inline constexpr const char* displacements_vtu = "displacements.vtu";
inline constexpr const char* timing = "timing.json";
inline constexpr const char* history = "history.csv";
inline constexpr const char* log = "simulator.log";  ///< the command's stdout and stderr
}  // namespace exchange_files

/// A model outside the suite failed on one case: non-zero exit, time-out, missing or malformed
/// output, non-finite values, wrong node count. The harness records it as a failed outcome with
/// this message as the reason, and goes on.
class ExternalModelError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The nodes an outside model is given for a scene at one level and ν: the network the built-in
/// mass-spring models use (a volume network on every tet-mesh node, or a triangle network on one
/// wall), with its consistent lumped masses, and the mass-spring problem whose loads and held
/// dofs it receives.
struct ExchangeNetwork {
  msm::BuiltNetwork built;
  std::unique_ptr<msm::Form> form;  ///< the network's springs: msm_problem needs a Form
  VtuCells cells;                   ///< tets (volume) or triangles (surface)
  std::string description;          ///< e.g. "volume nodes (tet mesh), 1234 nodes"
};
ExchangeNetwork exchange_network(const Scene& scene, const ModelSpec& model, const TetMesh& mesh,
                                 int level, double nu);

/// One case of an outside model, as written to its folder.
struct ExchangeProblem {
  std::string id;  ///< the case folder's name, case_id()
  std::string scene, model;
  double poisson_ratio = 0.0;
  int level = 0;
  LoadKind load = LoadKind::contact;
  double magnitude = 0.0;  ///< N, Pa or g
  double youngs_modulus = 0.0, density = 0.0;
  VesselParams vessel;
  ExchangeNodes node_set = ExchangeNodes::volume;
  msm::WallSurface surface = msm::WallSurface::inner;
  std::vector<Vec3> nodes;  ///< at rest, m
  VtuCells cells;
  std::vector<Vec3> loads;                  ///< N per node (surface loads and gravity)
  std::vector<std::array<char, 3>> fixed;   ///< per node and component: held at rest
  std::vector<double> masses;               ///< kg per node
  std::size_t qoi_node = 0;                 ///< where the scene's QoI is read
  double dt = 0.0;                          ///< dynamic problems: time step, s
  long steps = 0;                           ///< dynamic problems: steps; 0 static
  msm::Problem problem;                     ///< the mass-spring problem it came from
};

/// A file or folder name from a model or scene name: every character but letters, digits, '-'
/// and '.' becomes '_' ("vol[stiffness=lloyd;dt=2e-05]" → "vol_stiffness_lloyd_dt_2e-05_").
std::string file_stem(const std::string& name);

/// Writes the exchange folders of every case of the scene's outside models (kinds external and
/// displacements) — each of its model levels, ν and load magnitudes — as
/// output_dir/<model>/<case>/, the layout a displacements model's `file` folder has (pointing it
/// at output_dir/<model>). Meshes come from the cache under cache_dir (none if empty). Returns the
/// number of cases; InputError if the scene has no outside model.
std::size_t export_exchange(const Scene& scene, const std::filesystem::path& cache_dir,
                            const std::filesystem::path& output_dir, std::ostream* log);

/// "nu<ν>_L<level>_load<magnitude>" (default stream formatting, as the harness's field files).
std::string case_id(double nu, int level, double magnitude);

/// The case's problem: network nodes, the consistent nodal loads and held dofs of msm_problem at
/// `magnitude`, masses, QoI node; dt and steps from the model.
ExchangeProblem exchange_problem(const ExchangeNetwork& network, const Scene& scene,
                                 const ModelSpec& model, const TetMesh& mesh, int level, double nu,
                                 double magnitude, const Vec3& qoi_point);

/// Writes `root/<id>/problem.vtu` and `manifest.json` (atomically) and removes any answer left
/// there by an earlier run (so a stale answer is never read). Returns the case folder.
std::filesystem::path write_exchange_case(const std::filesystem::path& root,
                                          const ExchangeProblem& problem);

/// What a simulator answered for one case.
struct ExternalAnswer {
  std::vector<Vec3> u;  ///< displacement per node, m
  std::optional<double> setup_seconds, solve_seconds;  ///< self-reported (timing.json)
  std::vector<double> history_time_s;   ///< dynamic: history.csv, when written
  std::vector<Vec3> history_u;          ///< displacement of the QoI node, m
};

/// Reads the answer in `case_dir` (displacements.csv, else displacements.vtu; timing.json and
/// history.csv when present). Throws ExternalModelError naming the file and what is wrong: no
/// answer, a malformed header or line, a node missing, repeated or out of range, a node count
/// other than `nodes`, a value that is not finite.
ExternalAnswer read_external_answer(const std::filesystem::path& case_dir, std::size_t nodes);

/// Runs an external model's command on a written case folder: the command plus the manifest's
/// absolute path as the last argument, in spec.working_dir, with VESSELVERIFY_MANIFEST and
/// VESSELVERIFY_CASE_DIR set; then reads its answer. Throws ExternalModelError (non-zero exit,
/// killed, timed out, or read_external_answer's reasons), with the log's last lines.
ExternalAnswer run_external_case(const ExternalSpec& spec, const std::filesystem::path& case_dir,
                                 std::size_t nodes, ProcessResult* process = nullptr);

}  // namespace vessel
