#pragma once
/// What a scene with a guidewire load records (verification/harness/guidewire_coupling.hpp): the
/// wire against the rigid lumen and, with compliant coupling, each model's own contact force
/// beside the reference's. Plain data; SI inside, mN and mm where the names say so.
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "verification/guidewire_spec.hpp"

namespace vessel {

/// The wire at one bending stiffness against the rigid lumen.
struct GuidewireRigid {
  double bending_stiffness = 0.0;  ///< EI, N·m²
  GuidewireSolution solution;
  double wire_compliance = 0.0;    ///< −dδ/dF at the contact, m/N (compliant coupling only)
};

/// One model (at one ν and level) coupled with the wire at one EI.
struct GuidewireCouplingRow {
  std::string model;
  double poisson_ratio = 0.0;
  int level = 0;
  double bending_stiffness = 0.0;    ///< EI, N·m²
  double wall_compliance = 0.0;      ///< C_v: the model's indentation per unit patch force, m/N
  double reference_compliance = 0.0;  ///< C_ref: the reference's, on the model's loaded nodes, m/N
  double force_mN = 0.0;              ///< the model's coupled contact force
  double reference_force_mN = 0.0;    ///< the reference's
  double displacement_mm = 0.0;       ///< the model's contact displacement C_v·F
  double reference_displacement_mm = 0.0;  ///< C_ref·F_ref
  /// The wire's contact node in the model's coupled state, m (it slides along the wall as it gives).
  Vec3 contact_point = Vec3::Zero();
  bool ok = false;
  std::string failure;
};

struct GuidewireOutcome {
  GuidewireSpec spec;
  double patch_radius = 0.0;  ///< m: a coupled contact that slid farther has left the patch
  std::vector<GuidewireRigid> rigid;       ///< the scene's EI first, then the stiffness sweep's
  std::vector<GuidewireCouplingRow> rows;  ///< compliant coupling: per EI, per model outcome
};

}  // namespace vessel
