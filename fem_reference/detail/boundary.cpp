#include "fem_reference/detail/boundary.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace vessel::fem::detail {

void create_coarse_triangulation(const TetMesh& mesh, dl::Triangulation<kDim>& tria) {
  std::vector<dl::Point<kDim>> vertices;
  vertices.reserve(mesh.nodes.size());
  for (const auto& x : mesh.nodes) vertices.emplace_back(x.x(), x.y(), x.z());
  std::vector<dl::CellData<kDim>> cells(mesh.tets.size(), dl::CellData<kDim>(4));
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (unsigned v = 0; v < 4; ++v) cells[t].vertices[v] = static_cast<unsigned>(mesh.tets[t][v]);
    cells[t].material_id = 0;
  }
  tria.create_triangulation(vertices, cells, dl::SubCellData());
}

namespace {

using Face = std::array<int, 3>;
Face sorted_face(int a, int b, int c) {
  Face f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

std::vector<int> triangle_group_tags(const TetMesh& mesh) {
  std::vector<int> tag(mesh.triangles.size(), 0);
  for (const auto& g : mesh.groups) {
    if (g.dim != 2) continue;
    for (int e : g.elements) tag[static_cast<std::size_t>(e)] = g.tag;
  }
  return tag;
}

/// The node of `tet` at x (std::logic_error if none is within round-off).
int node_at(const TetMesh& mesh, const Tet& tet, const dl::Point<kDim>& x) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (int n : tet) {
    const double d = (mesh.nodes[static_cast<std::size_t>(n)] - to_vec3(x)).norm();
    if (d < best_d) best_d = d, best = n;
  }
  if (best_d > 1e-12 * (1.0 + x.norm())) {
    throw std::logic_error("triangulation cell vertex does not match its tet's nodes");
  }
  return best;
}

}  // namespace

MeshCorrespondence match_and_tag_boundary(dl::Triangulation<kDim>& tria, const TetMesh& mesh,
                                          const std::vector<int>& global_tet) {
  MeshCorrespondence m;
  m.triangle_tag = triangle_group_tags(mesh);
  std::map<Face, int> face_to_triangle;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    face_to_triangle[sorted_face(tri[0], tri[1], tri[2])] = static_cast<int>(t);
  }
  m.cell_tet.assign(tria.n_active_cells(), -1);
  m.face_triangle.assign(tria.n_active_cells(), {-1, -1, -1, -1});
  m.vertex_node.assign(tria.n_vertices(), -1);
  for (const auto& cell : tria.active_cell_iterators()) {
    if (cell->is_artificial()) continue;
    auto coarse = static_cast<std::size_t>(cell->id().get_coarse_cell_id());
    if (!global_tet.empty()) {
      const auto it =
          std::lower_bound(global_tet.begin(), global_tet.end(), static_cast<int>(coarse));
      coarse = it != global_tet.end() && *it == static_cast<int>(coarse)
                   ? static_cast<std::size_t>(it - global_tet.begin())
                   : mesh.tets.size();
    }
    if (coarse >= mesh.tets.size()) throw std::logic_error("triangulation cell with unknown tet");
    const auto idx = cell->active_cell_index();
    const auto& tet = mesh.tets[coarse];
    m.cell_tet[idx] = static_cast<int>(coarse);
    for (unsigned v = 0; v < 4; ++v)
      m.vertex_node[cell->vertex_index(v)] = node_at(mesh, tet, cell->vertex(v));
    for (unsigned f = 0; f < cell->n_faces(); ++f) {
      const auto face = cell->face(f);
      if (!face->at_boundary()) continue;
      const auto it = face_to_triangle.find(sorted_face(m.vertex_node[face->vertex_index(0)],
                                                        m.vertex_node[face->vertex_index(1)],
                                                        m.vertex_node[face->vertex_index(2)]));
      if (it == face_to_triangle.end()) continue;  // unlabelled boundary: free, id 0
      m.face_triangle[idx][f] = it->second;
      face->set_boundary_id(static_cast<dl::types::boundary_id>(
          m.triangle_tag[static_cast<std::size_t>(it->second)]));
    }
  }
  return m;
}

unsigned cell_vertex_of_node(const dl::CellAccessor<kDim>& cell, const std::vector<int>& vertex_node,
                             int node) {
  for (unsigned v = 0; v < 4; ++v) {
    if (vertex_node[cell.vertex_index(v)] == node) return v;
  }
  throw std::logic_error("mesh node " + std::to_string(node) + " is not a vertex of the cell");
}

}  // namespace vessel::fem::detail
