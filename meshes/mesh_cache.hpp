#pragma once
/// Generated meshes cached on disk by a hash of everything that determines them, so each vessel
/// and level is meshed once.
#include <filesystem>
#include <string>

#include "meshes/gmsh_vessel.hpp"

namespace vessel {

/// Where cached meshes go by default: $VESSELVERIFY_CACHE_DIR, else $XDG_CACHE_HOME/vesselverify,
/// else ~/.cache/vesselverify, else ./.vesselverify-cache.
std::filesystem::path default_cache_dir();

/// The canonical description of the params that the cache key hashes (all lengths at full
/// precision, the style, the level, the generator and gmsh versions; for a lumen the hash of the
/// STL's bytes instead of the shape parameters). InputError for a mesh file (never cached).
std::string mesh_cache_key(const VesselParams& params);
/// File name in the cache: "<kind>-<style>-L<level>-<16 hex digits of the key's hash>.msh"
/// ("lumen-<file stem>-L<level>-<hash>.msh" for a lumen).
std::string mesh_cache_file_name(const VesselParams& params);

struct MeshSource {
  std::filesystem::path path;  ///< cached .msh (empty if caching was off)
  bool cache_hit = false;
  double seconds = 0.0;        ///< time to generate (miss) or to read (hit)
};

/// Returns the cached mesh for params, generating and caching it (atomically) on a miss or when
/// the cached file cannot be read. An empty cache_dir disables caching. A lumen vessel is extruded
/// from its STL (meshes/lumen_mesh.hpp), cached by a hash of the file's bytes, the unit scale, the
/// thickness and the level; a mesh file is read as given (read_msh, the five groups required),
/// never cached.
TetMesh load_or_generate_vessel(const VesselParams& params,
                                const std::filesystem::path& cache_dir,
                                const MeshingOptions& options, MeshSource* source = nullptr);

}  // namespace vessel
