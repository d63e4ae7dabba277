#pragma once
/// What a scene with a guidewire load records (verification/harness/guidewire_coupling.hpp): the
/// wire against the rigid lumen and, with compliant coupling, each model's own contact force
/// beside the reference's. Plain data; SI inside, mN and mm where the names say so.
#include <limits>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "verification/guidewire/guidewire_spec.hpp"

namespace vessel {

/// The wire at one bending stiffness against the rigid lumen.
struct GuidewireRigid {
  double bending_stiffness = 0.0;  ///< EI, N·m²
  GuidewireSolution solution;
  double wire_compliance = 0.0;    ///< −dδ/dF at the contact, m/N (compliant coupling only)
  /// The continuum wire's force at this EI (guidewire_load.hpp's continuum_wire), N; NaN when
  /// the wire's pose has none.
  double continuum_force = std::numeric_limits<double>::quiet_NaN();
  /// Compliant coupling: the wire coupled with the reference's wall, its compliance C_ref read on
  /// the loaded nodes of one coupling row (`reference_row`: the finest level's first row at the
  /// first ν, the walls report.html draws); empty centreline when there is none.
  std::vector<Vec3> reference_centreline;  ///< m, clamp to tip
  double reference_force = 0.0;            ///< N
  double reference_compliance = 0.0;       ///< m/N
  std::string reference_row;               ///< "model, ν, level" of that row
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
  /// The model's relative L2 field error at the rigid wire's force (both walls under the same
  /// load: results.json's error), and with each wall under its own coupled force (linear walls:
  /// the model's field scaled by F/F_rigid against the reference's by F_ref/F_rigid); NaN when
  /// the outcome has no field norms.
  double field_relative_l2_rigid = std::numeric_limits<double>::quiet_NaN();
  double field_relative_l2 = std::numeric_limits<double>::quiet_NaN();
  /// The wire's contact node in the model's coupled state, m (it slides along the wall as it gives).
  Vec3 contact_point = Vec3::Zero();
  bool ok = false;
  std::string failure;
};

struct GuidewireOutcome {
  GuidewireSpec spec;
  double patch_radius = 0.0;  ///< m: a coupled contact that slid farther has left the patch
  /// m: the vessel's wall thickness; a row whose reference wall the series springs dent deeper
  /// (C_ref·F_ref) is beyond every linear wall (reference_within_wall)
  double wall_thickness = 0.0;
  std::vector<GuidewireRigid> rigid;       ///< the scene's EI first, then the stiffness sweep's
  std::vector<GuidewireCouplingRow> rows;  ///< compliant coupling: per EI, per model outcome
};

}  // namespace vessel
