#pragma once
/// The guidewire load's records after a scene's run: the wire's rigid solve and, for compliant
/// coupling, each model's own contact force (GuidewireSolver::coupled_force with the model's
/// wall compliance C_v = d/F, d its work-conjugate indentation under the rigid wire's patch load
/// F), beside the reference's (C_ref from the reference's indentation on the same nodal loads).
/// Valid for linear walls: C is measured once, at the rigid wire's force, and the field error
/// with each wall under its own force is the rigid force's field scaled (scaled_relative_l2).
#include <nlohmann/json_fwd.hpp>
#include <ostream>
#include <vector>

#include "verification/guidewire/guidewire_outcome.hpp"
#include "verification/harness/outcome.hpp"

namespace vessel {

/// The scene's guidewire outcome from its run's outcomes (every ok static outcome with an
/// indentation; the scene's EI first, then each of the spec's stiffness_sweep).
GuidewireOutcome couple_guidewire(const Scene& scene, const std::vector<ModelOutcome>& outcomes);

/// The stiffnesses (N·m²) a guidewire scene's coupling runs at: its wire's EI, then each of its
/// stiffness_sweep that differs from it by more than 1e-3 (relative).
std::vector<double> guidewire_stiffnesses(const GuidewireSpec& spec);

/// Whether the series springs leave the reference's wall at `rigid`'s EI dented (C_ref·F_ref) no
/// deeper than `wall_thickness` (m). Deeper, no linear wall holds the wire: the contact coupling
/// does not solve that EI, and the compliant rows at it are the springs' arithmetic, not a state
/// of the vessel (marked in summary.md, results.json's reference_within_wall and the report).
bool reference_within_wall(const GuidewireRigid& rigid, double wall_thickness);

/// summary.md's guidewire section: the wire against the rigid lumen per EI, and the coupled
/// contact force of each model beside the reference's (mN), with the contact displacements (mm).
void write_guidewire_markdown(std::ostream& out, const GuidewireOutcome& g);

/// results.json's "guidewire" object.
nlohmann::json guidewire_json(const GuidewireOutcome& g);

}  // namespace vessel
