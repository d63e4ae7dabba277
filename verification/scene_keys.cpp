#include "verification/scene_keys.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "meshes/vessel_geometry.hpp"
#include "msm/solvers/solve.hpp"
#include "verification/guidewire/guidewire_spec.hpp"

namespace vessel {

namespace {

/// Builds one row of the table: Row("vessel", "length", KeyType::number, "doc").positive("m").
struct Row {
  SceneKey k;
  Row(std::string section, std::string name, KeyType type, std::string doc) {
    k.section = std::move(section);
    k.name = std::move(name);
    k.type = type;
    k.doc = std::move(doc);
  }
  Row& dflt(std::string literal) { return k.default_value = std::move(literal), *this; }
  Row& note(std::string text) { return k.default_note = std::move(text), *this; }
  Row& unit(std::string u) { return k.unit = std::move(u), *this; }
  Row& range(double lo, double hi) { return k.min = lo, k.max = hi, *this; }
  Row& at_least(double lo) { return k.min = lo, *this; }
  Row& positive() { return k.min = 0.0, k.min_exclusive = true, *this; }
  Row& one_of(std::vector<std::string> c) { return k.choices = std::move(c), *this; }
  Row& in(std::vector<std::string> v) { return k.variants = std::move(v), *this; }
  Row& sweep() { return k.sweep = true, *this; }
  Row& required() { return k.required = true, *this; }
};

const std::vector<std::string> kSpringKinds{"surface_msm", "volume_msm"};
const std::vector<std::string> kMsmKinds{"surface_msm", "volume_msm", "network"};
const std::vector<std::string> kOutsideKinds{"external", "displacements"};
constexpr double kMaxSteps = 1e9;
const double kMaxLevel = kMaxMeshLevel;

std::vector<std::string> solver_names() { return {msm::kSolverNames.begin(), msm::kSolverNames.end()}; }

std::vector<SceneKey> top_and_vessel() {
  const std::vector<std::string> parametric{"parametric"};
  std::vector<Row> rows{
      Row("", "name", KeyType::string, "The scene's name, used in results and reports").required(),
      Row("", "description", KeyType::string, "One line for the report").dflt("\"\""),
      Row("", "reference", KeyType::string,
          "The FEM reference that judges the models: linear (small strain), finite-strain "
          "(neo-Hookean, same E and ν) or auto (finite-strain where the linear one's largest "
          "strain exceeds 5 %)")
          .dflt("\"linear\"").one_of({"linear", "finite-strain", "auto"}),
      Row("", "vessel", KeyType::table, "The vessel: a generated tube or arch, or a file").required(),
      Row("", "material", KeyType::table, "The wall's linear elastic material"),
      Row("", "boundary", KeyType::table, "The ends' supports"),
      Row("", "load", KeyType::table, "The load whose magnitudes the runs sweep").required(),
      Row("", "models", KeyType::tables, "The models run against the reference").required(),
      Row("", "tolerances", KeyType::table, "The error a model may make"),
      Row("", "budget", KeyType::table, "The accuracy and rate a simulator needs (recommend)"),
      Row("", "modes", KeyType::table, "Natural frequencies beside the FEM's"),
      Row("", "transient", KeyType::table, "The FEM transient the dynamic models are compared with"),
      Row("vessel", "kind", KeyType::string, "The generated vessel: a straight tube or a 180° arch")
          .dflt("\"straight\"").one_of({"straight", "arch"}).in(parametric),
      Row("vessel", "inner_radius", KeyType::number, "Lumen radius a").dflt("3e-3").unit("m")
          .positive().in(parametric),
      Row("vessel", "wall_thickness", KeyType::number, "Wall thickness t = b − a").dflt("1e-3")
          .unit("m").positive().in(parametric),
      Row("vessel", "wall_thickness", KeyType::number, "The surface models' shell thickness")
          .note("estimated from the mesh").unit("m").positive().in({"file"}),
      Row("vessel", "wall_thickness", KeyType::number, "The wall's thickness, extruded outward")
          .unit("m").positive().required().in({"lumen"}),
      Row("vessel", "length", KeyType::number, "Straight tube length").dflt("40e-3").unit("m")
          .positive().in(parametric),
      Row("vessel", "bend_radius", KeyType::number, "Arch centreline radius R (the arch spans 180°)")
          .dflt("15e-3").unit("m").positive().in(parametric),
      Row("vessel", "mesh", KeyType::string, "Hexahedra split into tets, or gmsh's tets")
          .dflt("\"structured\"").one_of({"structured", "unstructured"}).in(parametric),
      Row("vessel", "level", KeyType::integer,
          "Mesh level(s) the models run at; each halves the element size (an array: a "
          "convergence sweep; a mesh file: 0 only)")
          .dflt("0").range(0, kMaxLevel).sweep(),
      Row("vessel", "reference_level", KeyType::integer,
          "Finest level of the FEM reference (a mesh file: 0 only)")
          .note("the finest model level").range(0, kMaxLevel),
      Row("vessel", "file", KeyType::string,
          "A tet mesh (.msh) used as given; relative to the scene file's folder")
          .required().in({"file"}),
      Row("vessel", "lumen", KeyType::string,
          "A lumen surface (STL) extruded outward by wall_thickness and meshed; relative to the "
          "scene file's folder")
          .required().in({"lumen"}),
      Row("vessel", "units", KeyType::string, "The STL's length unit").dflt("\"m\"")
          .one_of({"m", "mm"}).in({"lumen"}),
      Row("vessel", "inlet_centre", KeyType::vector3,
          "The inlet end's centre, when the ends are listed by hand (with outlet_centres): "
          "every open loop of the lumen must then be a listed end")
          .unit("m").note("the ends found by their shape; the largest is the inlet")
          .in({"lumen"}),
      Row("vessel", "outlet_centres", KeyType::vectors3,
          "The outlet ends' centres, when the ends are listed by hand (with inlet_centre)")
          .unit("m").note("the ends found by their shape").in({"lumen"}),
  };
  std::vector<SceneKey> out;
  for (auto& r : rows) out.push_back(std::move(r.k));
  return out;
}

/// The guidewire load's keys (verification/guidewire/guidewire_load.hpp).
std::vector<Row> guidewire_rows() {
  const std::vector<std::string> g{"guidewire"};
  return {
      Row("load", "E", KeyType::number, "The wire's Young's modulus").unit("Pa").positive()
          .required().in(g),
      Row("load", "G", KeyType::number, "The wire's shear modulus (give G or nu)").unit("Pa")
          .note("E / (2 (1 + nu))").positive().in(g),
      Row("load", "nu", KeyType::number, "The wire's Poisson's ratio (give G or nu)")
          .dflt("0.33").range(0.0, 0.5).in(g),
      Row("load", "density", KeyType::number, "The wire's density").dflt("6450.0").unit("kg/m³")
          .positive().in(g),
      Row("load", "diameter", KeyType::number, "The wire's diameter (a solid section)").unit("m")
          .positive().required().in(g),
      Row("load", "insertion", KeyType::number, "Length of wire beyond the clamp").unit("m")
          .positive().required().in(g),
      Row("load", "segments", KeyType::integer, "Segments of the discrete wire").dflt("32")
          .range(4, 10000).in(g),
      Row("load", "model", KeyType::string,
          "The rod model: der (Discrete Elastic Rods), corde (seed 002's CORDE rod) or xpbd "
          "(the XPBD Cosserat rod's steady state) of msm/rods, or external (your own program, "
          "`command`)")
          .dflt("\"der\"").one_of(wire_model_names()).in(g),
      Row("load", "command", KeyType::strings,
          "model = \"external\": your wire program and its arguments (the case's manifest path "
          "is appended; it runs in the scene file's folder)").in(g),
      Row("load", "timeout_s", KeyType::number,
          "model = \"external\": each run of the wire program is killed after this").dflt("120.0")
          .unit("s").positive().in(g),
      Row("load", "clamp_point", KeyType::vector3,
          "The clamp (with clamp_direction); absent: the inlet's centreline point")
          .unit("m").in(g),
      Row("load", "clamp_direction", KeyType::vector3,
          "The wire's tangent at the clamp (normalised; with clamp_point)").in(g),
      Row("load", "tilt", KeyType::number,
          "Without clamp_point: the angle from the inlet's centreline tangent towards tilt_towards")
          .dflt("0.0").unit("rad").range(0.0, 1.5).in(g),
      Row("load", "tilt_towards", KeyType::vector3,
          "Without clamp_point: the direction the wire tilts towards (its part normal to the "
          "inlet's tangent)")
          .dflt("[1.0, 0.0, 0.0]").in(g),
      Row("load", "coupling", KeyType::string,
          "rigid: every model gets the wire's force against the rigid lumen; compliant: also each "
          "model's own force with its wall giving way (linear walls, series springs); contact: "
          "also each model's wall in a contact solve with the wire's surface, against the FEM "
          "wall's")
          .dflt("\"rigid\"").one_of({"rigid", "compliant", "contact"}).in(g),
      Row("load", "stiffness_sweep", KeyType::number,
          "Compliant or contact coupling: wire bending stiffnesses EI the coupling is repeated at "
          "(E scaled), with each wall's compliance of the run")
          .unit("N·m²").positive().sweep().in(g),
      Row("load", "contact_fine_size", KeyType::number,
          "Contact coupling: the contact mesh's element size near the wire's rigid contact")
          .dflt("0.08e-3").unit("m").positive().in(g),
      Row("load", "contact_fine_radius", KeyType::number,
          "Contact coupling: the radius of the contact mesh's refined region around the wire's "
          "rigid contact (wider for a stiff wire whose contact slides)")
          .dflt("1e-3").unit("m").positive().in(g),
      Row("load", "contact_wall", KeyType::string,
          "Contact coupling: linear: every wall linearised at rest, an EI whose series springs "
          "dent the reference's wall deeper than it is thick not solved; neo-hookean: the "
          "reference the finite-strain neo-Hookean FEM wall and each model at its own nonlinear "
          "equilibrium, at every EI (minutes per EI)")
          .dflt("\"linear\"").one_of({"linear", "neo-hookean"}).in(g),
      Row("load", "contact_p1_start", KeyType::boolean,
          "Contact coupling with contact_wall = \"neo-hookean\": the P2 reference solved first "
          "with P1 on the same mesh and P2 from P1's equilibrium (needed in the arch, where P2 "
          "from rest stalls; it does not pay on the straight tube)")
          .dflt("false").in(g),
  };
}

std::vector<SceneKey> material_to_load() {
  const std::vector<std::string> walls{"inner_wall", "outer_wall"};
  const std::vector<std::string> ends{"clamped", "roller", "free"};
  std::vector<Row> rows{
      Row("material", "E", KeyType::number, "Young's modulus").dflt("14.24e3").unit("Pa").positive(),
      Row("material", "nu", KeyType::number, "Poisson's ratio (an array: one run per value)")
          .dflt("0.45").range(0.0, 0.5).sweep(),
      Row("material", "density", KeyType::number, "Mass density").dflt("1060.0").unit("kg/m³")
          .positive(),
      Row("boundary", "inlet", KeyType::string, "The inlet end's support").dflt("\"clamped\"")
          .one_of(ends),
      Row("boundary", "outlet", KeyType::string, "The outlet end's support").dflt("\"clamped\"")
          .one_of(ends),
      Row("load", "type", KeyType::string, "The load")
          .one_of({"contact", "pressure", "gravity", "guidewire"})
          .required(),
      Row("load", "magnitudes", KeyType::number, "Contact forces the runs sweep, pushing into the wall")
          .unit("N").at_least(0.0).sweep().required().in({"contact"}),
      Row("load", "magnitudes", KeyType::number, "Pressures the runs sweep").unit("Pa")
          .at_least(0.0).sweep().required().in({"pressure"}),
      Row("load", "magnitudes", KeyType::number, "Gravities the runs sweep, in multiples of 9.81 m/s²")
          .unit("g").at_least(0.0).sweep().required().in({"gravity"}),
      Row("load", "point", KeyType::vector3, "The contact point on the wall").unit("m").required()
          .in({"contact"}),
      Row("load", "patch_radius", KeyType::number, "Radius of the contact patch").dflt("0.5e-3")
          .unit("m").positive().in({"contact", "guidewire"}),
      Row("load", "surface", KeyType::string, "The wall the load acts on").dflt("\"inner_wall\"")
          .one_of(walls).in({"contact", "pressure"}),
      Row("load", "direction", KeyType::vector3, "Gravity's direction (normalised; not zero)")
          .dflt("[0.0, -1.0, 0.0]").in({"gravity"}),
  };
  for (auto& r : guidewire_rows()) rows.push_back(std::move(r));
  std::vector<SceneKey> out;
  for (auto& r : rows) out.push_back(std::move(r.k));
  return out;
}

std::vector<SceneKey> models() {
  const std::vector<std::string> surfaces{"inner", "outer", "mid"};
  std::vector<Row> rows{
      Row("models", "kind", KeyType::string, "The model")
          .one_of({"fem", "surface_msm", "volume_msm", "network", "external", "displacements",
                   "corotational_fem", "xpbd_fem"})
          .required(),
      Row("models", "name", KeyType::string, "Unique within the scene; sweeps append the values")
          .note("kind_N, N the table's position"),
      Row("models", "degree", KeyType::integer, "FEM polynomial degree").dflt("2").range(1, 2)
          .sweep().in({"fem"}),
      Row("models", "surface", KeyType::string, "The wall surface the network is built on")
          .dflt("\"inner\"").one_of(surfaces).in({"surface_msm"}),
      Row("models", "topology", KeyType::string,
          "Springs of seed 000's grid or of the triangle mesh; auto: grid on structured tubes")
          .dflt("\"auto\"").one_of({"auto", "grid", "triangles"}).in({"surface_msm"}),
      Row("models", "bending", KeyType::string,
          "discrete-shells: the Discrete Shells hinge energy (Grinspun et al. 2003) instead of "
          "bend springs")
          .dflt("\"none\"").one_of({"none", "discrete-shells", "discrete_shells"})
          .in({"surface_msm"}),
      Row("models", "volume_term", KeyType::boolean,
          "The hybrid volume model (Golec et al. 2020): van-gelder springs plus a volume energy "
          "per tet")
          .dflt("false").in({"volume_msm"}),
      Row("models", "volume_moduli", KeyType::string, "volume_term's rule for (E_s, κ)")
          .dflt("\"golec\"").one_of({"golec", "homogenised"}).in({"volume_msm"}),
      Row("models", "edge_pairs", KeyType::boolean,
          "The edge-pair StVK tetrahedron (Kikuuwe et al. 2009) instead of springs")
          .dflt("false").in({"volume_msm"}),
      Row("models", "stiffness", KeyType::string, "Spring stiffness rule")
          .note("seed000 (surface), seed001 (volume); van-gelder with bending or volume_term")
          .one_of({"seed000", "seed001", "van-gelder", "van_gelder", "lloyd", "least-squares-fit",
                   "least_squares_fit", "uniform"})
          .sweep().in(kSpringKinds),
      Row("models", "mass", KeyType::string, "Node mass rule").dflt("\"consistent\"")
          .one_of({"uniform", "seed001", "consistent"}).sweep().in(kSpringKinds),
      Row("models", "solver", KeyType::string,
          "Static, linear, relaxation, an integrator, PBD or local-global")
          .dflt("\"static\"").one_of(solver_names()).sweep().in(kMsmKinds),
      Row("models", "damping", KeyType::number, "Point damping k_v (seed 000 eq. 3.3), per node")
          .dflt("0.0").unit("N·s/m").at_least(0.0).in(kMsmKinds),
      Row("models", "calibration", KeyType::string,
          "A calibration file of `vesselverify calibrate`, relative to the scene file's folder")
          .dflt("\"\"").in(kSpringKinds),
      Row("models", "calibration_transfer", KeyType::boolean,
          "Apply a group calibration to a mesh other than the one it was fitted on")
          .dflt("false").in(kSpringKinds),
      Row("models", "roi_radius", KeyType::number,
          "Contact loads: nodes farther than this from the contact point are fixed (absent: "
          "the whole vessel)")
          .unit("m").positive().sweep().in(kMsmKinds),
      Row("models", "dt", KeyType::number, "Time step of a dynamic solver (required with one)")
          .unit("s").positive().sweep().in(kMsmKinds),
      Row("models", "steps", KeyType::integer, "Steps of a dynamic solver (required with one)")
          .range(1, kMaxSteps).in(kMsmKinds),
      Row("models", "iterations", KeyType::integer,
          "Local–global iterations per step of local-global-euler (Liu et al. 2013)")
          .dflt("10").range(1, 1e6).in(kMsmKinds),
      Row("models", "file", KeyType::string,
          "The spring-network file (.json or .vtu, docs/network_format.md), relative to the "
          "scene file's folder")
          .required().in({"network"}),
      Row("models", "command", KeyType::strings,
          "The program and its arguments, run in the scene file's folder; the manifest's path "
          "is appended")
          .required().in({"external"}),
      Row("models", "timeout_s", KeyType::number, "The process group is killed after this")
          .dflt("600.0").unit("s").positive().in({"external"}),
      Row("models", "file", KeyType::string,
          "The folder of case folders with the answers, as `vesselverify export` names them")
          .required().in({"displacements"}),
      Row("models", "nodes", KeyType::string,
          "The nodes the model is given and answers at: the tet mesh's, or one wall surface's")
          .dflt("\"volume\"").one_of({"volume", "surface"}).in(kOutsideKinds),
      Row("models", "surface", KeyType::string, "nodes = \"surface\": which wall")
          .dflt("\"inner\"").one_of(surfaces).in(kOutsideKinds),
      Row("models", "dt", KeyType::number, "A dynamic problem's time step (with steps)").unit("s")
          .positive().in(kOutsideKinds),
      Row("models", "steps", KeyType::integer, "A dynamic problem's steps from rest (with dt)")
          .range(1, kMaxSteps).in(kOutsideKinds),
      Row("models", "dt", KeyType::number,
          "XPBD time step; its carried multipliers' forces act explicitly, so it must resolve "
          "the wall's shear waves")
          .dflt("1e-4").unit("s").positive().in({"xpbd_fem"}),
      Row("models", "iterations", KeyType::integer, "Gauss–Seidel sweeps over the tets per step")
          .dflt("4").range(1, 1e6).in({"xpbd_fem"}),
      Row("models", "velocity_damping", KeyType::number,
          "Fraction of the velocity removed per step")
          .dflt("0.02").range(0.0, 0.99).in({"xpbd_fem"}),
      Row("models", "settle_relative_change", KeyType::number,
          "Steady state: no node moves farther in a step than this fraction of the largest node "
          "displacement from rest (a bound on the last step, not on the distance to the steady "
          "state)")
          .dflt("1e-6").range(1e-15, 0.1).in({"xpbd_fem"}),
      Row("models", "max_steps", KeyType::integer,
          "Steps to reach the steady state before the run is recorded as failed")
          .dflt("200000").range(1, kMaxSteps).in({"xpbd_fem"}),
  };
  std::vector<SceneKey> out;
  for (auto& r : rows) out.push_back(std::move(r.k));
  return out;
}

std::vector<SceneKey> tolerances_to_transient() {
  std::vector<Row> rows{
      Row("tolerances", "max_error_mm", KeyType::number, "The error a model may make")
          .dflt("0.1").unit("mm").positive(),
      Row("budget", "quantity", KeyType::string,
          "What the budget is measured on: the contact node, a patch, the whole field, the "
          "instrument's force (contact loads) or the wire's contact force (guidewire loads with "
          "coupling = \"contact\")")
          .dflt("\"contact_point\"")
          .one_of({"contact_point", "patch", "field", "reaction", "contact_force"}),
      Row("budget", "radius", KeyType::number, "The patch's radius (quantity patch only; required there)")
          .unit("m").positive(),
      Row("budget", "tolerance_mm", KeyType::number, "The displacement error allowed")
          .note("tolerances.max_error_mm").unit("mm").positive(),
      Row("budget", "tolerance_mN", KeyType::number, "The force error allowed (quantity reaction or contact_force; required there)")
          .unit("mN").positive(),
      Row("budget", "rate_hz", KeyType::number,
          "Update rate: 30 visual, 1000 haptic (this or time_budget_s is required)")
          .unit("Hz").positive(),
      Row("budget", "time_budget_s", KeyType::number, "Compute time allowed per update")
          .note("1/rate_hz").unit("s").positive(),
      Row("budget", "magnitude", KeyType::number, "The load the budget applies at, one of the load's magnitudes")
          .note("a representative magnitude").unit("the load's").at_least(0.0),
      Row("modes", "count", KeyType::integer, "Lowest natural frequencies per model; 0: none")
          .dflt("0").range(0, 100),
      Row("modes", "reference_level", KeyType::integer, "Mesh level of the modal reference (P2)")
          .note("vessel.reference_level").range(0, kMaxLevel),
      Row("transient", "reference_level", KeyType::integer,
          "Mesh level of the FEM transient (P2, Newmark)")
          .note("vessel.reference_level").range(0, kMaxLevel),
  };
  std::vector<SceneKey> out;
  for (auto& r : rows) out.push_back(std::move(r.k));
  return out;
}

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

bool SceneKey::applies_to(const std::string& variant) const {
  return variants.empty() || std::find(variants.begin(), variants.end(), variant) != variants.end();
}

std::string SceneKey::expected() const {
  std::string what;
  const std::string u = unit.empty() ? "" : " " + unit;
  switch (type) {
    case KeyType::string:
      if (choices.empty()) return "a string";
      for (const auto& c : choices) what += (what.empty() ? "one of " : ", ") + c;
      return what;
    case KeyType::boolean: return "true or false";
    case KeyType::vector3: return "[x, y, z]" + u;
    case KeyType::vectors3: return "a non-empty array of [x, y, z]" + u;
    case KeyType::strings: return "a non-empty array of strings";
    case KeyType::table: return "a table";
    case KeyType::tables: return "an array of tables";
    case KeyType::integer:
      what = "an integer in [" + std::to_string(static_cast<long long>(min)) + ", " +
             std::to_string(static_cast<long long>(max)) + "]";
      break;
    case KeyType::number:
      if (std::isfinite(min) && std::isfinite(max)) {
        what = "a number in [" + number_text(min) + ", " + number_text(max) + "]" + u;
      } else if (std::isfinite(min)) {
        what = "a number " + std::string(min_exclusive ? "> " : ">= ") + number_text(min) + u;
      } else {
        what = "a number" + u;
      }
      break;
  }
  return sweep ? what + " or an array of them" : what;
}

const std::vector<SceneSection>& scene_sections() {
  static const std::vector<SceneSection> sections{
      {"", "The scene file's top level", "", {}, ""},
      {"vessel",
       "The vessel: generated (parametric: a straight tube or an arch), a tet mesh file (file) "
       "or a lumen surface (lumen)",
       "", {"parametric", "file", "lumen"}, "parametric"},
      {"material", "Linear elastic, homogeneous", "", {}, ""},
      {"boundary", "Each end's support", "", {}, ""},
      {"load", "The load the runs sweep over its magnitudes; its type chooses the keys", "type",
       {"contact", "pressure", "gravity", "guidewire"}, ""},
      {"models",
       "One [[models]] table per model; array values of sweep keys stand for every combination",
       "kind",
       {"fem", "surface_msm", "volume_msm", "network", "external", "displacements",
        "corotational_fem", "xpbd_fem"},
       ""},
      {"tolerances", "", "", {}, ""},
      {"budget", "What a simulator needs; `vesselverify recommend` names the cheapest model meeting it",
       "", {}, ""},
      {"modes", "Each model's lowest natural frequencies at rest beside the FEM's", "", {}, ""},
      {"transient", "The FEM transient of dynamic models", "", {}, ""},
  };
  return sections;
}

const std::vector<SceneKey>& scene_keys() {
  static const std::vector<SceneKey> keys = [] {
    std::vector<SceneKey> all;
    for (auto part : {top_and_vessel(), material_to_load(), models(), tolerances_to_transient()}) {
      all.insert(all.end(), part.begin(), part.end());
    }
    return all;
  }();
  return keys;
}

const SceneKey* find_scene_key(const std::string& section, const std::string& name,
                               const std::string& variant) {
  for (const SceneKey& k : scene_keys()) {
    if (k.section == section && k.name == name && k.applies_to(variant)) return &k;
  }
  return nullptr;
}

std::vector<std::string> scene_key_names(const std::string& section, const std::string& variant) {
  std::vector<std::string> names;
  for (const SceneKey& k : scene_keys()) {
    if (k.section == section && k.applies_to(variant)) names.push_back(k.name);
  }
  return names;
}

}  // namespace vessel
