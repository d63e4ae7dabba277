#pragma once
/// A guidewire as the vessel's load (the scene's `[load] type = "guidewire"`): a rod clamped at
/// the inlet and inserted a given length; solved against the rigid lumen, its contact force and
/// point become the contact patch every model and the reference get (verification/guidewire_load
/// .hpp). Plain data; SI units.
#include <filesystem>
#include <string>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

enum class GuidewireCoupling {
  rigid,      ///< the wire's force against the rigid lumen loads every model
  compliant,  ///< and each model's own force, the wire pushing a wall that gives way
};

struct GuidewireSpec {
  double young = 0.0;     ///< E, Pa
  double shear = 0.0;     ///< G, Pa
  double density = 6450.0;  ///< kg/m³
  double diameter = 0.0;  ///< m, solid circular section
  double insertion = 0.0;  ///< length of wire beyond the clamp, m
  int segments = 32;
  std::string model = "der";  ///< der | corde | xpbd (msm/rods) | external (the user's program)
  /// model = "external": the user's wire program (argv; the case's manifest path appended, run
  /// in working_dir, the scene file's folder) and its time limit (verification/wire_exchange.hpp).
  std::vector<std::string> command;
  std::filesystem::path working_dir;
  double timeout_s = 120.0;
  /// The clamp: a point and a unit tangent (set from `clamp_point`/`clamp_direction`, or from the
  /// inlet's centreline point and tangent tilted by `tilt` towards `tilt_towards`).
  Vec3 clamp_point = Vec3::Zero();
  Vec3 clamp_direction = Vec3::UnitZ();
  GuidewireCoupling coupling = GuidewireCoupling::rigid;
  /// Compliant coupling: the bending stiffnesses EI (N·m²) the coupling is repeated at (E scaled,
  /// the section kept), with the walls' compliances of the scene's run.
  std::vector<double> stiffness_sweep;
};

/// The wire solved against a rigid lumen (or one that gives way by `wall_give` along the normal).
struct GuidewireSolution {
  double force = 0.0;           ///< the wall's normal force on the wire, N (≥ 0)
  Vec3 contact_point = Vec3::Zero();  ///< the wire's centreline node in contact, m
  Vec3 wall_point = Vec3::Zero();     ///< the wall under it (the centreline node + r_wire·n), m
  Vec3 normal = Vec3::Zero();   ///< unit, the direction the wire pushes the wall
  Vec3 clamp_force = Vec3::Zero();   ///< the clamp's force on the wire, N
  std::vector<Vec3> centreline;  ///< node positions from the clamp to the tip, m
  int contact_nodes = 0;         ///< nodes in contact (a guidewire load needs one)
  double bending_stiffness = 0.0;  ///< EI, N·m²
};

}  // namespace vessel
