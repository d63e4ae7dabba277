#pragma once
/// Small triangle surfaces for the bending-term tests: a closed cylinder (structured, quads split
/// by one diagonal), a flat grid of right triangles, and a flat patch of equilateral triangles.
#include <cmath>
#include <numbers>

#include "meshes/stl_io.hpp"

namespace vessel::msm::test {

/// Cylinder of radius R (m) about the z axis from z = 0 to L: n_circ nodes per ring (node i at
/// angle 2πi/n_circ), n_axial + 1 rings; node (i, j) = j·n_circ + i. Each quad is split along
/// (i, j)–(i+1, j+1); triangles oriented with outward normals.
inline TriangleSurface cylinder_surface(double R, double L, int n_circ, int n_axial) {
  TriangleSurface s;
  for (int j = 0; j <= n_axial; ++j) {
    for (int i = 0; i < n_circ; ++i) {
      const double phi = 2 * std::numbers::pi * i / n_circ;
      s.nodes.emplace_back(R * std::cos(phi), R * std::sin(phi), L * j / n_axial);
    }
  }
  auto id = [n_circ](int i, int j) { return j * n_circ + (i % n_circ); };
  for (int j = 0; j < n_axial; ++j) {
    for (int i = 0; i < n_circ; ++i) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  s.source_node.assign(s.nodes.size(), -1);
  return s;
}

/// Flat sheet in z = 0 of nx × ny rectangles a × b (m) from the origin, each split along its
/// diagonal (i, j)–(i+1, j+1).
inline TriangleSurface grid_sheet(double a, double b, int nx, int ny) {
  TriangleSurface s;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) s.nodes.emplace_back(a * i, b * j, 0.0);
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  s.source_node.assign(s.nodes.size(), -1);
  return s;
}

/// Flat rhombic patch in z = 0 of equilateral triangles of side a (m): lattice vectors at `angle`
/// and angle + 60° (rad) from the x axis, (nx + 1) × (ny + 1) nodes.
inline TriangleSurface equilateral_sheet(double a, int nx, int ny, double angle) {
  TriangleSurface s;
  const Vec3 u(a * std::cos(angle), a * std::sin(angle), 0.0);
  const Vec3 v(a * std::cos(angle + std::numbers::pi / 3),
               a * std::sin(angle + std::numbers::pi / 3), 0.0);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) s.nodes.push_back(i * u + j * v);
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      s.triangles.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
      s.triangles.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  s.source_node.assign(s.nodes.size(), -1);
  return s;
}

}  // namespace vessel::msm::test
