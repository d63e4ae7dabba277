#include "verification/cli/vessel_options.hpp"

#include <iomanip>

namespace vessel::cli {

void add_vessel_options(CLI::App& cmd, VesselOptions& o) {
  auto& p = o.params;
  cmd.add_option("--vessel", o.vessel, "Vessel shape: 'straight' tube or 180° 'arch'")
      ->check(CLI::IsMember({"straight", "arch"}))
      ->capture_default_str();
  cmd.add_flag("--structured", o.structured,
               "Structured (transfinite, extruded) mesh: circumferential × axial × radial layers "
               "doubled per level. Default: unstructured tets (gmsh HXT) of size t/2^level");
  cmd.add_option("--level", p.level, "Refinement level 0..4 (each level halves the element size)")
      ->capture_default_str();
  cmd.add_option("--inner-radius", p.inner_radius, "Inner radius a, metres")->capture_default_str();
  cmd.add_option("--wall-thickness", p.wall_thickness, "Wall thickness t = b − a, metres")
      ->capture_default_str();
  cmd.add_option("--length", p.length, "Straight tube length, metres")->capture_default_str();
  cmd.add_option("--bend-radius", p.bend_radius, "Arch centreline radius, metres")
      ->capture_default_str();
  cmd.add_option("--cache-dir", o.cache_dir,
                 "Directory of cached generated meshes (env VESSELVERIFY_CACHE_DIR)")
      ->capture_default_str();
  cmd.add_flag("--no-cache", o.no_cache, "Always generate; neither read nor write the cache");
  cmd.add_flag("--gmsh-log", o.meshing.verbose, "Show gmsh's own log");
}

VesselParams resolve(VesselOptions& o) {
  o.params.kind = o.vessel == "arch" ? VesselKind::arch : VesselKind::straight;
  o.params.style = o.structured ? MeshStyle::structured : MeshStyle::unstructured;
  validate(o.params);
  return o.params;
}

TetMesh mesh_vessel(VesselOptions& o, std::ostream& log, MeshSource* source) {
  const VesselParams params = resolve(o);
  log << "meshing " << describe(params) << " ..." << std::flush;
  MeshSource info;
  TetMesh mesh =
      load_or_generate_vessel(params, o.no_cache ? std::filesystem::path() : o.cache_dir,
                              o.meshing, &info);
  log << std::fixed << std::setprecision(2) << (info.cache_hit ? " read from cache in " : " generated in ")
      << info.seconds << " s" << std::defaultfloat << "\n";
  if (!info.path.empty()) log << "  cached mesh: " << info.path.string() << "\n";
  if (source) *source = info;
  return mesh;
}

}  // namespace vessel::cli
