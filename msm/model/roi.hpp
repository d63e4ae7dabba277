#pragma once
/// Region-of-interest mass-spring models (issue #7): only the part of the vessel around the
/// contact is simulated. Nodes farther than R from the contact point are held at rest, and their
/// unknowns are removed from the system (not merely fixed by identity rows, which would keep the
/// full matrix, its fill-in and every spring's Hessian block), so the solve's cost scales with the
/// region, not the vessel. The error is still measured against the full FEM reference at every node
/// of the full model (the removed nodes' displacement is zero), so error and speed-up against R
/// are honest.
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

/// Per node: 1 if it lies farther than `radius` (m) from `centre`, else 0.
std::vector<char> nodes_beyond(const std::vector<Vec3>& nodes, const Vec3& centre, double radius);

/// A network cut down to a region: the nodes that still move (any free dof, within R) and the held
/// nodes one spring away from them (the region's boundary ring, all dofs fixed); springs with at
/// least one moving end (a spring between two held nodes exerts no force on a moving node); tets
/// with at least one moving node (for the volume term); with carry_triangles, the triangles with a
/// moving node and those sharing an edge with them, their nodes kept (every hinge of the bending
/// term with a moving node lies between two of them).
struct RoiNetwork {
  SpringNetwork network;        ///< kept nodes and springs, renumbered
  std::vector<int> full_index;  ///< per kept node: its index in the full network
  std::size_t moving_nodes = 0;
};

/// `held[i]`: node i of the full problem is held (beyond R, or all its dofs fixed already).
RoiNetwork restrict_network(const SpringNetwork& full, const std::vector<char>& held,
                            bool carry_triangles = false);

/// The full problem restricted to the region's network (rest, loads, masses and fixed dofs of
/// the kept nodes; the ring held), on `form` (a model of roi.network). Loads on held nodes are
/// carried by the supports, as they would be on the full problem with those nodes fixed.
Problem restrict_problem(const Problem& full, const RoiNetwork& roi, const std::vector<char>& held,
                         const Form& form);

/// The full problem's held nodes for a region of radius R about `centre`: beyond R, or with all
/// three dofs already fixed. Throws std::runtime_error if no node moves (R smaller than the
/// node spacing around the contact).
std::vector<char> held_nodes(const Problem& full, const Vec3& centre, double radius);

}  // namespace vessel::msm
