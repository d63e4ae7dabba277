#pragma once
/// One place that turns a model description (volume or surface, which wall, which topology,
/// stiffness and mass rules) into a spring network with stiffness and masses, for the command
/// line and the verification harness alike.
#include <optional>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "meshes/vessel_geometry.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/model/model_terms.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

/// Which network: springs on a wall surface (seeds 000/002) or on every tet edge (seed 001).
enum class ModelType { surface, volume };
std::string to_string(ModelType type);
ModelType parse_model_type(const std::string& name);  ///< "surface" | "volume"; else InputError

/// A surface model's springs: seed 000's structured grid families, the triangle edges with bend
/// springs across them, or `automatic` (the grid on a structured vessel, triangles otherwise).
enum class Topology { automatic, grid, triangles };
std::string to_string(Topology topology);             ///< "auto" | "grid" | "triangles"
Topology parse_topology(const std::string& name);     ///< InputError if unknown

/// A surface model's bending: none beyond its springs, or the Discrete Shells hinge energy
/// (Grinspun et al. 2003; msm/terms/bending_term.hpp) with the wall's plate rigidity.
enum class Bending { none, discrete_shells };
std::string to_string(Bending bending);          ///< "none" | "discrete-shells"
Bending parse_bending(const std::string& name);  ///< InputError if unknown

/// How the hybrid volume model picks its springs' E_s and its κ: `golec` (Golec et al. 2020's
/// affine rule, E_s = 2.5μ, κ = λ − μ; msm/stiffness/hybrid_moduli.hpp) or `homogenised` (our
/// extension: the (E_s, κ) for which this mesh's own network, loaded by uniform boundary tractions,
/// has the target E and ν, with a per-tet stability clip on a negative κ;
/// volume_term_homogenised.hpp).
enum class VolumeModuli { golec, homogenised };
std::string to_string(VolumeModuli rule);                   ///< "golec" | "homogenised"
VolumeModuli parse_volume_moduli(const std::string& name);  ///< InputError if unknown

struct NetworkOptions {
  ModelType model = ModelType::surface;
  WallSurface surface = WallSurface::inner;  ///< surface model: which wall
  Topology topology = Topology::automatic;   ///< surface model
  bool two_ring = false;           ///< triangle topology: add two-ring springs
  StiffnessRule stiffness = StiffnessRule::seed000;
  StiffnessParams stiffness_params;
  MassRule mass = MassRule::consistent;
  double density = kVesselDensity;  ///< kg/m³
  double axial_damping = 0.0;       ///< k_d of seed 000 eq. (3.4), N·s/m, every spring
  /// The hybrid volume model (Golec et al. 2020; msm/stiffness/hybrid_moduli.hpp): volume model
  /// only, van-gelder springs carrying μ (E replaced by 2.5μ) plus a volume term κ = λ − μ on every
  /// tet, so that the network reaches the material's ν. InputError with another model or stiffness
  /// rule, or at ν = 0.5.
  bool volume_term = false;
  /// The volume term's rule (with volume_term only; InputError otherwise). `homogenised` covers
  /// ν from the mesh's floor (≈ 0.06 on a gmsh cube) to below 1/2.
  VolumeModuli volume_moduli = VolumeModuli::golec;
  /// Surface model only: discrete_shells adds the hinge energy of Grinspun et al. (2003) on every
  /// interior edge with D = E·t³/(12(1 − ν²)) (E and ν from stiffness_params, t the wall thickness)
  /// and drops the triangle topology's bend springs, whose job the hinges take over; the springs on
  /// the triangle edges are the membrane (van-gelder: E·t·ΣA/L²). Needs the triangle topology
  /// (auto picks it); InputError with the volume model or the grid topology.
  Bending bending = Bending::none;
  /// Volume model only: the springs of each tet coupled in its tetrahedron-sharing edge pairs, the
  /// edge-based StVK tetrahedron of Kikuuwe et al. (2009) (msm/terms/edge_pair_term.hpp) with λ and
  /// μ from stiffness_params' E and ν: P1 FEM written on the tets' edges. It replaces the springs
  /// (their stiffness rule does not apply). InputError with the surface model, the volume term or
  /// at ν = 0.5.
  bool edge_pairs = false;
};

/// The supports a spring-network file gives (msm/formats/network_file.hpp): nodes held in every
/// component, and the mesh's surface groups whose supports (clamped, roller) hold the nodes lying
/// on them. Built-in networks have none: they follow every support through their source nodes.
struct NetworkSupports {
  std::vector<int> fixed_nodes;            ///< indices into the network's nodes, ascending
  std::vector<std::string> follow_groups;  ///< e.g. "inlet", "outlet"
};

struct BuiltNetwork {
  SpringNetwork network;      ///< springs with stiffness and damping assigned
  std::vector<double> masses;  ///< kg per network node
  std::string topology;        ///< human-readable description
  /// The energy terms the network carries besides its springs (options.volume_term, .bending,
  /// .edge_pairs), with their parameters.
  ModelTerms terms;
  /// A network read from a file: its own supports (the problem holds exactly those), and the file
  /// for messages. Unset for built-in networks.
  std::optional<NetworkSupports> file_supports;
  std::string file;
};

/// Builds the network on the mesh: "auto" topology is seed 000's grid on a structured vessel and
/// the triangle topology otherwise. Throws InputError for an unknown model, surface or topology
/// name, or invalid stiffness parameters.
BuiltNetwork build_network(const TetMesh& mesh, const VesselParams& params,
                           const NetworkOptions& options);

/// Surface model on any triangle surface (an STL file, or a user mesh's wall): the triangle
/// topology (options.topology must be auto or triangles: the seed 000 grid needs the generated
/// structured tube), stiffness, damping and masses as in build_network, wall thickness t (m).
/// Throws InputError for a grid topology, a non-surface model or invalid parameters.
BuiltNetwork build_surface_network(const TriangleSurface& surface, double thickness,
                                   const NetworkOptions& options);

}  // namespace vessel::msm
