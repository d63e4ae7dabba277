#pragma once
/// Generated meshes cached by everything that determines them, so each vessel and level is meshed
/// once: entries of the checksummed content store (meshes/foundation/content_store.hpp) in the
/// cache directory's `meshes/`, each holding its key and the mesh as .msh text.
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
struct MeshSource {
  std::filesystem::path path;  ///< the cache entry (empty if caching was off)
  bool cache_hit = false;
  double seconds = 0.0;        ///< time to generate (miss) or to read (hit)
};

/// Returns the cached mesh for params, generating and caching it (atomically) on a miss or when
/// the entry is corrupt or cannot be read (reported on std::cerr). An empty cache_dir disables caching. A lumen vessel is extruded
/// from its STL (meshes/lumen_mesh.hpp), cached by a hash of the file's bytes, the unit scale, the
/// thickness and the level; a mesh file is read as given (read_msh, the five groups required),
/// never cached.
TetMesh load_or_generate_vessel(const VesselParams& params,
                                const std::filesystem::path& cache_dir,
                                const MeshingOptions& options, MeshSource* source = nullptr);

}  // namespace vessel
