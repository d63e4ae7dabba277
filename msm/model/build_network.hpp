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
  /// The hybrid volume model (Golec et al. 2020; model_factory.hpp): volume model only, van-gelder
  /// springs carrying μ (E replaced by 2.5μ) plus a volume term κ = λ − μ on every tet, so that
  /// the network reaches the material's ν. InputError with another model or stiffness rule, or at
  /// ν = 0.5.
  bool volume_term = false;
};

struct BuiltNetwork {
  SpringNetwork network;      ///< springs with stiffness and damping assigned
  std::vector<double> masses;  ///< kg per network node
  std::string topology;        ///< human-readable description
  /// κ (Pa) of the volume term on network.tets (options.volume_term); none: springs only.
  std::optional<double> volume_kappa;
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
