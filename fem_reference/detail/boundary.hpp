#pragma once
/// Private to fem_reference: the deal.II triangulation of a TetMesh and the correspondence between
/// the two (cells ↔ tets, vertices ↔ nodes, boundary faces ↔ surface triangles), shared by the
/// serial and the distributed solver.
#include <deal.II/grid/tria.h>

#include <array>
#include <vector>

#include "fem_reference/detail/common.hpp"

namespace vessel::fem::detail {

/// The mesh's tets as the coarse cells of `tria`, in TetMesh order (a cell's coarse cell id is
/// its tet index) with the TetMesh nodes as vertices.
void create_coarse_triangulation(const TetMesh& mesh, dl::Triangulation<kDim>& tria);

/// Which TetMesh entity each local cell and vertex of a triangulation made from a TetMesh is.
struct MeshCorrespondence {
  std::vector<int> cell_tet;  ///< per active cell (active_cell_index): its tet (−1: artificial)
  std::vector<int> vertex_node;  ///< per triangulation vertex: its mesh node (−1: artificial only)
  /// Per active cell and face: the TetMesh triangle that face is (−1: interior or unlabelled).
  std::vector<std::array<int, 4>> face_triangle;
  std::vector<int> triangle_tag;  ///< per TetMesh triangle: its surface group's gmsh tag (0: none)
};

/// Matches the non-artificial cells of `tria` (made by create_coarse_triangulation, possibly
/// distributed) to the mesh: tets by coarse cell id (with `global_tet`, the ascending coarse cell
/// id of each of `mesh`'s tets: a distributed rank's part of the whole mesh; empty: the tet index
/// is the coarse cell id), vertices by position (std::logic_error if a
/// vertex is not one of its tet's nodes), boundary faces by their node sets; and sets each
/// boundary face's id to the gmsh tag of the surface group of its triangle (unlabelled: 0).
MeshCorrespondence match_and_tag_boundary(dl::Triangulation<kDim>& tria, const TetMesh& mesh,
                                          const std::vector<int>& global_tet = {});

/// The local vertex (0..3) of `cell` that is mesh node `node` (std::logic_error if none).
unsigned cell_vertex_of_node(const dl::CellAccessor<kDim>& cell, const std::vector<int>& vertex_node,
                             int node);

}  // namespace vessel::fem::detail
