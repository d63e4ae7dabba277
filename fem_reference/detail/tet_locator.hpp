#pragma once
/// Point location in a TetMesh lives in meshes/tet_locator.hpp (the harness checks user networks'
/// nodes with it too); the FEM's private names for it.
#include "meshes/tet_locator.hpp"

namespace vessel::fem::detail {
using vessel::min_barycentric;
using vessel::TetLocator;
}  // namespace vessel::fem::detail
