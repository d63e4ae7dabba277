#pragma once
/// Command-line options shared by every subcommand that builds a vessel mesh.
#include <CLI/CLI.hpp>
#include <filesystem>

#include "meshes/mesh_cache.hpp"

namespace vessel::cli {

struct VesselOptions {
  VesselParams params;
  std::string vessel = "straight";
  bool structured = false;
  std::filesystem::path mesh_file;  ///< --input of `fem`: a .msh vessel used as given
  std::filesystem::path lumen;      ///< --lumen: an STL lumen extruded by --wall-thickness
  std::string units = "m";          ///< --units of the lumen file: m or mm
  std::filesystem::path cache_dir = default_cache_dir();
  bool no_cache = false;
  MeshingOptions meshing;
};

/// Adds --vessel, --structured, --level, --inner-radius, --wall-thickness, --length,
/// --bend-radius, --lumen, --units, --cache-dir, --no-cache, --gmsh-log to `cmd`.
void add_vessel_options(CLI::App& cmd, VesselOptions& options);

/// Adds --input FILE.msh: a vessel mesh with the five groups, used as given (level 0).
void add_mesh_file_option(CLI::App& cmd, VesselOptions& options);

/// Completes params from the parsed strings and validates them (InputError if out of range). A
/// --lumen or --input file makes the vessel a file vessel (meshes/lumen_mesh.hpp).
VesselParams resolve(VesselOptions& options);

/// Meshes (or loads from the cache) the vessel, printing progress and timing to `log`.
TetMesh mesh_vessel(VesselOptions& options, std::ostream& log, MeshSource* source = nullptr);

}  // namespace vessel::cli
