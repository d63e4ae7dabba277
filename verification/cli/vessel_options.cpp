#include "verification/cli/vessel_options.hpp"

#include <iomanip>

#include "meshes/foundation/errors.hpp"

namespace vessel::cli {

void add_vessel_options(CLI::App& cmd, VesselOptions& o) {
  auto& p = o.params;
  cmd.add_option("--vessel", o.vessel, "Vessel shape: 'straight' tube or 180° 'arch'")
      ->check(CLI::IsMember({"straight", "arch"}))
      ->capture_default_str();
  cmd.add_flag("--structured", o.structured,
               "Structured (transfinite, extruded) mesh: circumferential × axial × radial layers "
               "doubled per level. Default: unstructured tets (gmsh Delaunay) of size t/2^level");
  cmd.add_option("--level", p.level, "Refinement level 0..4 (each level halves the element size)")
      ->capture_default_str();
  cmd.add_option("--inner-radius", p.inner_radius, "Inner radius a, metres")->capture_default_str();
  cmd.add_option("--wall-thickness", p.wall_thickness, "Wall thickness t = b − a, metres")
      ->capture_default_str();
  cmd.add_option("--length", p.length, "Straight tube length, metres")->capture_default_str();
  cmd.add_option("--bend-radius", p.bend_radius, "Arch centreline radius, metres")
      ->capture_default_str();
  cmd.add_option("--lumen", o.lumen,
                 "An STL lumen surface (open at its ends, normals outward) instead of --vessel: "
                 "the wall is extruded outward by --wall-thickness; inlet = the largest end, "
                 "outlet = the others; --level subdivides the lumen");
  cmd.add_option("--units", o.units, "Length unit of the --lumen file: m or mm")
      ->check(CLI::IsMember({"m", "mm"}))
      ->capture_default_str();
  cmd.add_option("--cache-dir", o.cache_dir,
                 "Directory of cached generated meshes; default $VESSELVERIFY_CACHE_DIR, else "
                 "$XDG_CACHE_HOME/vesselverify, else ~/.cache/vesselverify");
  cmd.add_flag("--no-cache", o.no_cache, "Always generate; neither read nor write the cache");
  cmd.add_flag("--gmsh-log", o.meshing.verbose, "Show gmsh's own log");
}

void add_mesh_file_option(CLI::App& cmd, VesselOptions& o) {
  cmd.add_option("--input", o.mesh_file,
                 "A vessel mesh (.msh 2.2/4.1 ASCII, linear tets, groups inlet, outlet, "
                 "inner_wall, outer_wall, wall) instead of --vessel, used as given (level 0)");
}

VesselParams resolve(VesselOptions& o) {
  o.params.kind = o.vessel == "arch" ? VesselKind::arch : VesselKind::straight;
  o.params.style = o.structured ? MeshStyle::structured : MeshStyle::unstructured;
  if (!o.mesh_file.empty() && !o.lumen.empty()) {
    throw InputError("--input and --lumen: expected one vessel file, got both");
  }
  if (!o.mesh_file.empty() || !o.lumen.empty()) {
    if (o.structured) throw InputError("--structured: a vessel from a file has its own mesh");
    o.params.kind = o.mesh_file.empty() ? VesselKind::lumen : VesselKind::mesh_file;
    o.params.file = o.mesh_file.empty() ? o.lumen : o.mesh_file;
    o.params.file_scale = o.units == "mm" ? 1e-3 : 1.0;
    o.params.style = MeshStyle::unstructured;
  }
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
