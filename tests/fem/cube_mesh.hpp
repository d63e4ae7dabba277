#pragma once
/// A structured tetrahedral mesh of the cube [0, L]³ for the finite-strain tests: n³ hexahedra,
/// each split into the six Kuhn tets (paths from corner 000 to 111), which is conforming. Surface
/// groups x0, x1, y0, y1, z0, z1 (the faces at x = 0, x = L, ...), volume group "wall".
#include <algorithm>
#include <array>
#include <map>
#include <string>

#include "meshes/tet_mesh.hpp"

namespace vessel::test {

inline TetMesh cube_mesh(int n, double L) {
  TetMesh m;
  auto node = [n](int i, int j, int k) { return (k * (n + 1) + j) * (n + 1) + i; };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.nodes.emplace_back(L * i / n, L * j / n, L * k / n);
  const std::array<std::array<int, 3>, 6> orders{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        for (const auto& order : orders) {
          std::array<int, 3> c{i, j, k};
          Tet t;
          t[0] = node(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[order[s]];
            t[s + 1] = node(c[0], c[1], c[2]);
          }
          const auto& x = m.nodes;
          if (signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) < 0) std::swap(t[2], t[3]);
          m.tets.push_back(t);
        }
      }
    }
  }
  // Boundary triangles: tet faces that occur once, oriented away from the tet's fourth node.
  std::map<std::array<int, 3>, std::pair<int, Triangle>> faces;  // sorted nodes → (count, face)
  for (const Tet& t : m.tets) {
    for (int f = 0; f < 4; ++f) {
      Triangle tri{t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]};
      const Vec3 nrm = (m.nodes[tri[1]] - m.nodes[tri[0]]).cross(m.nodes[tri[2]] - m.nodes[tri[0]]);
      if (nrm.dot(m.nodes[t[f]] - m.nodes[tri[0]]) > 0) std::swap(tri[1], tri[2]);
      std::array<int, 3> key{tri[0], tri[1], tri[2]};
      std::sort(key.begin(), key.end());
      auto& e = faces[key];
      ++e.first;
      e.second = tri;
    }
  }
  const std::array<std::string, 6> names{"x0", "x1", "y0", "y1", "z0", "z1"};
  for (int g = 0; g < 6; ++g) m.groups.push_back({names[g], 2, g + 1, {}});
  for (const auto& [key, e] : faces) {
    if (e.first != 1) continue;
    const Vec3 c = (m.nodes[key[0]] + m.nodes[key[1]] + m.nodes[key[2]]) / 3.0;
    int g = -1;
    for (int a = 0; a < 3 && g < 0; ++a) {
      if (c[a] < 1e-9 * L) g = 2 * a;
      if (c[a] > L * (1 - 1e-9)) g = 2 * a + 1;
    }
    m.groups[g].elements.push_back(static_cast<int>(m.triangles.size()));
    m.triangles.push_back(e.second);
  }
  PhysicalGroup wall{"wall", 3, 10, {}};
  for (int t = 0; t < static_cast<int>(m.tets.size()); ++t) wall.elements.push_back(t);
  m.groups.push_back(wall);
  return m;
}

}  // namespace vessel::test
