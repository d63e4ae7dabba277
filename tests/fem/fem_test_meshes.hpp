#pragma once
/// Small vessel meshes shared by the FEM tests (generated once per test executable).
#include "meshes/gmsh_vessel.hpp"

namespace vessel::test {

/// A short structured straight tube (a = 3 mm, t = 1 mm, L = 1 mm): plane strain with roller
/// ends makes the length irrelevant to Lamé's solution, and a short tube keeps P2 DoFs small.
inline VesselParams short_tube(int level) {
  VesselParams p;
  p.length = 1e-3;
  p.style = MeshStyle::structured;
  p.level = level;
  return p;
}

/// The mesh of short_tube(level), level 0..3, generated on first use.
inline const TetMesh& short_tube_mesh(int level) {
  static TetMesh meshes[4];
  static bool made[4] = {false, false, false, false};
  if (!made[level]) {
    meshes[level] = generate_vessel_mesh(short_tube(level));
    made[level] = true;
  }
  return meshes[level];
}

}  // namespace vessel::test
