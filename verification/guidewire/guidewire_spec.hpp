#pragma once
/// A guidewire as the vessel's load (the scene's `[load] type = "guidewire"`): a rod clamped at
/// the inlet and inserted a given length; solved against the rigid lumen, its contact force and
/// point become the contact patch every model and the reference get (verification/guidewire_load
/// .hpp). Plain data; SI units.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "meshes/tet_mesh.hpp"

namespace vessel {

/// The wire's model: a rod of msm/rods, or the user's own program (verification/guidewire/wire_exchange.hpp).
enum class WireModel {
  der,       ///< Discrete Elastic Rods (msm/rods/der_rod.hpp)
  corde,     ///< seed 002's CORDE rod (msm/rods/corde_rod.hpp)
  xpbd,      ///< the XPBD Cosserat rod's steady state (msm/rods/xpbd_rod.hpp)
  external,  ///< the user's program through the wire exchange
};

/// Every model with its scene name (the `model` key's values), in the enum's order.
inline constexpr std::array<std::pair<WireModel, std::string_view>, 4> kWireModelNames{{
    {WireModel::der, "der"},
    {WireModel::corde, "corde"},
    {WireModel::xpbd, "xpbd"},
    {WireModel::external, "external"},
}};

/// The rods msm/rods solves (every model but external).
inline constexpr std::array<WireModel, 3> kRodModels{WireModel::der, WireModel::corde,
                                                     WireModel::xpbd};

/// The model's scene name ("der", ...).
inline std::string to_string(WireModel m) {
  return std::string(kWireModelNames[static_cast<std::size_t>(m)].second);
}

/// The model of a scene name; nullopt for any other string.
inline std::optional<WireModel> parse_wire_model(std::string_view name) {
  for (const auto& [m, n] : kWireModelNames) {
    if (n == name) return m;
  }
  return std::nullopt;
}

/// The scene names, in order (the `model` key's allowed values).
inline std::vector<std::string> wire_model_names() {
  std::vector<std::string> names;
  for (const auto& entry : kWireModelNames) names.emplace_back(entry.second);
  return names;
}

enum class GuidewireCoupling {
  rigid,      ///< the wire's force against the rigid lumen loads every model
  compliant,  ///< and each model's own force, the wire pushing a wall that gives way
  /// and each model's wall in a contact solve with the wire, judged against the FEM wall's
  /// (verification/contact_models/contact_models.hpp); the compliant rows stay, as a shortcut
  contact,
};
/// The coupling's scene name: "rigid", "compliant" or "contact".
inline std::string to_string(GuidewireCoupling coupling) {
  switch (coupling) {
    case GuidewireCoupling::compliant:
      return "compliant";
    case GuidewireCoupling::contact:
      return "contact";
    case GuidewireCoupling::rigid:
      break;
  }
  return "rigid";
}

/// The wall of a contact solve: linear elasticity, or the finite-strain compressible neo-Hookean
/// wall (fem::NeoHookean; each mass-spring model then at its own nonlinear equilibrium).
enum class ContactWall { linear, neo_hookean };
/// "linear" or "neo-Hookean".
inline std::string to_string(ContactWall wall) {
  return wall == ContactWall::linear ? "linear" : "neo-Hookean";
}
/// "linear" or "neo-hookean" (the scene's and the command line's name); InputError naming both
/// otherwise.
ContactWall parse_contact_wall(const std::string& name);

struct GuidewireSpec {
  double young = 0.0;     ///< E, Pa
  double shear = 0.0;     ///< G, Pa
  double density = 6450.0;  ///< kg/m³
  double diameter = 0.0;  ///< m, solid circular section
  double insertion = 0.0;  ///< length of wire beyond the clamp, m
  int segments = 32;
  WireModel model = WireModel::der;
  /// model = external: the user's wire program (argv; the case's manifest path appended, run
  /// in working_dir, the scene file's folder) and its time limit (verification/guidewire/wire_exchange.hpp).
  std::vector<std::string> command;
  std::filesystem::path working_dir;
  double timeout_s = 120.0;
  /// The clamp: a point and a unit tangent (set from `clamp_point`/`clamp_direction`, or from the
  /// inlet's centreline point and tangent tilted by `tilt` towards `tilt_towards`).
  Vec3 clamp_point = Vec3::Zero();
  Vec3 clamp_direction = Vec3::UnitZ();
  GuidewireCoupling coupling = GuidewireCoupling::rigid;
  /// Compliant or contact coupling: the bending stiffnesses EI (N·m²) the coupling is repeated at
  /// (E scaled, the section kept), with the walls' compliances of the scene's run.
  std::vector<double> stiffness_sweep;
  /// Contact coupling: the contact mesh's element size near the wire's rigid contact, m, and the
  /// radius of that refined region, m.
  double contact_fine_size = 0.08e-3;
  double contact_fine_radius = 1.0e-3;
  /// Contact coupling: the walls of the run's contact solve. linear: an EI whose series springs
  /// dent the reference's wall deeper than it is thick is not solved (a linear wall cannot hold
  /// the wire there); neo_hookean: every EI.
  ContactWall contact_wall = ContactWall::linear;
  /// Contact coupling at finite strain: the P2 reference solved first with P1 on the same mesh
  /// and P2 from P1's equilibrium (in the arch P2 from rest stalls; on the straight tube the
  /// start does not pay: contact.md).
  bool contact_p1_start = false;
  /// Contact coupling: the contact solved at the wire's own EI alone, not at stiffness_sweep's
  /// (the series springs still are). Not a scene key: set by the quick variant.
  bool contact_at_own_stiffness_only = false;
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
