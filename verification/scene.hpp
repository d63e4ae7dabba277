#pragma once
/// Declarative verification scenes: what vessel, material, boundary conditions, load sweep and
/// models a verification runs, read from TOML and validated strictly (unknown keys, wrong types and
/// out-of-range values are InputErrors naming the file, line and key). SI units in the file.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "meshes/surface_loads.hpp"
#include "meshes/vessel_geometry.hpp"

namespace vessel {

enum class BoundaryCondition { clamped, axial_roller, free };
enum class LoadKind { contact, pressure, gravity };
enum class ModelKind { fem, surface_msm, volume_msm };

/// One model to run against the reference. FEM models use `degree`; mass-spring models use the
/// rest (names as the msm library defines them; checked against the lists in scene.cpp). A
/// [[models]] table whose stiffness, mass, solver, dt or degree is an array expands into one
/// ModelSpec per combination (a sweep from the scene file).
struct ModelSpec {
  std::string name;  ///< unique within the scene, used in results and reports
  ModelKind kind = ModelKind::fem;
  int degree = 2;                      ///< FEM: 1 or 2
  std::string surface = "mid";         ///< surface msm: inner | outer | mid
  std::string topology = "auto";       ///< surface msm: auto | grid | triangles
  std::string stiffness;               ///< msm stiffness rule (msm::parse_stiffness_rule names)
  std::string mass = "consistent";     ///< msm mass rule (msm::parse_mass_rule names)
  std::string solver = "static";       ///< static | linear | relaxation | an integrator
  double dt = 0.0;                     ///< s, integrators only (> 0)
  double damping = 0.0;                ///< point damping k_v of seed 000 eq. (3.3), N·s/m per node
  long steps = 0;                      ///< integrators: number of steps (> 0)
};

struct LoadSpec {
  LoadKind kind = LoadKind::contact;
  std::vector<double> magnitudes;  ///< N (contact), Pa (pressure), multiples of g (gravity)
  ContactPatchSpec contact;        ///< point, radius, surface group (force set per magnitude)
  Vec3 gravity_direction = Vec3(0.0, -1.0, 0.0);
};

struct Tolerances {
  double max_error_mm = 0.1;  ///< seed 000's visual threshold
};

struct Scene {
  std::string name;
  std::string description;
  std::filesystem::path source;  ///< the file it was read from
  VesselParams vessel;           ///< vessel.level is model_levels.front()
  /// Levels the models run at (`level = 1` or `level = [0, 1, 2]`: a convergence sweep), ascending.
  std::vector<int> model_levels{0};
  int reference_level = 1;       ///< finest FEM level of the reference (default: the finest model level)
  double youngs_modulus = 14.24e3;  ///< Pa
  std::vector<double> poisson_ratios{0.45};
  double density = 1060.0;  ///< kg/m³
  std::map<std::string, BoundaryCondition> boundary;  ///< group name → condition
  LoadSpec load;
  std::vector<ModelSpec> models;
  Tolerances tolerances;
};

/// Reads and validates a scene file. Throws InputError ("file:line: key: what was found, what was
/// expected") for a missing file, a TOML syntax error, an unknown key, a wrong type or a value out
/// of range.
Scene read_scene(const std::filesystem::path& path);
/// Same, from text; `source_name` is used in messages.
Scene parse_scene(std::string_view text, const std::string& source_name);

std::string to_string(BoundaryCondition bc);
std::string to_string(LoadKind kind);
std::string to_string(ModelKind kind);

}  // namespace vessel
