#pragma once
/// Declarative verification scenes: what vessel, material, boundary conditions, load sweep and
/// models a verification runs, read from TOML and validated strictly (unknown keys, wrong types and
/// out-of-range values are InputErrors naming the file, line and key). SI units in the file.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "meshes/supports.hpp"
#include "meshes/surface_loads.hpp"
#include "meshes/vessel_geometry.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/model/build_network.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "verification/guidewire/guidewire_spec.hpp"

namespace vessel {

enum class LoadKind { contact, pressure, gravity };
/// network: a spring network read from a file (msm/formats/network_file.hpp), run by the suite's
/// own solvers like the built-in mass-spring models; external and displacements: models outside
/// the suite (ExternalSpec); corotational_fem and xpbd_fem: P1 tets on the vessel's mesh run by the
/// msm solvers (TetFemSpec).
enum class ModelKind {
  fem,
  surface_msm,
  volume_msm,
  network,
  external,
  displacements,
  corotational_fem,
  xpbd_fem
};

/// Which nodes a model outside the suite (kinds external and displacements) is given and answers
/// at: every node of the vessel's tet mesh (cells: its tets), or the nodes of one wall surface
/// (cells: its triangles; the surface mass-spring models' network on that wall).
enum class ExchangeNodes { volume, surface };
std::string to_string(ExchangeNodes nodes);  ///< "volume" | "surface"

/// A model outside the suite (verification/harness/external_model.hpp): `external` runs `command` once per
/// case on an exchange directory; `displacements` reads answers computed elsewhere from
/// `directory`, one case folder each as `vesselverify export` names them.
struct ExternalSpec {
  std::vector<std::string> command;  ///< external: the program and its arguments
  double timeout_s = 600.0;          ///< external: the process group is killed after this, s
  ExchangeNodes nodes = ExchangeNodes::volume;
  msm::WallSurface surface = msm::WallSurface::inner;  ///< nodes = surface: which wall
  /// displacements: the folder of case folders (relative paths: against the scene file's folder).
  std::filesystem::path directory;
  /// Dynamic problems (both > 0): the simulator runs `steps` steps of `dt` from rest under the
  /// load applied as a step at t = 0; 0: a static problem.
  double dt = 0.0;
  long steps = 0;
  /// The folder the command runs in (the scene file's folder; relative paths in `command` resolve
  /// there).
  std::filesystem::path working_dir;
};

/// The P1 tet models the simulators run, on the vessel's own mesh (msm/fem): corotational_fem
/// (Müller & Gross 2004) solved statically by Newton with its consistent tangent; xpbd_fem
/// (Macklin & Müller 2021's stable neo-Hookean constraints) stepped by XPBD to its steady state.
struct TetFemSpec {
  double dt = 1e-4;              ///< xpbd_fem: time step, s
  int iterations = 4;            ///< xpbd_fem: Gauss–Seidel sweeps per step
  double velocity_damping = 0.02;  ///< xpbd_fem: fraction of the velocity removed per step
  /// xpbd_fem: steady when no node moves farther in a step than this fraction of the largest node
  /// displacement from rest (msm::XpbdFem::relax)
  double settle_relative_change = 1e-6;
  long max_steps = 200'000;  ///< xpbd_fem: steps before the run is recorded as failed
};

/// One model to run against the reference. FEM models use `degree`; mass-spring models use the
/// rest. A [[models]] table whose stiffness, mass, solver, dt or degree is an array expands into
/// one ModelSpec per combination (a sweep from the scene file).
struct ModelSpec {
  std::string name;  ///< unique within the scene, used in results and reports
  ModelKind kind = ModelKind::fem;
  int degree = 2;                                         ///< FEM: 1 or 2
  msm::WallSurface surface = msm::NetworkOptions{}.surface;  ///< surface msm: which wall
  msm::Topology topology = msm::Topology::automatic;      ///< surface msm
  msm::StiffnessRule stiffness = msm::StiffnessRule::seed000;
  /// volume_msm: the hybrid volume model (Golec et al. 2020; msm/model/mass_spring_model.hpp):
  /// van-gelder springs carrying μ plus a volume energy per tet with κ = λ − μ (any ν < 0.5).
  bool volume_term = false;
  /// volume_term's rule for (E_s, κ): golec (default) or homogenised (msm/model/build_network.hpp).
  msm::VolumeModuli volume_moduli = msm::VolumeModuli::golec;
  /// volume_msm: each tet's springs coupled in its tetrahedron-sharing edge pairs, the edge-based
  /// StVK tetrahedron of Kikuuwe et al. 2009 (msm/terms/edge_pair_term.hpp): P1 FEM on the edges.
  bool edge_pairs = false;
  /// surface msm: discrete_shells adds the Discrete Shells hinge energy (Grinspun et al. 2003) with
  /// D = E·t³/(12(1 − ν²)) and drops the bend springs (msm/model/build_network.hpp).
  msm::Bending bending = msm::Bending::none;
  msm::MassRule mass = msm::MassRule::consistent;
  /// static | linear | relaxation | an integrator | pbd; dynamic solvers with dt (s, > 0) and
  /// steps (> 0).
  msm::SolverSpec solver;
  double damping = 0.0;  ///< point damping k_v of seed 000 eq. (3.3), N·s/m per node
  /// Region of interest (mass-spring, contact loads): nodes farther than this from the contact
  /// point are fixed and their unknowns removed from the solve, m; 0 = the whole vessel.
  double roi_radius = 0.0;
  /// Mass-spring: a calibration file of `vesselverify calibrate` (verification/calibration_file
  /// .hpp) whose stiffness factors are applied to the built network; relative paths are resolved
  /// against the scene file's folder. Empty: none.
  std::filesystem::path calibration;
  /// Apply a group calibration to a mesh other than the one it was fitted on (its hash differs).
  bool calibration_transfer = false;
  ExternalSpec external;  ///< kinds external and displacements only
  /// kind network: the spring-network file (.json or .vtu; docs/user_guide/network_format.md), relative
  /// paths resolved against the scene file's folder. Its springs, masses and supports replace
  /// the stiffness, mass and topology keys.
  std::filesystem::path network_file;
  TetFemSpec tet_fem;  ///< kinds corotational_fem and xpbd_fem
};

struct LoadSpec {
  LoadKind kind = LoadKind::contact;
  std::vector<double> magnitudes;  ///< N (contact), Pa (pressure), multiples of g (gravity)
  ContactPatchSpec contact;        ///< point, radius, surface group (force set per magnitude)
  Vec3 gravity_direction = Vec3(0.0, -1.0, 0.0);
  /// `type = "guidewire"`: the wire, a contact load on the inner wall whose one magnitude and
  /// point are those of `wire`, its solve against the rigid lumen. Parsing leaves `wire` empty
  /// (and `magnitudes` with it); solve_guidewire_load (verification/guidewire/guidewire_load.hpp)
  /// fills both on the run path, where the references are computed.
  std::optional<GuidewireSpec> guidewire;
  std::optional<GuidewireSolution> wire;
};

/// Standard gravity, m/s²: gravity magnitudes are multiples of it.
inline constexpr double kStandardGravity = 9.81;

struct Tolerances {
  double max_error_mm = 0.1;  ///< seed 000's visual threshold
};

/// What the scene's error budget is measured on (the `[budget]` table's `quantity`).
enum class BudgetQuantity {
  contact_point,  ///< |u_model − u_ref| at the QoI (contact) node, mm
  patch,     ///< max |u_model − u_ref| over the model nodes within `radius` of the QoI point, mm
  field,     ///< max |u_model − u_ref| over all model nodes, mm
  reaction,  ///< the force the instrument feels at the reference's indentation, mN
  /// The wire's contact force on the wall from the wire–wall contact solve (a guidewire load with
  /// coupling = "contact", guidewire_contact.hpp): |F_model − F_reference| at the worst EI, mN
  contact_force,
};

/// An accuracy and rate budget: what the scene needs (issue #7). Rate: `rate_hz` sets the update
/// period 1/rate; `time_budget_s` the compute time allowed per update (default the period); given
/// alone it is also the period.
struct Budget {
  bool stated = false;  ///< the scene has a [budget] table
  BudgetQuantity quantity = BudgetQuantity::contact_point;
  double radius = 0.0;         ///< m, quantity patch only
  double tolerance = 0.1;      ///< mm (mN for reaction, contact_force); seed 000's 0.1 mm
  double rate_hz = 0.0;        ///< 0: not given
  double time_budget_s = 0.0;  ///< 0: not given
  double magnitude = 0.0;      ///< load the budget applies at (scene's unit); 0: representative
  /// Compute time allowed per update, s (time_budget_s, else 1/rate_hz; 0 if neither).
  [[nodiscard]] double seconds_per_update() const {
    return time_budget_s > 0.0 ? time_budget_s : (rate_hz > 0.0 ? 1.0 / rate_hz : 0.0);
  }
  /// Simulated time one update advances, s (1/rate_hz, else time_budget_s; 0 if neither).
  [[nodiscard]] double update_period() const {
    return rate_hz > 0.0 ? 1.0 / rate_hz : time_budget_s;
  }
};

/// Natural frequencies (the `[modes]` table; issue 14): each model's lowest `count` modes at rest
/// beside the FEM's of the same vessel (same supports and density). Mass-spring models: K their
/// exact Hessian at rest, M their lumped masses (msm/dynamics/natural_frequencies.hpp); FEM models
/// of the scene and the modal reference: consistent mass, displacement formulation.
struct ModalSpec {
  int count = 0;  ///< lowest modes per model; 0: none computed
  /// Mesh level of the modal reference (P2, displacement formulation); −1: the scene's
  /// reference_level.
  int reference_level = -1;
};

/// The FEM transient the dynamic models' histories are compared with (the `[transient]` table).
struct TransientSpec {
  /// Mesh level of the transient (P2, Newmark); −1: the scene's reference_level. Every Newmark
  /// step is a solve with the level's factor, so a level below the static reference's keeps a
  /// long transient affordable.
  int reference_level = -1;
};

/// Which FEM reference judges the mass-spring models (issue 17): the linear one (small strain),
/// the finite-strain one (neo-Hookean with the same E and ν, fem::HyperelasticSolver, solved at
/// each load magnitude), or automatic: finite-strain where the linear reference's largest strain
/// at that load exceeds 5 %.
enum class ReferenceChoice { linear, finite_strain, automatic };

struct Scene {
  std::string name;
  std::string description;
  std::filesystem::path source;  ///< the file it was read from
  VesselParams vessel;           ///< vessel.level is model_levels.front()
  /// Levels the models run at (`level = 1` or `level = [0, 1, 2]`: a convergence sweep), ascending.
  std::vector<int> model_levels{0};
  int reference_level = 1;       ///< finest FEM level of the reference (default: the finest model level)
  double youngs_modulus = 14.24e3;  ///< Pa
  std::vector<double> poisson_ratios{0.45};
  double density = 1060.0;  ///< kg/m³
  std::map<std::string, EndCondition> boundary;  ///< end group name → condition
  LoadSpec load;  ///< the load the runs sweep over its magnitudes
  /// Further loads applied together with `load`, each at its single magnitude (the fem and msm
  /// commands combine pressure, contact and gravity; a scene file has none).
  std::vector<LoadSpec> constant_loads;
  std::vector<ModelSpec> models;
  Tolerances tolerances;
  Budget budget;
  ModalSpec modes;
  TransientSpec transient;
  ReferenceChoice reference = ReferenceChoice::linear;  ///< `reference = "linear"` (default)
};

/// Reads and validates a scene file. Throws InputError ("file:line: key: what was found, what was
/// expected") for a missing file, a TOML syntax error, an unknown key, a wrong type or a value out
/// of range.
Scene read_scene(const std::filesystem::path& path);
/// Same, from text; `source_name` is used in messages.
Scene parse_scene(std::string_view text, const std::string& source_name);

std::string to_string(LoadKind kind);
std::string to_string(ReferenceChoice choice);  ///< linear | finite-strain | auto
std::string to_string(ModelKind kind);
std::string to_string(BudgetQuantity quantity);
BudgetQuantity parse_budget_quantity(const std::string& name);  ///< InputError if unknown
/// "mm", or "mN" for reaction.
const char* budget_unit(BudgetQuantity quantity);

}  // namespace vessel
