#include "meshes/mesh_cache.hpp"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

#include "meshes/foundation/content_hash.hpp"
#include "meshes/foundation/content_store.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/lumen_mesh.hpp"
#include "meshes/msh_io.hpp"

namespace vessel {

namespace fs = std::filesystem;

namespace {

/// Bumped whenever the generator's output for the same params changes.
constexpr int kGeneratorVersion = 3;
/// Bumped whenever the lumen extrusion's output for the same file and params changes.
constexpr int kLumenGeneratorVersion = 2;  // 2: holes in the wall refused (steepness)

/// The hash of a file's bytes (InputError naming it if it cannot be read).
std::string file_hash(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!fs::exists(path)) throw InputError(path.string() + ": lumen file not found");
  if (!in) throw InputError(path.string() + ": cannot open lumen file");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return ContentHash().text(bytes.str()).hex();
}

std::string exact(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

fs::path default_cache_dir() {
  if (const char* dir = std::getenv("VESSELVERIFY_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return fs::path(xdg) / "vesselverify";
  }
  if (const char* home = std::getenv("HOME"); home && *home) {
    return fs::path(home) / ".cache" / "vesselverify";
  }
  return ".vesselverify-cache";
}

std::string mesh_cache_key(const VesselParams& p) {
  if (p.kind == VesselKind::lumen) {
    std::string key =
        "vesselverify-lumen-wall generator=" + std::to_string(kLumenGeneratorVersion) +
        " file=" + file_hash(p.file) + " scale=" + exact(p.file_scale) +
        " t=" + exact(p.wall_thickness) + " level=" + std::to_string(p.level);
    if (p.listed_ends.given()) {  // they choose the inlet and which loops are ends
      const auto point = [](const Vec3& c) {
        return exact(c.x()) + "," + exact(c.y()) + "," + exact(c.z());
      };
      key += " inlet=" + point(p.listed_ends.inlet) + " outlets=";
      for (const Vec3& c : p.listed_ends.outlets) key += point(c) + ";";
    }
    return key;
  }
  if (p.kind == VesselKind::mesh_file)
    throw InputError(p.file.string() + ": a mesh file is not cached");
  std::string key = "vesselverify-mesh generator=" + std::to_string(kGeneratorVersion) +
                    " gmsh=" + gmsh_version() + " kind=" + to_string(p.kind) +
                    " style=" + to_string(p.style) + " level=" + std::to_string(p.level) +
                    " a=" + exact(p.inner_radius) + " t=" + exact(p.wall_thickness);
  key += p.kind == VesselKind::straight ? " L=" + exact(p.length) : " R=" + exact(p.bend_radius);
  return key;
}

TetMesh load_or_generate_vessel(const VesselParams& params, const fs::path& cache_dir,
                                const MeshingOptions& options, MeshSource* source) {
  validate(params);
  MeshSource info;
  const auto t0 = std::chrono::steady_clock::now();
  if (params.kind == VesselKind::mesh_file) {  // used as given: nothing to cache
    TetMesh mesh = read_msh(params.file);
    require_vessel_groups(mesh, params.file.string());
    info.seconds = seconds_since(t0);
    if (source) *source = info;
    return mesh;
  }
  // As stored, so this run and a later one reading the cache solve the same problem.
  const auto generate = [&] {
    return as_stored(params.kind == VesselKind::lumen
                         ? lumen_wall_mesh({params.file, params.wall_thickness, params.file_scale,
                                            params.level, params.listed_ends})
                         : generate_vessel_mesh(params, options));
  };
  if (cache_dir.empty()) {
    TetMesh mesh = generate();
    info.seconds = seconds_since(t0);
    if (source) *source = info;
    return mesh;
  }
  // The payload: the generation's seconds on its first line, then the mesh as .msh text.
  ContentStore store(cache_dir / "meshes", &std::cerr, "mesh cache");
  const std::string key = mesh_cache_key(params);
  info.path = store.entry_path(key);
  TetMesh mesh;
  store.lookup(
      key,
      [&](std::string_view payload) {
        std::istringstream in{std::string(payload)};
        double generated_seconds = 0.0;
        in >> generated_seconds;
        in.ignore(1);
        mesh = parse_msh(in, info.path.string());
        require_vessel_groups(mesh, info.path.string());
        info.cache_hit = true;
        return generated_seconds;
      },
      [&] {
        mesh = generate();
        std::ostringstream out;
        out.precision(17);
        out << seconds_since(t0) << "\n";
        write_msh(out, mesh);
        return out.str();
      });
  info.seconds = seconds_since(t0);
  if (source) *source = info;
  return mesh;
}

}  // namespace vessel
