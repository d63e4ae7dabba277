#include "verification/scene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "meshes/foundation/errors.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/solvers/integrators.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "verification/model_capabilities.hpp"

namespace vessel {

namespace {

// Every choice of a model is checked by the msm library's own parser (one list of names, theirs).

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string show(const toml::node& node) {
  std::ostringstream s;
  node.visit([&](auto&& v) {
    using T = std::remove_cvref_t<decltype(v)>;
    if constexpr (toml::is_string<T>) {
      s << '"' << *v << '"';
    } else if constexpr (toml::is_table<T>) {
      s << "a table";
    } else if constexpr (toml::is_array<T>) {
      s << "an array";
    } else if constexpr (toml::is_boolean<T>) {
      s << (*v ? "true" : "false");
    } else {
      s << *v;  // numbers, dates and times
    }
  });
  return s.str();
}

/// Reads one TOML table strictly: every key must be asked for, every value must have the asked
/// type and range; messages say "file:line: key 'a.b': found X, expected Y".
class TableReader {
 public:
  TableReader(const toml::table& table, std::string prefix, const std::string& file)
      : table_(table), prefix_(std::move(prefix)), file_(file) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key,
                         const std::string& what) const {
    const auto line = node ? node->source().begin.line : table_.source().begin.line;
    const std::string where = key.empty() ? "[" + prefix_.substr(0, prefix_.size() - 1) + "]"
                                          : "key '" + prefix_ + key + "'";
    throw InputError(file_ + ":" + std::to_string(line) + ": " + where + ": " + what);
  }

  const toml::node* get(const std::string& key) {
    known_.push_back(key);
    return table_.get(key);
  }

  const toml::node& require(const std::string& key, const std::string& expected) {
    const toml::node* n = get(key);
    if (!n) fail(nullptr, key, "missing; expected " + expected);
    return *n;
  }

  /// A number (integer or float), finite, within [lo, hi].
  double number(const toml::node& n, const std::string& key, double lo, double hi,
                const std::string& unit) const {
    std::optional<double> v;
    if (n.is_floating_point() || n.is_integer()) v = n.value<double>();
    std::ostringstream range;
    range << "a number in [" << lo << ", " << hi << "]" << (unit.empty() ? "" : " " + unit);
    if (!v) fail(&n, key, "found " + show(n) + ", expected " + range.str());
    if (!std::isfinite(*v) || *v < lo || *v > hi) {
      std::ostringstream found;
      found << *v;
      fail(&n, key, "found " + found.str() + ", expected " + range.str());
    }
    return *v;
  }

  double number_or(const std::string& key, double fallback, double lo, double hi,
                   const std::string& unit = "") {
    const toml::node* n = get(key);
    return n ? number(*n, key, lo, hi, unit) : fallback;
  }

  double positive(const std::string& key, double fallback, const std::string& unit) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    const double v = number(*n, key, 0.0, HUGE_VAL, unit);
    if (v <= 0.0) fail(n, key, "found 0, expected a number > 0 " + unit);
    return v;
  }

  long integer_or(const std::string& key, long fallback, long lo, long hi) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    const auto v = n->value_exact<int64_t>();
    if (!v || *v < lo || *v > hi) {
      fail(n, key, "found " + show(*n) + ", expected an integer in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
    }
    return static_cast<long>(*v);
  }

  /// An integer or an array of integers, each within [lo, hi]; at least one.
  std::vector<int> integers_or(const std::string& key, std::vector<int> fallback, long lo, long hi) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    std::vector<const toml::node*> items;
    if (const auto* arr = n->as_array()) {
      if (arr->empty()) fail(n, key, "found an empty array, expected at least one integer");
      for (const auto& item : *arr) items.push_back(&item);
    } else {
      items.push_back(n);
    }
    std::vector<int> out;
    for (const toml::node* item : items) {
      const auto v = item->value_exact<int64_t>();
      if (!v || *v < lo || *v > hi) {
        fail(item, key, "found " + show(*item) + ", expected an integer in [" + std::to_string(lo) +
                            ", " + std::to_string(hi) + "] or an array of them");
      }
      out.push_back(static_cast<int>(*v));
    }
    return out;
  }
  /// A string, or an array of strings, each accepted by `parse` (an msm parse_* function); its
  /// InputError becomes this key's.
  template <class Parse>
  std::vector<std::string> names_or(const std::string& key, const std::string& fallback,
                                    Parse&& parse) {
    const toml::node* n = get(key);
    if (!n) return {fallback};
    std::vector<const toml::node*> items;
    if (const auto* arr = n->as_array()) {
      if (arr->empty()) fail(n, key, "found an empty array, expected at least one name");
      for (const auto& item : *arr) items.push_back(&item);
    } else {
      items.push_back(n);
    }
    std::vector<std::string> out;
    for (const toml::node* item : items) {
      const auto v = item->value_exact<std::string>();
      if (!v) fail(item, key, "found " + show(*item) + ", expected a string or an array of strings");
      try {
        (void)parse(*v);
      } catch (const InputError& e) {
        fail(item, key, e.what());
      }
      out.push_back(*v);
    }
    return out;
  }
  /// One string accepted by `parse` (an msm parse_* function), not an array.
  template <class Parse>
  std::string name_or(const std::string& key, const std::string& fallback, Parse&& parse) {
    const toml::node* n = table_.get(key);
    if (n && n->is_array()) fail(n, key, "found an array, expected one string");
    return names_or(key, fallback, std::forward<Parse>(parse)).front();
  }
  bool boolean_or(const std::string& key, bool fallback) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    const auto v = n->value_exact<bool>();
    if (!v) fail(n, key, "found " + show(*n) + ", expected true or false");
    return *v;
  }
  std::string string_or(const std::string& key, const std::string& fallback,
                        const std::vector<std::string>& allowed = {}) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    const auto v = n->value_exact<std::string>();
    const std::string expected =
        allowed.empty() ? "a string" : "one of " + join(allowed);
    if (!v) fail(n, key, "found " + show(*n) + ", expected " + expected);
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), *v) == allowed.end()) {
      fail(n, key, "found \"" + *v + "\", expected " + expected);
    }
    return *v;
  }

  /// A number or an array of numbers, each within [lo, hi]; at least one.
  std::vector<double> numbers(const toml::node& n, const std::string& key, double lo, double hi,
                              const std::string& unit) const {
    std::vector<double> out;
    if (const auto* arr = n.as_array()) {
      if (arr->empty()) fail(&n, key, "found an empty array, expected at least one number");
      for (const auto& item : *arr) out.push_back(number(item, key, lo, hi, unit));
    } else {
      out.push_back(number(n, key, lo, hi, unit));
    }
    return out;
  }

  Vec3 vector3(const toml::node& n, const std::string& key) const {
    const auto* arr = n.as_array();
    if (!arr || arr->size() != 3) fail(&n, key, "found " + show(n) + ", expected [x, y, z]");
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = number(*arr->get(i), key, -HUGE_VAL, HUGE_VAL, "");
    return v;
  }

  TableReader sub(const std::string& key, bool required) {
    const toml::node* n = get(key);
    if (!n) {
      if (required) fail(nullptr, key, "missing; expected a [" + prefix_ + key + "] table");
      return TableReader(empty_, prefix_ + key + ".", file_);
    }
    if (!n->is_table()) fail(n, key, "found " + show(*n) + ", expected a table");
    return TableReader(*n->as_table(), prefix_ + key + ".", file_);
  }

  /// Fails on the first key that was never asked for.
  void finish() const {
    for (const auto& [key, node] : table_) {
      const std::string k(key.str());
      if (std::find(known_.begin(), known_.end(), k) == known_.end()) {
        fail(&node, k, "unknown key; expected one of: " + join(known_));
      }
    }
  }

  const toml::table& table() const { return table_; }
  const std::string& prefix() const { return prefix_; }

 private:
  inline static const toml::table empty_{};
  const toml::table& table_;
  std::string prefix_;
  std::string file_;
  std::vector<std::string> known_;
};

/// A vessel from a file (`file = "x.msh"` or `lumen = "x.stl"`), paths relative to the scene's
/// folder. A mesh file is used as given: its one level is 0, and a scene asking for another is an
/// error. A lumen needs its wall_thickness (m) and may say `units = "mm"`; levels refine it.
VesselParams read_file_vessel(TableReader& r, const std::string& scene_file,
                              std::vector<int>& levels, int& reference_level) {
  VesselParams p;
  const toml::node* file = r.get("file");
  const toml::node* lumen = r.get("lumen");
  if (file && lumen) {
    r.fail(lumen, "lumen", "found with `file`; expected one of them: a tet mesh (.msh) or a lumen surface (STL)");
  }
  const std::string key = file ? "file" : "lumen";
  const auto name = (file ? file : lumen)->value_exact<std::string>();
  if (!name || name->empty()) {
    r.fail(file ? file : lumen, key, "found " + show(file ? *file : *lumen) + ", expected a file name");
  }
  p.file = *name;
  if (p.file.is_relative()) p.file = std::filesystem::path(scene_file).parent_path() / p.file;
  p.kind = file ? VesselKind::mesh_file : VesselKind::lumen;
  p.style = MeshStyle::unstructured;
  levels = r.integers_or("level", {0}, 0, kMaxMeshLevel);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  reference_level =
      static_cast<int>(r.integer_or("reference_level", levels.back(), 0, kMaxMeshLevel));
  if (file) {
    if (levels != std::vector<int>{0} || reference_level != 0) {
      r.fail(r.table().get(levels != std::vector<int>{0} ? "level" : "reference_level"),
             levels != std::vector<int>{0} ? "level" : "reference_level",
             "found a level other than 0 with a mesh file; expected 0 or none (a .msh file is "
             "used as given, its one level: mesh it finer yourself, or give a lumen STL, which "
             "levels refine)");
    }
    // Optional: the surface models' shell thickness; else estimated from the mesh
    // (file_vessel_wall_thickness).
    p.wall_thickness = r.positive("wall_thickness", 0.0, "m");
  } else {
    const toml::node* t = r.get("wall_thickness");
    if (!t) r.fail(nullptr, "wall_thickness", "missing; a lumen needs the wall's thickness (m) to extrude it outward");
    p.wall_thickness = r.positive("wall_thickness", 0.0, "m");
    const std::string units = r.string_or("units", "m", {"m", "mm"});
    p.file_scale = units == "mm" ? 1e-3 : 1.0;
  }
  p.level = levels.front();
  r.finish();
  if (!std::filesystem::exists(p.file)) {
    r.fail(file ? file : lumen, key, "file " + p.file.string() + " not found");
  }
  return p;
}

VesselParams read_vessel(TableReader r, std::vector<int>& levels, int& reference_level,
                         const std::string& scene_file) {
  if (r.table().contains("file") || r.table().contains("lumen")) {
    return read_file_vessel(r, scene_file, levels, reference_level);
  }
  VesselParams p;
  const std::string kind = r.string_or("kind", "straight", {"straight", "arch"});
  p.kind = kind == "arch" ? VesselKind::arch : VesselKind::straight;
  p.inner_radius = r.positive("inner_radius", p.inner_radius, "m");
  p.wall_thickness = r.positive("wall_thickness", p.wall_thickness, "m");
  p.length = r.positive("length", p.length, "m");
  p.bend_radius = r.positive("bend_radius", p.bend_radius, "m");
  const std::string mesh = r.string_or("mesh", "structured", {"structured", "unstructured"});
  p.style = mesh == "structured" ? MeshStyle::structured : MeshStyle::unstructured;
  levels = r.integers_or("level", {0}, 0, kMaxMeshLevel);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  p.level = levels.front();
  reference_level =
      static_cast<int>(r.integer_or("reference_level", levels.back(), 0, kMaxMeshLevel));
  r.finish();
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
  const std::vector<int> degrees = r.integers_or("degree", {2}, 1, 2);
  r.finish();
  std::vector<ModelSpec> out;
  for (const int d : degrees) {
    ModelSpec c = m;
    c.degree = d;
    if (degrees.size() > 1) c.name += "[degree=" + std::to_string(d) + "]";
    out.push_back(c);
  }
  return out;
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
  std::vector<double> radii = r.numbers(*roi, "roi_radius", 0.0, HUGE_VAL, "m");
  for (const double v : radii) {
    if (v <= 0.0) r.fail(roi, "roi_radius", "found 0, expected a radius > 0 m");
  }
  return radii;
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
    const toml::node* c = r.get("command");
    const auto* arr = c ? c->as_array() : nullptr;
    const std::string expected =
        "a non-empty array of strings, the program and its arguments (e.g. [\"python3\", "
        "\"model.py\"]); the manifest's path is appended";
    if (!c) r.fail(nullptr, "command", "missing; expected " + expected);
    if (!arr || arr->empty()) r.fail(c, "command", "found " + show(*c) + ", expected " + expected);
    for (const auto& item : *arr) {
      const auto v = item.value_exact<std::string>();
      if (!v || v->empty()) r.fail(&item, "command", "found " + show(item) + ", expected " + expected);
      e.command.push_back(*v);
    }
    e.timeout_s = r.positive("timeout_s", e.timeout_s, "s");
  } else {
    const toml::node* f = r.get("file");
    const auto v = f ? f->value_exact<std::string>() : std::nullopt;
    const std::string expected =
        "the folder of case folders with the answers (as `vesselverify export` wrote them, one "
        "folder per case holding displacements.csv or displacements.vtu)";
    if (!f) r.fail(nullptr, "file", "missing; expected " + expected);
    if (!v || v->empty()) r.fail(f, "file", "found " + show(*f) + ", expected " + expected);
    e.directory = *v;
  }
  e.nodes = r.string_or("nodes", "volume", {"volume", "surface"}) == "surface"
                ? ExchangeNodes::surface
                : ExchangeNodes::volume;
  if (const toml::node* sf = r.table().get("surface"); sf && e.nodes != ExchangeNodes::surface) {
    r.get("surface");
    r.fail(sf, "surface", "found a wall surface with nodes = \"volume\"; expected it only with "
                          "nodes = \"surface\"");
  }
  e.surface = msm::parse_wall_surface(
      r.name_or("surface", msm::to_string(e.surface), msm::parse_wall_surface));
  const toml::node* dt = r.get("dt");
  const toml::node* steps = r.table().get("steps");
  if (dt || steps) {
    if (!dt) r.fail(steps, "steps", "found steps without dt; expected both (a dynamic problem) or neither");
    if (!steps) r.fail(dt, "dt", "found dt without steps; expected both (a dynamic problem) or neither");
    e.dt = r.number(*dt, "dt", 0.0, HUGE_VAL, "s");
    if (e.dt <= 0.0) r.fail(dt, "dt", "found 0, expected a time step > 0 s");
  }
  e.steps = r.integer_or("steps", 0, 1, 1'000'000'000L);
  r.finish();
  return {m};
}

/// A mass-spring table's wall keys: `surface`, `topology` and `bending` (surface models),
/// `volume_term`, `volume_moduli` and `edge_pairs` (volume models).
void read_wall_options(TableReader& r, ModelSpec& m) {
  if (m.kind == ModelKind::surface_msm) {
    m.surface = msm::parse_wall_surface(r.name_or("surface", msm::to_string(m.surface), msm::parse_wall_surface));
    m.topology = msm::parse_topology(r.name_or("topology", "auto", msm::parse_topology));
    // `bending = "discrete-shells"`: the hinge energy of Grinspun et al. 2003 on the triangles
    // (msm/terms/bending_term.hpp), membrane springs van-gelder by default.
    m.bending = msm::parse_bending(r.name_or("bending", "none", msm::parse_bending));
    if (m.bending != msm::Bending::none && m.topology == msm::Topology::grid) {
      r.fail(r.table().get("topology"), "topology",
             "found \"grid\" with bending = \"discrete-shells\"; expected \"triangles\" or "
             "\"auto\" (the hinges replace the triangle topology's bend springs)");
    }
  }
  if (m.kind == ModelKind::volume_msm) {
    m.volume_term = r.boolean_or("volume_term", false);
    // volume_moduli = "golec" | "homogenised": the volume term's (E_s, κ) rule.
    m.volume_moduli =
        msm::parse_volume_moduli(r.name_or("volume_moduli", "golec", msm::parse_volume_moduli));
    if (m.volume_moduli != msm::VolumeModuli::golec && !m.volume_term) {
      r.fail(r.table().get("volume_moduli"), "volume_moduli",
             "found \"" + msm::to_string(m.volume_moduli) +
                 "\" without volume_term = true; expected volume_term = true with it");
    }
    // edge_pairs = true: the springs coupled in each tet's edge pairs (Kikuuwe et al. 2009), StVK
    // P1 on the edges; it has no springs of its own, so no stiffness rule and no volume term.
    m.edge_pairs = r.boolean_or("edge_pairs", false);
    if (m.edge_pairs && m.volume_term) {
      r.fail(r.table().get("edge_pairs"), "edge_pairs",
             "found true with volume_term = true; expected one of them (the edge-pair model "
             "reaches any ν < 0.5 by itself)");
    }
    if (m.edge_pairs && r.table().get("stiffness")) {
      r.fail(r.table().get("stiffness"), "stiffness",
             "found with edge_pairs = true; expected no stiffness key (the edge-pair model's "
             "coefficients come from each tet's StVK energy, not from a spring rule)");
    }
  }
}

/// Refuses PBD where it cannot run: on a network file, a volume model or with bending.
void check_pbd(TableReader& r, const ModelSpec& m, const std::vector<std::string>& solvers) {
  if (std::find(solvers.begin(), solvers.end(), "pbd") == solvers.end()) return;
  const toml::node* key = r.table().get("solver");
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
    dts = r.numbers(*dt, "dt", 0.0, HUGE_VAL, "s");
    for (const double v : dts) {
      if (v <= 0.0) r.fail(dt, "dt", "found 0, expected a time step > 0 s");
    }
    m.solver.steps = r.integer_or("steps", 0, 1, 1'000'000'000L);
    if (m.solver.steps == 0) r.fail(nullptr, "steps", "missing; expected the number of steps (> 0)");
  }
  // `iterations`: local–global iterations per step of local-global-euler (Liu et al. 2013).
  if (const toml::node* it = r.get("iterations")) {
    if (std::find(solvers.begin(), solvers.end(), "local-global-euler") == solvers.end()) {
      r.fail(it, "iterations",
             "found local-global iterations without solver \"local-global-euler\"; expected it "
             "only with that solver");
    }
    m.solver.local_global.iterations = static_cast<int>(
        r.integer_or("iterations", m.solver.local_global.iterations, 1, 1'000'000L));
  }
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
  const std::string kind = r.string_or(
      "kind", "", {"fem", "surface_msm", "volume_msm", "network", "external", "displacements"});
  if (kind.empty()) {
    r.fail(nullptr, "kind",
           "missing; expected one of fem, surface_msm, volume_msm, network, external, "
           "displacements");
  }
  m.kind = kind == "fem"             ? ModelKind::fem
           : kind == "surface_msm"   ? ModelKind::surface_msm
           : kind == "network"       ? ModelKind::network
           : kind == "external"      ? ModelKind::external
           : kind == "displacements" ? ModelKind::displacements
                                     : ModelKind::volume_msm;
  m.name = r.string_or("name", kind + "_" + std::to_string(index + 1));
  if (m.kind == ModelKind::fem) return fem_models(r, m);
  if (m.kind == ModelKind::external || m.kind == ModelKind::displacements) {
    return outside_model(r, m);
  }
  const bool network = m.kind == ModelKind::network;
  if (network) {
    // A spring network from a file: its springs, masses and supports come from the file, so the
    // stiffness, mass, topology and calibration keys are unknown here.
    m.network_file = r.string_or("file", "");
    if (m.network_file.empty()) {
      r.fail(nullptr, "file", "missing; expected the spring-network file (.json or .vtu)");
    }
  }
  read_wall_options(r, m);
  const auto stiffness = network ? std::vector<std::string>{msm::to_string(m.stiffness)} :
      r.names_or("stiffness",
                 m.kind == ModelKind::volume_msm
                     ? (m.volume_term ? "van-gelder" : "seed001")
                     : (m.bending != msm::Bending::none ? "van-gelder" : "seed000"),
                 msm::parse_stiffness_rule);
  if (m.volume_term) {
    for (const auto& k : stiffness) {
      if (msm::parse_stiffness_rule(k) != msm::StiffnessRule::van_gelder) {
        r.fail(r.table().get("stiffness"), "stiffness",
               "found \"" + k + "\" with volume_term = true; expected \"van-gelder\" (the hybrid "
               "volume model's κ = λ − μ assumes van-gelder springs, whose λ = μ)");
      }
    }
  }
  const auto mass = network ? std::vector<std::string>{msm::to_string(m.mass)}
                            : r.names_or("mass", "consistent", msm::parse_mass_rule);
  const auto solvers = r.names_or("solver", "static", msm::parse_solver);
  check_pbd(r, m, solvers);
  m.damping = r.number_or("damping", 0.0, 0.0, HUGE_VAL, "N·s/m");
  if (!network) {
    m.calibration = r.string_or("calibration", "");
    m.calibration_transfer = r.boolean_or("calibration_transfer", false);
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
  r.finish();
  return sweep(m, stiffness, mass, solvers, dts, radii);
}

LoadSpec read_load(TableReader r) {
  LoadSpec load;
  const std::string type = r.string_or("type", "", {"contact", "pressure", "gravity"});
  if (type.empty()) r.fail(nullptr, "type", "missing; expected one of contact, pressure, gravity");
  load.kind = type == "contact" ? LoadKind::contact
                                : (type == "pressure" ? LoadKind::pressure : LoadKind::gravity);
  const char* unit = load.kind == LoadKind::contact ? "N" : (load.kind == LoadKind::pressure ? "Pa" : "g");
  load.magnitudes = r.numbers(r.require("magnitudes", std::string("a number or array of numbers (") + unit + ")"),
                              "magnitudes", 0.0, HUGE_VAL, unit);
  if (load.kind == LoadKind::contact) {
    load.contact.point = r.vector3(r.require("point", "[x, y, z] in m on the wall"), "point");
    load.contact.radius = r.positive("patch_radius", load.contact.radius, "m");
    load.contact.surface_group =
        r.string_or("surface", load.contact.surface_group, {"inner_wall", "outer_wall"});
  } else if (load.kind == LoadKind::pressure) {
    load.contact.surface_group = r.string_or("surface", "inner_wall", {"inner_wall", "outer_wall"});
  } else {
    if (const toml::node* d = r.get("direction")) {
      load.gravity_direction = r.vector3(*d, "direction");
      if (load.gravity_direction.norm() == 0.0) r.fail(d, "direction", "found [0, 0, 0], expected a non-zero vector");
      load.gravity_direction.normalize();
    }
  }
  r.finish();
  return load;
}

/// The [budget] table (issue #7): quantity, its tolerance, a rate or time budget, the load.
Budget read_budget(TableReader r, const Scene& scene) {
  Budget b;
  b.stated = true;
  const toml::node* q = r.get("quantity");
  if (q) {
    const auto name = q->value_exact<std::string>();
    try {
      if (!name) throw InputError("");
      b.quantity = parse_budget_quantity(*name);
    } catch (const InputError&) {
      r.fail(q, "quantity",
             "found " + show(*q) + ", expected one of contact_point, patch, field, reaction");
    }
  }
  const bool contact = scene.load.kind == LoadKind::contact;
  if (b.quantity == BudgetQuantity::reaction && !contact) {
    r.fail(q, "quantity",
           "found \"reaction\" with a " + to_string(scene.load.kind) +
               " load; expected a contact load (the instrument's force)");
  }
  const toml::node* radius = r.get("radius");
  if (b.quantity == BudgetQuantity::patch) {
    if (!radius) r.fail(nullptr, "radius", "missing; quantity \"patch\" needs a radius > 0 m");
    b.radius = r.number(*radius, "radius", 0.0, HUGE_VAL, "m");
    if (b.radius <= 0.0) r.fail(radius, "radius", "found 0, expected a radius > 0 m");
  } else if (radius) {
    r.fail(radius, "radius",
           "found a radius with quantity \"" + to_string(b.quantity) +
               "\"; expected it only with quantity \"patch\"");
  }
  const toml::node* mm = r.get("tolerance_mm");
  const toml::node* mn = r.get("tolerance_mN");
  if (b.quantity == BudgetQuantity::reaction) {
    if (mm)
      r.fail(mm, "tolerance_mm",
             "found a displacement tolerance; quantity \"reaction\" "
             "expected tolerance_mN (a force, mN)");
    if (!mn)
      r.fail(nullptr, "tolerance_mN",
             "missing; quantity \"reaction\" needs a force "
             "tolerance > 0 mN");
    b.tolerance = r.number(*mn, "tolerance_mN", 0.0, HUGE_VAL, "mN");
    if (b.tolerance <= 0.0) r.fail(mn, "tolerance_mN", "found 0, expected a tolerance > 0 mN");
  } else {
    if (mn)
      r.fail(mn, "tolerance_mN",
             "found a force tolerance with quantity \"" + to_string(b.quantity) +
                 "\"; expected tolerance_mm");
    b.tolerance = scene.tolerances.max_error_mm;  // [tolerances], itself 0.1 mm by default
    if (mm) {
      b.tolerance = r.number(*mm, "tolerance_mm", 0.0, HUGE_VAL, "mm");
      if (b.tolerance <= 0.0) r.fail(mm, "tolerance_mm", "found 0, expected a tolerance > 0 mm");
    }
  }
  b.rate_hz = r.positive("rate_hz", 0.0, "Hz");
  b.time_budget_s = r.positive("time_budget_s", 0.0, "s");
  if (const toml::node* m = r.get("magnitude")) {
    b.magnitude = r.number(*m, "magnitude", 0.0, HUGE_VAL, "");
    const auto& mags = scene.load.magnitudes;
    if (std::none_of(mags.begin(), mags.end(), [&](double v) {
          return std::abs(v - b.magnitude) <= 1e-12 * std::max(std::abs(v), 1e-300);
        })) {
      std::ostringstream found;
      found << "found " << b.magnitude << ", expected one of the load's magnitudes";
      r.fail(m, "magnitude", found.str());
    }
  }
  r.finish();  // unknown keys (a misspelt rate) first
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
  TableReader r(root, "", source_name);
  scene.name = r.string_or("name", "");
  if (scene.name.empty()) r.fail(nullptr, "name", "missing; expected the scene's name");
  scene.description = r.string_or("description", "");
  scene.vessel =
      read_vessel(r.sub("vessel", true), scene.model_levels, scene.reference_level, source_name);

  TableReader material = r.sub("material", false);
  scene.youngs_modulus = material.positive("E", scene.youngs_modulus, "Pa");
  if (const toml::node* nu = material.get("nu")) {
    scene.poisson_ratios = material.numbers(*nu, "nu", 0.0, 0.5, "");
  }
  scene.density = material.positive("density", scene.density, "kg/m³");
  material.finish();

  TableReader boundary = r.sub("boundary", false);
  for (const auto& group : {std::string(group_names::inlet), std::string(group_names::outlet)}) {
    scene.boundary[group] = parse_end_condition(
        boundary.string_or(group, "clamped", {"clamped", "roller", "free"}));
  }
  boundary.finish();

  scene.load = read_load(r.sub("load", true));

  const toml::node* models = r.get("models");
  if (!models) r.fail(nullptr, "models", "missing; expected at least one [[models]] table");
  const auto* list = models->as_array();
  if (!list || list->empty()) r.fail(models, "models", "expected at least one [[models]] table");
  std::set<std::string> names;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const auto* t = list->get(i)->as_table();
    if (!t) r.fail(list->get(i), "models", "expected [[models]] tables");
    for (ModelSpec& m :
         read_model(TableReader(*t, "models[" + std::to_string(i) + "].", source_name), i,
                    scene.load.kind)) {
      // Models outside the suite: their command runs in the scene file's folder, and their
      // answers' folder is relative to it.
      m.external.working_dir = std::filesystem::path(source_name).parent_path();
      if (!m.external.directory.empty() && m.external.directory.is_relative()) {
        m.external.directory = m.external.working_dir / m.external.directory;
      }
      if (!m.calibration.empty() && m.calibration.is_relative()) {
        m.calibration = std::filesystem::path(source_name).parent_path() / m.calibration;
      }
      if (!m.network_file.empty() && m.network_file.is_relative()) {
        m.network_file = std::filesystem::path(source_name).parent_path() / m.network_file;
      }
      if (!names.insert(m.name).second) {
        r.fail(list->get(i), "models",
               "model name \"" + m.name + "\" is used twice; names must be unique");
      }
      scene.models.push_back(std::move(m));
    }
  }

  TableReader tol = r.sub("tolerances", false);
  scene.tolerances.max_error_mm = tol.positive("max_error_mm", scene.tolerances.max_error_mm, "mm");
  tol.finish();
  if (r.get("budget")) scene.budget = read_budget(r.sub("budget", false), scene);
  TableReader modes = r.sub("modes", false);
  scene.modes.count = static_cast<int>(modes.integer_or("count", 0, 0, 100));
  scene.modes.reference_level =
      static_cast<int>(modes.integer_or("reference_level", -1, 0, kMaxMeshLevel));
  modes.finish();
  TableReader transient = r.sub("transient", false);
  scene.transient.reference_level =
      static_cast<int>(transient.integer_or("reference_level", -1, 0, kMaxMeshLevel));
  transient.finish();
  const std::string reference =
      r.string_or("reference", "linear", {"linear", "finite-strain", "auto"});
  scene.reference = reference == "finite-strain" ? ReferenceChoice::finite_strain
                    : reference == "auto"        ? ReferenceChoice::automatic
                                                 : ReferenceChoice::linear;
  r.finish();
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
  }
  return "?";
}

BudgetQuantity parse_budget_quantity(const std::string& name) {
  for (const auto q : {BudgetQuantity::contact_point, BudgetQuantity::patch, BudgetQuantity::field,
                       BudgetQuantity::reaction}) {
    if (name == to_string(q)) return q;
  }
  throw InputError("budget quantity: expected one of contact_point, patch, field, reaction; got '" +
                   name + "'");
}

const char* budget_unit(BudgetQuantity q) { return q == BudgetQuantity::reaction ? "mN" : "mm"; }

std::string to_string(ModelKind kind) {
  switch (kind) {
    case ModelKind::fem: return "fem";
    case ModelKind::surface_msm: return "surface_msm";
    case ModelKind::volume_msm: return "volume_msm";
    case ModelKind::network: return "network";
    case ModelKind::external: return "external";
    case ModelKind::displacements: return "displacements";
  }
  return "?";
}

std::string to_string(ExchangeNodes nodes) {
  return nodes == ExchangeNodes::surface ? "surface" : "volume";
}

}  // namespace vessel
