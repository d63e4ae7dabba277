#include "msm/model/build_network.hpp"

#include <algorithm>
#include <cmath>

#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/stiffness/hybrid_moduli.hpp"
#include "msm/terms/bending_term.hpp"
#include "msm/terms/volume_term_homogenised.hpp"

namespace vessel::msm {

std::string to_string(ModelType type) { return type == ModelType::volume ? "volume" : "surface"; }

ModelType parse_model_type(const std::string& name) {
  if (name == "surface") return ModelType::surface;
  if (name == "volume") return ModelType::volume;
  throw InputError("model: expected 'surface' or 'volume', got '" + name + "'");
}

std::string to_string(Topology topology) {
  switch (topology) {
    case Topology::automatic: return "auto";
    case Topology::grid: return "grid";
    case Topology::triangles: return "triangles";
  }
  return "?";
}

Topology parse_topology(const std::string& name) {
  for (const auto t : {Topology::automatic, Topology::grid, Topology::triangles}) {
    if (name == to_string(t)) return t;
  }
  throw InputError("topology: expected auto, grid or triangles, got '" + name + "'");
}

std::string to_string(Bending bending) {
  return bending == Bending::discrete_shells ? "discrete-shells" : "none";
}

Bending parse_bending(const std::string& name) {
  if (name == "none") return Bending::none;
  if (name == "discrete-shells" || name == "discrete_shells") return Bending::discrete_shells;
  throw InputError("bending: expected 'none' or 'discrete-shells', got '" + name + "'");
}

std::string to_string(VolumeModuli rule) {
  return rule == VolumeModuli::homogenised ? "homogenised" : "golec";
}

VolumeModuli parse_volume_moduli(const std::string& name) {
  if (name == "golec") return VolumeModuli::golec;
  if (name == "homogenised") return VolumeModuli::homogenised;
  throw InputError("volume_moduli: expected 'golec' or 'homogenised', got '" + name + "'");
}

namespace {

std::string triangle_topology_name(bool two_ring) {
  return std::string("triangle mesh (edges + bend across edges") + (two_ring ? " + two-ring)" : ")");
}

/// The bending option's checks that need no network: a surface model, not on seed 000's grid.
void check_bending(const NetworkOptions& o, Topology topology) {
  if (o.bending == Bending::none) return;
  if (o.model != ModelType::surface) {
    throw InputError(
        "bending: the discrete-shells term lives on a surface model's triangles, got the volume "
        "model (expected model surface, or bending none)");
  }
  if (topology == Topology::grid) {
    throw InputError(
        "bending: the discrete-shells term replaces the bend springs of the triangle topology; "
        "expected topology 'triangles' or 'auto', got 'grid' (seed 000's grid families)");
  }
}

/// The bending term's network changes: the bend springs go (the hinges carry bending), D recorded.
void apply_bending(BuiltNetwork& built, const NetworkOptions& o) {
  if (o.bending == Bending::none) return;
  auto& springs = built.network.springs;
  springs.erase(std::remove_if(springs.begin(), springs.end(),
                               [](const Spring& s) { return s.family == SpringFamily::bend; }),
                springs.end());
  built.terms.bending_rigidity = plate_bending_rigidity(
      o.stiffness_params.youngs_modulus, built.network.thickness, o.stiffness_params.poisson_ratio);
  built.topology += " without bend springs + discrete-shell hinges (Grinspun et al. 2003)";
}

/// The edge-pair model's network changes: the springs go (the tets' edge-pair energy, which holds
/// their edges' own terms, replaces them), λ and μ recorded.
void apply_edge_pairs(BuiltNetwork& built, const NetworkOptions& o) {
  if (!o.edge_pairs) return;
  if (o.model != ModelType::volume) {
    throw InputError("edge_pairs: the edge-pair model lives on tetrahedra; expected the volume "
                     "model, got the surface model");
  }
  if (o.volume_term) {
    throw InputError("edge_pairs: the edge-pair model is StVK P1 on the tets' edges and reaches "
                     "any ν < 0.5 by itself; expected volume_term = false with it");
  }
  built.terms.edge_pairs = lame_parameters(o.stiffness_params.youngs_modulus,
                                     o.stiffness_params.poisson_ratio);
  built.network.springs.clear();
  built.topology += " coupled in tetrahedron-sharing edge pairs (Kikuuwe et al. 2009: StVK P1 "
                    "on edges, no springs of their own)";
}

/// Stiffness, axial damping and masses: the same for every topology. With the volume term, the
/// springs carry μ (E_s = 2.5μ) and κ = λ − μ is recorded (msm/stiffness/hybrid_moduli.hpp).
void assign_laws_and_masses(BuiltNetwork& built, const NetworkOptions& o) {
  StiffnessParams params = o.stiffness_params;
  if (o.volume_term) {
    if (o.model != ModelType::volume) {
      throw InputError(
          "volume_term: the hybrid volume model needs the volume model (tetrahedra), got the "
          "surface model");
    }
    if (o.stiffness != StiffnessRule::van_gelder) {
      throw InputError("volume_term: the hybrid volume model's springs use the van-gelder rule "
                       "(its κ = λ − μ assumes their λ = μ), got stiffness '" +
                       to_string(o.stiffness) + "'");
    }
    if (o.volume_moduli == VolumeModuli::homogenised) {
      const HomogenisedModuli m = homogenised_moduli(built.network.nodes, built.network.tets,
                                                     params.youngs_modulus, params.poisson_ratio);
      params.youngs_modulus = m.spring_youngs_modulus;
      built.terms.volume_kappa = m.kappa;
      built.network.tet_kappa_factors = m.tet_factors;
      built.topology += " + volume term per tet, (E_s, κ) homogenised on this mesh";
    } else {
      const HybridModuli m = hybrid_moduli(params.youngs_modulus, params.poisson_ratio);
      params.youngs_modulus = m.spring_youngs_modulus;
      built.terms.volume_kappa = m.kappa;
      built.topology += " + volume term per tet (Golec et al. 2020)";
    }
  } else if (o.volume_moduli != VolumeModuli::golec) {
    throw InputError("volume_moduli: '" + to_string(o.volume_moduli) +
                     "' picks the volume term's moduli; expected volume_term = true with it");
  }
  assign_stiffness(built.network, o.stiffness, params);
  for (auto& s : built.network.springs) s.damping = o.axial_damping;
  built.masses = nodal_masses(built.network, o.mass, o.density);
}

}  // namespace

BuiltNetwork build_network(const TetMesh& mesh, const VesselParams& params,
                           const NetworkOptions& o) {
  validate(o.stiffness_params);
  BuiltNetwork built;
  if (o.model == ModelType::volume) {
    check_bending(o, o.topology);
    built.network = build_volume_network(mesh);
    built.topology = "tetrahedral edges (seed 001)";
  } else {
    const TriangleSurface surface = wall_surface(mesh, params, o.surface);
    Topology topology = o.topology;
    if (topology == Topology::automatic) {
      topology = params.style == MeshStyle::structured && o.bending == Bending::none
                     ? Topology::grid
                     : Topology::triangles;
    }
    check_bending(o, topology);
    if (topology == Topology::grid) {
      built.network = build_tube_grid_network(surface, params, params.wall_thickness);
      built.topology = "structured tube grid (seed 000 families)";
    } else {
      built.network = build_triangle_network(surface, params.wall_thickness, o.two_ring);
      built.topology = triangle_topology_name(o.two_ring);
    }
  }
  apply_bending(built, o);
  apply_edge_pairs(built, o);
  assign_laws_and_masses(built, o);
  return built;
}

BuiltNetwork build_surface_network(const TriangleSurface& surface, double thickness,
                                   const NetworkOptions& o) {
  validate(o.stiffness_params);
  if (o.model != ModelType::surface) {
    throw InputError(
        "model: a triangle surface carries only the surface model, got 'volume'; the volume model "
        "needs a tetrahedral .msh mesh");
  }
  if (o.topology == Topology::grid) {
    throw InputError(
        "topology: expected auto or triangles on a triangle surface, got 'grid' (seed 000's grid "
        "needs the generated --structured tube)");
  }
  if (!(thickness > 0) || !std::isfinite(thickness)) {
    throw InputError("wall thickness t: expected a finite value > 0 m, got " +
                     std::to_string(thickness));
  }
  BuiltNetwork built;
  check_bending(o, Topology::triangles);
  built.network = build_triangle_network(surface, thickness, o.two_ring);
  built.topology = triangle_topology_name(o.two_ring);
  apply_bending(built, o);
  apply_edge_pairs(built, o);
  assign_laws_and_masses(built, o);
  return built;
}

}  // namespace vessel::msm
