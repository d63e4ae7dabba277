#include "msm/model/build_network.hpp"

#include <cmath>

#include "meshes/errors.hpp"

namespace vessel::msm {

BuiltNetwork build_network(const TetMesh& mesh, const VesselParams& params,
                           const NetworkOptions& o) {
  validate(o.stiffness_params);
  BuiltNetwork built;
  if (o.model == "volume") {
    built.network = build_volume_network(mesh);
    built.topology = "tetrahedral edges (seed 001)";
  } else if (o.model == "surface") {
    const TriangleSurface surface = wall_surface(mesh, params, parse_wall_surface(o.surface));
    std::string topology = o.topology;
    if (topology == "auto") topology = params.style == MeshStyle::structured ? "grid" : "triangles";
    if (topology == "grid") {
      built.network = build_tube_grid_network(surface, params, params.wall_thickness);
      built.topology = "structured tube grid (seed 000 families)";
    } else if (topology == "triangles") {
      built.network = build_triangle_network(surface, params.wall_thickness, o.two_ring);
      built.topology = std::string("triangle mesh (edges + bend across edges") +
                       (o.two_ring ? " + two-ring)" : ")");
    } else {
      throw InputError("topology: expected auto, grid or triangles, got '" + o.topology + "'");
    }
  } else {
    throw InputError("model: expected 'surface' or 'volume', got '" + o.model + "'");
  }
  assign_stiffness(built.network, o.stiffness, o.stiffness_params);
  for (auto& s : built.network.springs) s.damping = o.axial_damping;
  built.masses = nodal_masses(built.network, o.mass, o.density);
  return built;
}

BuiltNetwork build_surface_network(const TriangleSurface& surface, double thickness,
                                   const NetworkOptions& o) {
  validate(o.stiffness_params);
  if (o.model != "surface") {
    throw InputError("model: a triangle surface carries only the surface model, got '" + o.model +
                     "'; the volume model needs a tetrahedral .msh mesh");
  }
  if (o.topology != "auto" && o.topology != "triangles") {
    throw InputError("topology: expected auto or triangles on a triangle surface, got '" +
                     o.topology + "' (seed 000's grid needs the generated --structured tube)");
  }
  if (!(thickness > 0) || !std::isfinite(thickness)) {
    throw InputError("wall thickness t: expected a finite value > 0 m, got " +
                     std::to_string(thickness));
  }
  BuiltNetwork built;
  built.network = build_triangle_network(surface, thickness, o.two_ring);
  built.topology = std::string("triangle mesh (edges + bend across edges") +
                   (o.two_ring ? " + two-ring)" : ")");
  assign_stiffness(built.network, o.stiffness, o.stiffness_params);
  for (auto& s : built.network.springs) s.damping = o.axial_damping;
  built.masses = nodal_masses(built.network, o.mass, o.density);
  return built;
}

}  // namespace vessel::msm
