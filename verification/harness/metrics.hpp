#pragma once
/// Every error quantity of a model state against the reference at the model's own nodes: the
/// nodal statistics (seed 000's max, mean, standard deviation, RMS, plus the relative L2 error),
/// the quantities a budget may name (contact point, field, patch, indentation, reaction), the wall
/// profile through the QoI point, an outside model's largest edge strain and the natural
/// frequencies' ratios. Inputs in metres; errors returned in millimetres (reaction in mN).
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "meshes/vtu_io.hpp"
#include "verification/harness/outcome.hpp"
#include "verification/scene.hpp"

namespace vessel {

/// Statistics of e_i = model[i] − reference[i] (std::invalid_argument if the sizes differ or
/// are zero).
ErrorStatistics compare_displacements(const std::vector<Vec3>& model,
                                      const std::vector<Vec3>& reference);

/// The budget quantities of a model state: displacements u_model and u_ref (m) at the model's
/// nodes, its QoI node index and point, `loads` the model's nodal loads (N, per node; empty
/// unless the load is a contact: no indentation or reaction then), `history` the dynamic history
/// (empty for static models). The patch error is computed when budget.quantity is patch.
QuantityErrors quantity_errors(const Budget& budget, const std::vector<Vec3>& nodes,
                               const std::vector<Vec3>& u_model, const std::vector<Vec3>& u_ref,
                               std::size_t qoi, const Vec3& qoi_point,
                               const std::vector<Vec3>& loads, const History& history);

/// The budget quantity's value among the quantity errors (NaN if not computable).
double budget_quantity_error(const QuantityErrors& q, BudgetQuantity quantity);

/// The model nodes on the wall line through the QoI point: within a third of the level's cell size
/// of the QoI's angle around the centreline, at the radius nearest the QoI's; sorted by arc length.
std::vector<std::size_t> wall_line(const VesselParams& v, int level,
                                   const std::vector<Vec3>& nodes, const Vec3& qoi);

/// Radial displacements (mm) of model and reference at the nodes of `line`, by arc length (mm).
WallProfile wall_profile(const VesselParams& v, const std::vector<Vec3>& nodes,
                         const std::vector<std::size_t>& line, const std::vector<Vec3>& u_model,
                         const std::vector<Vec3>& u_ref);

/// The largest |Δl|/l over the edges of the exchange cells under displacements u: the strain an
/// outside model's answer implies, since its own elements are not known.
double largest_edge_strain(const std::vector<Vec3>& nodes, const VtuCells& cells,
                           const std::vector<Vec3>& u);

/// f_model,k / f_reference,k mode by mode (modes paired by rank, both sorted ascending); as many
/// as both have, 0 where the reference's frequency is 0.
std::vector<double> frequency_ratios(const ModalOutcome& model, const ModalOutcome& reference);

}  // namespace vessel
