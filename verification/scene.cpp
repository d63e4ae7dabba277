#include "verification/scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "meshes/foundation/errors.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/model_capabilities.hpp"
#include "verification/scene_reader.hpp"

namespace vessel {

namespace {

using scene_detail::show;
using scene_detail::TableReader;

/// A vessel from a file (`file = "x.msh"` or `lumen = "x.stl"`), paths relative to the scene's
/// folder. A mesh file is used as given: its one level is 0, and a scene asking for another is an
/// error. A lumen needs its wall_thickness (m) and may say `units = "mm"`; levels refine it.
VesselParams read_file_vessel(TableReader& r, const std::string& scene_file,
                              std::vector<int>& levels, int& reference_level) {
  VesselParams p;
  const toml::node* file = r.table().get("file");
  const std::string key = file ? "file" : "lumen";
  const toml::node& node = r.require(key);
  const auto name = node.value_exact<std::string>();
  if (!name || name->empty()) r.fail(&node, key, "found " + show(node) + ", expected a file name");
  p.file = *name;
  if (p.file.is_relative()) p.file = std::filesystem::path(scene_file).parent_path() / p.file;
  p.kind = file ? VesselKind::mesh_file : VesselKind::lumen;
  p.style = MeshStyle::unstructured;
  levels = r.integers_or("level", {0});
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  reference_level = static_cast<int>(r.integer_or("reference_level", levels.back()));
  if (file && (levels != std::vector<int>{0} || reference_level != 0)) {
    const std::string bad = levels != std::vector<int>{0} ? "level" : "reference_level";
    r.fail(r.table().get(bad), bad,
           "found a level other than 0 with a mesh file; expected 0 or none (a .msh file is "
           "used as given, its one level: mesh it finer yourself, or give a lumen STL, which "
           "levels refine)");
  }
  // A mesh file's optional shell thickness (0: estimated, file_vessel_wall_thickness); a
  // lumen's required one.
  p.wall_thickness = r.number_or("wall_thickness", 0.0);
  if (!file) p.file_scale = r.string_or("units") == "mm" ? 1e-3 : 1.0;
  // A lumen's ends listed by hand: both keys or neither.
  const toml::node* inlet = file ? nullptr : r.table().get("inlet_centre");
  const toml::node* outlets = file ? nullptr : r.table().get("outlet_centres");
  if ((inlet == nullptr) != (outlets == nullptr)) {
    r.fail(inlet ? inlet : outlets, inlet ? "inlet_centre" : "outlet_centres",
           std::string("found without ") + (inlet ? "outlet_centres" : "inlet_centre") +
               "; expected both (the ends listed by hand) or neither (found by their shape)");
  }
  if (inlet) {
    p.listed_ends.inlet = r.vector3(*inlet, "inlet_centre");
    p.listed_ends.outlets = r.vectors3(*outlets, "outlet_centres");
  }
  p.level = levels.front();
  if (!std::filesystem::exists(p.file)) r.fail(&node, key, "file " + p.file.string() + " not found");
  return p;
}

VesselParams read_vessel(TableReader r, std::vector<int>& levels, int& reference_level,
                         const std::string& scene_file) {
  const toml::node* file = r.table().get("file");
  const toml::node* lumen = r.table().get("lumen");
  if (file && lumen) {
    r.fail(lumen, "lumen",
           "found with `file`; expected one of them: a tet mesh (.msh) or a lumen surface (STL)");
  }
  r.enter(file ? "file" : (lumen ? "lumen" : "parametric"));
  if (file || lumen) return read_file_vessel(r, scene_file, levels, reference_level);
  VesselParams p;
  p.kind = r.string_or("kind") == "arch" ? VesselKind::arch : VesselKind::straight;
  p.inner_radius = r.number_or("inner_radius");
  p.wall_thickness = r.number_or("wall_thickness");
  p.length = r.number_or("length");
  p.bend_radius = r.number_or("bend_radius");
  p.style = r.string_or("mesh") == "structured" ? MeshStyle::structured : MeshStyle::unstructured;
  levels = r.integers_or("level", {0});
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  p.level = levels.front();
  reference_level = static_cast<int>(r.integer_or("reference_level", levels.back()));
  try {
    validate(p);
  } catch (const InputError& e) {
    r.fail(nullptr, "", e.what());
  }
  return p;
}

bool is_dynamic(const std::string& solver) { return msm::parse_solver(solver).is_dynamic(); }

/// A FEM [[models]] table: `degree` 1 or 2, or an array of them (a sweep).
std::vector<ModelSpec> fem_models(TableReader& r, const ModelSpec& m) {
  const std::vector<int> degrees = r.integers_or("degree", {2});
  std::vector<ModelSpec> out;
  for (const int d : degrees) {
    ModelSpec c = m;
    c.degree = d;
    if (degrees.size() > 1) c.name += "[degree=" + std::to_string(d) + "]";
    out.push_back(c);
  }
  return out;
}

/// A corotational_fem or xpbd_fem [[models]] table: the P1 tets of the vessel's mesh; xpbd_fem's
/// step, sweeps, damping and steady-state test (TetFemSpec).
std::vector<ModelSpec> tet_fem_model(TableReader& r, ModelSpec m) {
  if (m.kind == ModelKind::xpbd_fem) {
    TetFemSpec& t = m.tet_fem;
    t.dt = r.number_or("dt", t.dt);
    t.iterations = static_cast<int>(r.integer_or("iterations", t.iterations));
    t.velocity_damping = r.number_or("velocity_damping", t.velocity_damping);
    t.settle_relative_change = r.number_or("settle_relative_change", t.settle_relative_change);
    t.max_steps = r.integer_or("max_steps", t.max_steps);
  }
  return {m};
}

/// Region of interest: a radius or an array of radii (a sweep), each > 0 m; contact loads only.
/// {0} (the whole vessel) when absent.
std::vector<double> roi_radii(TableReader& r, LoadKind load) {
  const toml::node* roi = r.get("roi_radius");
  if (!roi) return {0.0};
  if (load != LoadKind::contact) {
    r.fail(roi, "roi_radius",
           "found a region-of-interest radius on a " + to_string(load) +
               " load; expected it only with a contact load (the region is centred on the "
               "contact point)");
  }
  return r.numbers(*roi, "roi_radius");
}

/// "5e-05" rather than "0.000050".
std::string short_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// An `external` or `displacements` [[models]] table (a model outside the suite,
/// verification/harness/external_model.hpp): the nodes it is given, and its command and time limit, or
/// the folder of answers computed elsewhere; `dt` and `steps` make the problem dynamic.
std::vector<ModelSpec> outside_model(TableReader& r, ModelSpec m) {
  ExternalSpec& e = m.external;
  if (m.kind == ModelKind::external) {
    e.command = r.string_array("command");
    e.timeout_s = r.number_or("timeout_s");
  } else {
    const toml::node& f = r.require("file");
    const auto v = f.value_exact<std::string>();
    if (!v || v->empty()) {
      r.fail(&f, "file",
             "found " + show(f) +
                 ", expected the folder of case folders with the answers (as `vesselverify "
                 "export` wrote them, one folder per case holding displacements.csv or "
                 "displacements.vtu)");
    }
    e.directory = *v;
  }
  e.nodes = r.string_or("nodes") == "surface" ? ExchangeNodes::surface : ExchangeNodes::volume;
  if (const toml::node* sf = r.get("surface"); sf && e.nodes != ExchangeNodes::surface) {
    r.fail(sf, "surface", "found a wall surface with nodes = \"volume\"; expected it only with "
                          "nodes = \"surface\"");
  }
  e.surface = msm::parse_wall_surface(r.string_or("surface"));
  const toml::node* dt = r.get("dt");
  const toml::node* steps = r.get("steps");
  if (dt || steps) {
    if (!dt) r.fail(steps, "steps", "found steps without dt; expected both (a dynamic problem) or neither");
    if (!steps) r.fail(dt, "dt", "found dt without steps; expected both (a dynamic problem) or neither");
    e.dt = r.number(*dt, "dt");
  }
  e.steps = r.integer_or("steps", 0);
  return {m};
}

/// A mass-spring table's wall keys: `surface`, `topology` and `bending` (surface models),
/// `volume_term`, `volume_moduli` and `edge_pairs` (volume models).
void read_wall_options(TableReader& r, ModelSpec& m) {
  if (m.kind == ModelKind::surface_msm) {
    m.surface = msm::parse_wall_surface(r.string_or("surface", msm::to_string(m.surface)));
    m.topology = msm::parse_topology(r.string_or("topology"));
    // `bending = "discrete-shells"`: the hinge energy of Grinspun et al. 2003 on the triangles
    // (msm/terms/bending_term.hpp), membrane springs van-gelder by default.
    m.bending = msm::parse_bending(r.string_or("bending"));
    if (m.bending != msm::Bending::none && m.topology == msm::Topology::grid) {
      r.fail(r.get("topology"), "topology",
             "found \"grid\" with bending = \"discrete-shells\"; expected \"triangles\" or "
             "\"auto\" (the hinges replace the triangle topology's bend springs)");
    }
  }
  if (m.kind == ModelKind::volume_msm) {
    m.volume_term = r.boolean_or("volume_term");
    // volume_moduli = "golec" | "homogenised": the volume term's (E_s, κ) rule.
    m.volume_moduli = msm::parse_volume_moduli(r.string_or("volume_moduli"));
    if (m.volume_moduli != msm::VolumeModuli::golec && !m.volume_term) {
      r.fail(r.get("volume_moduli"), "volume_moduli",
             "found \"" + msm::to_string(m.volume_moduli) +
                 "\" without volume_term = true; expected volume_term = true with it");
    }
    // edge_pairs = true: the springs coupled in each tet's edge pairs (Kikuuwe et al. 2009), StVK
    // P1 on the edges; it has no springs of its own, so no stiffness rule and no volume term.
    m.edge_pairs = r.boolean_or("edge_pairs");
    if (m.edge_pairs && m.volume_term) {
      r.fail(r.get("edge_pairs"), "edge_pairs",
             "found true with volume_term = true; expected one of them (the edge-pair model "
             "reaches any ν < 0.5 by itself)");
    }
    if (m.edge_pairs && r.get("stiffness")) {
      r.fail(r.get("stiffness"), "stiffness",
             "found with edge_pairs = true; expected no stiffness key (the edge-pair model's "
             "coefficients come from each tet's StVK energy, not from a spring rule)");
    }
  }
}

/// Refuses PBD where it cannot run: on a network file, a volume model or with bending.
void check_pbd(TableReader& r, const ModelSpec& m, const std::vector<std::string>& solvers) {
  if (std::find(solvers.begin(), solvers.end(), "pbd") == solvers.end()) return;
  const toml::node* key = r.get("solver");
  if (m.kind == ModelKind::network) {
    r.fail(key, "solver",
           "found \"pbd\" on a network model; expected another solver (seed 002's constraints "
           "need a surface network's triangles, which a network file does not give)");
  }
  if (m.kind == ModelKind::volume_msm) {
    r.fail(key, "solver",
           "found \"pbd\" on a volume model; expected it on a surface_msm model (seed 002's "
           "constraints act on a surface network)");
  }
  if (m.bending != msm::Bending::none) {
    r.fail(key, "solver",
           "found \"pbd\" with bending = \"discrete-shells\"; expected another solver (PBD "
           "projects its own constraints and would ignore the bending energy)");
  }
}

/// The time steps of a table with a dynamic solver (`dt`, required > 0, and `steps` into m), and
/// `iterations` of local-global-euler; {0} for static solvers alone.
std::vector<double> read_time_stepping(TableReader& r, ModelSpec& m,
                                       const std::vector<std::string>& solvers) {
  std::vector<double> dts{0.0};
  const auto dynamic = std::find_if(solvers.begin(), solvers.end(), is_dynamic);
  if (dynamic != solvers.end()) {
    const toml::node* dt = r.get("dt");
    if (!dt) r.fail(nullptr, "dt", "missing; solver \"" + *dynamic + "\" needs a time step > 0 s");
    dts = r.numbers(*dt, "dt");
    m.solver.steps = r.integer_or("steps", 0);
    if (m.solver.steps == 0) {
      r.fail(nullptr, "steps",
             "missing; solver \"" + *dynamic + "\" needs the number of steps (an integer > 0)");
    }
  } else {
    for (const std::string key : {"dt", "steps"}) {
      if (const toml::node* n = r.get(key)) {
        r.fail(n, key,
               "found with solver \"" + solvers.front() +
                   "\"; expected it only with a dynamic solver (an integrator, pbd or "
                   "local-global-euler)");
      }
    }
  }
  // `iterations`: local–global iterations per step of local-global-euler (Liu et al. 2013).
  if (const toml::node* it = r.get("iterations")) {
    if (std::find(solvers.begin(), solvers.end(), "local-global-euler") == solvers.end()) {
      r.fail(it, "iterations",
             "found local-global iterations without solver \"local-global-euler\"; expected it "
             "only with that solver");
    }
  }
  m.solver.local_global.iterations =
      static_cast<int>(r.integer_or("iterations", m.solver.local_global.iterations));
  return dts;
}

/// Every combination of the swept values, each named after m's name plus the values that vary,
/// e.g. "volume[stiffness=lloyd;dt=2e-05]".
std::vector<ModelSpec> sweep(const ModelSpec& m, const std::vector<std::string>& stiffness,
                             const std::vector<std::string>& mass,
                             const std::vector<std::string>& solvers,
                             const std::vector<double>& dts, const std::vector<double>& radii) {
  std::vector<ModelSpec> out;
  for (const auto& k : stiffness) {
    for (const auto& ms : mass) {
      for (const auto& solver : solvers) {
        for (const double dt : is_dynamic(solver) ? dts : std::vector<double>{0.0}) {
          for (const double roi : radii) {
            ModelSpec c = m;
            c.roi_radius = roi;
            c.stiffness = msm::parse_stiffness_rule(k);
            c.mass = msm::parse_mass_rule(ms);
            c.solver = msm::parse_solver(solver);
            c.solver.local_global = m.solver.local_global;
            c.solver.dt = dt;
            c.solver.steps = is_dynamic(solver) ? m.solver.steps : 0;
            std::string swept;
            const auto add = [&](bool varies, const std::string& key, const std::string& value) {
              if (varies) swept += (swept.empty() ? "" : ";") + key + "=" + value;
            };
            add(stiffness.size() > 1, "stiffness", k);
            add(mass.size() > 1, "mass", ms);
            add(solvers.size() > 1, "solver", solver);
            add(dts.size() > 1 && is_dynamic(solver), "dt", short_number(dt));
            add(radii.size() > 1, "roi_radius", short_number(roi));
            if (!swept.empty()) c.name += "[" + swept + "]";
            out.push_back(c);
          }
        }
      }
    }
  }
  return out;
}

/// One [[models]] table. `stiffness`, `mass`, `solver`, `dt` and `roi_radius` (and `degree` for
/// FEM) may be arrays: the table then stands for every combination (a sweep, see `sweep`).
std::vector<ModelSpec> read_model(TableReader r, std::size_t index, LoadKind load) {
  ModelSpec m;
  const std::string kind = r.string_or("kind", "");
  if (kind.empty()) (void)r.require("kind");
  r.enter(kind);
  m.kind = kind == "fem"                ? ModelKind::fem
           : kind == "surface_msm"      ? ModelKind::surface_msm
           : kind == "network"          ? ModelKind::network
           : kind == "external"         ? ModelKind::external
           : kind == "displacements"    ? ModelKind::displacements
           : kind == "corotational_fem" ? ModelKind::corotational_fem
           : kind == "xpbd_fem"         ? ModelKind::xpbd_fem
                                        : ModelKind::volume_msm;
  m.name = r.string_or("name", kind + "_" + std::to_string(index + 1));
  if (m.kind == ModelKind::fem) return fem_models(r, m);
  if (m.kind == ModelKind::corotational_fem || m.kind == ModelKind::xpbd_fem) {
    return tet_fem_model(r, m);
  }
  if (m.kind == ModelKind::external || m.kind == ModelKind::displacements) {
    return outside_model(r, m);
  }
  const bool network = m.kind == ModelKind::network;
  // A spring network from a file: its springs, masses and supports come from the file, so the
  // stiffness, mass, topology and calibration keys are not part of it.
  if (network) m.network_file = r.string_or("file", "");
  read_wall_options(r, m);
  const auto stiffness = network ? std::vector<std::string>{msm::to_string(m.stiffness)} :
      r.strings_or("stiffness",
                   m.kind == ModelKind::volume_msm
                       ? (m.volume_term ? "van-gelder" : "seed001")
                       : (m.bending != msm::Bending::none ? "van-gelder" : "seed000"));
  if (m.volume_term) {
    for (const auto& k : stiffness) {
      if (msm::parse_stiffness_rule(k) != msm::StiffnessRule::van_gelder) {
        r.fail(r.get("stiffness"), "stiffness",
               "found \"" + k + "\" with volume_term = true; expected \"van-gelder\" (the hybrid "
               "volume model's κ = λ − μ assumes van-gelder springs, whose λ = μ)");
      }
    }
  }
  const auto mass = network ? std::vector<std::string>{msm::to_string(m.mass)}
                            : r.strings_or("mass", r.default_string("mass"));
  const auto solvers = r.strings_or("solver", r.default_string("solver"));
  check_pbd(r, m, solvers);
  m.damping = r.number_or("damping");
  if (!network) {
    m.calibration = r.string_or("calibration");
    m.calibration_transfer = r.boolean_or("calibration_transfer");
  }
  if (m.calibration_transfer && m.calibration.empty()) {
    r.fail(r.get("calibration_transfer"), "calibration_transfer",
           "found without a calibration file; expected calibration = \"file.json\" beside it");
  }
  if (m.edge_pairs && !m.calibration.empty()) {
    r.fail(r.get("calibration"), "calibration",
           "found with edge_pairs = true; expected none (a calibration scales springs, and the "
           "edge-pair model has none)");
  }
  const std::vector<double> radii = roi_radii(r, load);
  const std::vector<double> dts = read_time_stepping(r, m, solvers);
  return sweep(m, stiffness, mass, solvers, dts, radii);
}

/// The guidewire load's keys (verification/guidewire/guidewire_spec.hpp), checked; its solve is
/// solve_guidewire_load's, on the run path.
GuidewireSpec read_guidewire(const TableReader& r, const VesselParams& vessel) {
  GuidewireSpec w;
  w.young = r.number(r.require("E"), "E");
  const toml::node* G = r.get("G");
  const toml::node* nu = r.get("nu");
  if (G && nu) r.fail(nu, "nu", "found both G and nu; expected one of them");
  w.shear = G ? r.number(*G, "G") : w.young / (2.0 * (1.0 + r.number_or("nu")));
  w.density = r.number_or("density");
  w.diameter = r.number(r.require("diameter"), "diameter");
  w.insertion = r.number(r.require("insertion"), "insertion");
  w.segments = static_cast<int>(r.integer_or("segments", 32));
  w.model = *parse_wire_model(r.string_or("model"));  // one of the key's choices, checked
  const toml::node* command = r.get("command");
  if (w.model == WireModel::external) {
    if (!command) (void)r.require("command");
    w.command = r.string_array("command");
    w.timeout_s = r.number_or("timeout_s");
    w.working_dir = std::filesystem::path(r.file()).parent_path();
  } else {
    for (const char* key : {"command", "timeout_s"}) {
      if (const toml::node* n = r.get(key)) {
        if (std::string(key) == "timeout_s") (void)r.number(*n, key);  // its type first
        r.fail(n, key, "found with model = \"" + to_string(w.model) + "\"; expected model = \"external\"");
      }
    }
  }
  const toml::node* point = r.get("clamp_point");
  const toml::node* direction = r.get("clamp_direction");
  if (point) w.clamp_point = r.vector3(*point, "clamp_point");
  if (direction) w.clamp_direction = r.vector3(*direction, "clamp_direction");
  if (point || direction) {
    if (!point) r.fail(direction, "clamp_point", "missing; clamp_direction needs clamp_point");
    if (!direction) r.fail(point, "clamp_direction", "missing; clamp_point needs clamp_direction");
    for (const char* k : {"tilt", "tilt_towards"}) {
      if (const toml::node* n = r.get(k)) r.fail(n, k, "found with clamp_point; expected one pose");
    }
    if (w.clamp_direction.norm() == 0.0) {
      r.fail(direction, "clamp_direction", "found [0, 0, 0], expected a non-zero vector");
    }
    w.clamp_direction.normalize();
  } else {
    const toml::node* towards = r.get("tilt_towards");
    try {
      set_tilted_clamp(vessel, r.number_or("tilt"),
                       towards ? r.vector3(*towards, "tilt_towards") : Vec3::UnitX(), w);
    } catch (const InputError& e) {
      r.fail(towards, "tilt_towards", e.what());
    }
  }
  const std::string coupling = r.string_or("coupling", "rigid");
  w.coupling = coupling == "contact"     ? GuidewireCoupling::contact
               : coupling == "compliant" ? GuidewireCoupling::compliant
                                         : GuidewireCoupling::rigid;
  if (const toml::node* sweep = r.get("stiffness_sweep")) {
    if (w.coupling == GuidewireCoupling::rigid) {
      r.fail(sweep, "stiffness_sweep",
             "found with coupling = \"rigid\"; expected \"compliant\" or \"contact\"");
    }
    w.stiffness_sweep = r.numbers(*sweep, "stiffness_sweep");
  }
  // The contact coupling's own keys: refused with another coupling.
  const auto contact_key = [&](const char* key) {
    const toml::node* node = r.get(key);
    if (node && w.coupling != GuidewireCoupling::contact) {
      r.fail(node, key, "found with coupling = \"" + coupling + "\"; expected coupling = \"contact\"");
    }
    return node;
  };
  if (const toml::node* size = contact_key("contact_fine_size")) {
    w.contact_fine_size = r.number(*size, "contact_fine_size");
  }
  if (const toml::node* radius = contact_key("contact_fine_radius")) {
    w.contact_fine_radius = r.number(*radius, "contact_fine_radius");
  }
  if (contact_key("contact_wall")) {
    w.contact_wall = parse_contact_wall(r.string_or("contact_wall", "linear"));
  }
  if (const toml::node* start = contact_key("contact_p1_start")) {
    w.contact_p1_start = r.boolean_or("contact_p1_start");
    if (w.contact_p1_start && w.contact_wall != ContactWall::neo_hookean) {
      r.fail(start, "contact_p1_start",
             "found with a linear contact wall; expected contact_wall = \"neo-hookean\" (the P1 "
             "start is the finite-strain P2 reference's)");
    }
  }
  return w;
}

LoadSpec read_load(TableReader r, const VesselParams& vessel) {
  LoadSpec load;
  const std::string type = r.string_or("type", "");
  if (type.empty()) (void)r.require("type");
  r.enter(type);
  if (type == "guidewire") {
    load.guidewire = read_guidewire(r, vessel);
    load.contact.radius = r.number_or("patch_radius");
    load.contact.surface_group = "inner_wall";
    try {
      check_guidewire(vessel, *load.guidewire);
    } catch (const InputError& e) {
      throw InputError(r.file() + ": " + e.what());
    }
    return load;  // its magnitude and point: solve_guidewire_load, on the run path
  }
  load.kind = type == "contact" ? LoadKind::contact
                                : (type == "pressure" ? LoadKind::pressure : LoadKind::gravity);
  load.magnitudes = r.numbers(r.require("magnitudes"), "magnitudes");
  if (load.kind == LoadKind::contact) {
    load.contact.point = r.vector3(r.require("point"), "point");
    load.contact.radius = r.number_or("patch_radius");
  }
  if (load.kind != LoadKind::gravity) load.contact.surface_group = r.string_or("surface");
  if (load.kind == LoadKind::gravity) {
    if (const toml::node* d = r.get("direction")) {
      load.gravity_direction = r.vector3(*d, "direction");
      if (load.gravity_direction.norm() == 0.0) r.fail(d, "direction", "found [0, 0, 0], expected a non-zero vector");
      load.gravity_direction.normalize();
    }
  }
  return load;
}

/// Every [[models]] table, sweeps expanded; relative paths made relative to the scene's folder.
void read_models(const TableReader& r, Scene& scene) {
  const toml::node& models = r.require("models");
  const auto* list = models.as_array();
  if (!list || list->empty()) r.fail(&models, "models", "expected at least one [[models]] table");
  const std::filesystem::path folder = std::filesystem::path(r.file()).parent_path();
  std::set<std::string> names;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const auto* t = list->get(i)->as_table();
    if (!t) r.fail(list->get(i), "models", "expected [[models]] tables");
    for (ModelSpec& m : read_model(TableReader(*t, "models", "models[" + std::to_string(i) + "].",
                                               r.file()),
                                   i, scene.load.kind)) {
      // Models outside the suite: their command runs in the scene file's folder, and their
      // answers' folder is relative to it.
      m.external.working_dir = folder;
      if (!m.external.directory.empty() && m.external.directory.is_relative()) {
        m.external.directory = folder / m.external.directory;
      }
      if (!m.calibration.empty() && m.calibration.is_relative()) m.calibration = folder / m.calibration;
      if (!m.network_file.empty() && m.network_file.is_relative()) {
        m.network_file = folder / m.network_file;
      }
      if (!names.insert(m.name).second) {
        r.fail(list->get(i), "models",
               "model name \"" + m.name + "\" is used twice; names must be unique");
      }
      scene.models.push_back(std::move(m));
    }
  }
}

/// A positive tolerance or radius that one quantity needs and the others must not have.
double quantity_number(TableReader& r, const std::string& key, bool wanted, const std::string& why) {
  const toml::node* n = r.get(key);
  if (wanted && !n) r.fail(nullptr, key, "missing; " + why + " needs " + r.spec(key).expected());
  return n ? r.number(*n, key) : 0.0;
}

/// The [budget] table (issue #7): quantity, its tolerance, a rate or time budget, the load.
Budget read_budget(TableReader r, const Scene& scene) {
  Budget b;
  b.stated = true;
  b.quantity = parse_budget_quantity(r.string_or("quantity"));
  const toml::node* q = r.get("quantity");
  if (b.quantity == BudgetQuantity::reaction && scene.load.kind != LoadKind::contact) {
    r.fail(q, "quantity",
           "found \"reaction\" with a " + to_string(scene.load.kind) +
               " load; expected a contact load (the instrument's force)");
  }
  if (b.quantity == BudgetQuantity::contact_force &&
      !(scene.load.guidewire && scene.load.guidewire->coupling == GuidewireCoupling::contact)) {
    r.fail(q, "quantity",
           "found \"contact_force\"; expected a guidewire load with coupling = \"contact\" (the "
           "force comes from the wire-wall contact solve)");
  }
  const bool force =
      b.quantity == BudgetQuantity::reaction || b.quantity == BudgetQuantity::contact_force;
  const bool patch = b.quantity == BudgetQuantity::patch;
  if (const toml::node* radius = r.get("radius"); radius && !patch) {
    r.fail(radius, "radius",
           "found a radius with quantity \"" + to_string(b.quantity) +
               "\"; expected it only with quantity \"patch\"");
  }
  b.radius = quantity_number(r, "radius", patch, "quantity \"patch\"");
  const toml::node* mm = r.get("tolerance_mm");
  const toml::node* mn = r.get("tolerance_mN");
  if (force) {
    const std::string quantity = "quantity \"" + to_string(b.quantity) + "\"";
    if (mm) {
      r.fail(
          mm, "tolerance_mm",
          "found a displacement tolerance; " + quantity + " expected tolerance_mN (a force, mN)");
    }
    b.tolerance = quantity_number(r, "tolerance_mN", true, quantity);
  } else {
    if (mn) {
      r.fail(mn, "tolerance_mN",
             "found a force tolerance with quantity \"" + to_string(b.quantity) +
                 "\"; expected tolerance_mm");
    }
    // [tolerances], itself 0.1 mm by default.
    b.tolerance = r.number_or("tolerance_mm", scene.tolerances.max_error_mm);
  }
  b.rate_hz = r.number_or("rate_hz", 0.0);
  b.time_budget_s = r.number_or("time_budget_s", 0.0);
  if (const toml::node* m = r.get("magnitude")) {
    b.magnitude = r.number(*m, "magnitude");
    if (scene.load.guidewire) {
      r.fail(m, "magnitude",
             "found with a guidewire load; expected none (its one magnitude is the wire's force, "
             "found when the wire is solved)");
    }
    const auto& mags = scene.load.magnitudes;
    if (std::none_of(mags.begin(), mags.end(), [&](double v) {
          return std::abs(v - b.magnitude) <= 1e-12 * std::max(std::abs(v), 1e-300);
        })) {
      std::ostringstream found;
      found << "found " << b.magnitude << ", expected one of the load's magnitudes";
      r.fail(m, "magnitude", found.str());
    }
  }
  if (b.rate_hz == 0.0 && b.time_budget_s == 0.0) {
    r.fail(nullptr, "rate_hz",
           "missing; expected rate_hz (30 visual, 1000 haptic) or time_budget_s per update");
  }
  return b;
}

}  // namespace

Scene parse_scene(std::string_view text, const std::string& source_name) {
  toml::table root;
  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    throw InputError(source_name + ":" + std::to_string(e.source().begin.line) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
  Scene scene;
  scene.source = source_name;
  TableReader r(root, "", "", source_name);
  scene.name = r.string_or("name", "");
  if (scene.name.empty()) r.fail(r.get("name"), "name", "found \"\", expected the scene's name");
  scene.description = r.string_or("description");
  scene.vessel =
      read_vessel(r.sub("vessel"), scene.model_levels, scene.reference_level, source_name);

  const TableReader material = r.sub("material");
  scene.youngs_modulus = material.number_or("E");
  if (const toml::node* nu = material.get("nu")) scene.poisson_ratios = material.numbers(*nu, "nu");
  scene.density = material.number_or("density");

  const TableReader boundary = r.sub("boundary");
  for (const auto& group : {std::string(group_names::inlet), std::string(group_names::outlet)}) {
    scene.boundary[group] = parse_end_condition(boundary.string_or(group));
  }

  scene.load = read_load(r.sub("load"), scene.vessel);
  read_models(r, scene);
  scene.tolerances.max_error_mm = r.sub("tolerances").number_or("max_error_mm");
  if (r.get("budget")) scene.budget = read_budget(r.sub("budget"), scene);
  const TableReader modes = r.sub("modes");
  scene.modes.count = static_cast<int>(modes.integer_or("count", 0));
  scene.modes.reference_level = static_cast<int>(modes.integer_or("reference_level", -1));
  scene.transient.reference_level =
      static_cast<int>(r.sub("transient").integer_or("reference_level", -1));
  const std::string reference = r.string_or("reference");
  scene.reference = reference == "finite-strain" ? ReferenceChoice::finite_strain
                    : reference == "auto"        ? ReferenceChoice::automatic
                                                 : ReferenceChoice::linear;
  return scene;
}

Scene read_scene(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": scene file not found");
  if (!in) throw InputError(path.string() + ": cannot open scene file");
  std::ostringstream text;
  text << in.rdbuf();
  Scene scene = parse_scene(text.str(), path.string());
  check_model_inputs(scene);  // the files its models read: found now, not minutes into a run
  return scene;
}

std::string to_string(LoadKind kind) {
  switch (kind) {
    case LoadKind::contact: return "contact";
    case LoadKind::pressure: return "pressure";
    case LoadKind::gravity: return "gravity";
  }
  return "?";
}

std::string to_string(ReferenceChoice choice) {
  switch (choice) {
    case ReferenceChoice::linear: return "linear";
    case ReferenceChoice::finite_strain: return "finite-strain";
    case ReferenceChoice::automatic: return "auto";
  }
  return "?";
}

std::string to_string(BudgetQuantity q) {
  switch (q) {
    case BudgetQuantity::contact_point:
      return "contact_point";
    case BudgetQuantity::patch:
      return "patch";
    case BudgetQuantity::field:
      return "field";
    case BudgetQuantity::reaction:
      return "reaction";
    case BudgetQuantity::contact_force:
      return "contact_force";
  }
  return "?";
}

BudgetQuantity parse_budget_quantity(const std::string& name) {
  for (const auto q : {BudgetQuantity::contact_point, BudgetQuantity::patch, BudgetQuantity::field,
                       BudgetQuantity::reaction, BudgetQuantity::contact_force}) {
    if (name == to_string(q)) return q;
  }
  throw InputError(
      "budget quantity: expected one of contact_point, patch, field, reaction, contact_force; got "
      "'" +
      name + "'");
}

const char* budget_unit(BudgetQuantity q) {
  return q == BudgetQuantity::reaction || q == BudgetQuantity::contact_force ? "mN" : "mm";
}

std::string to_string(ModelKind kind) {
  switch (kind) {
    case ModelKind::fem: return "fem";
    case ModelKind::surface_msm: return "surface_msm";
    case ModelKind::volume_msm: return "volume_msm";
    case ModelKind::network: return "network";
    case ModelKind::external: return "external";
    case ModelKind::displacements: return "displacements";
    case ModelKind::corotational_fem: return "corotational_fem";
    case ModelKind::xpbd_fem: return "xpbd_fem";
  }
  return "?";
}

std::string to_string(ExchangeNodes nodes) {
  return nodes == ExchangeNodes::surface ? "surface" : "volume";
}

}  // namespace vessel
