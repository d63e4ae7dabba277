#include "verification/calibration_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

constexpr const char* kSchema = "vesselverify.calibration";
constexpr int kVersion = 1;

void fnv(std::uint64_t& h, std::int64_t v) {
  for (int i = 0; i < 8; ++i) {
    h ^= static_cast<std::uint64_t>(v >> (8 * i)) & 0xffu;
    h *= 1099511628211ull;
  }
}

std::string kind_name(LoadKind k) { return to_string(k); }

LoadKind parse_load_kind(const std::string& s, const std::string& where) {
  if (s == "contact") return LoadKind::contact;
  if (s == "pressure") return LoadKind::pressure;
  if (s == "gravity") return LoadKind::gravity;
  throw InputError(where + ": found \"" + s + "\", expected contact, pressure or gravity");
}

/// A required member of the right type, InputError naming file and key otherwise.
template <class T>
T member(const nlohmann::json& j, const std::string& key, const std::string& file) {
  const auto it = j.find(key);
  if (it == j.end()) throw InputError(file + ": key \"" + key + "\" missing");
  try {
    return it->get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(file + ": key \"" + key + "\" has the wrong type (found " +
                     std::string(it->type_name()) + ")");
  }
}

}  // namespace

std::string mesh_hash(const TetMesh& mesh) {
  std::uint64_t h = 1469598103934665603ull;
  fnv(h, static_cast<std::int64_t>(mesh.nodes.size()));
  for (const Vec3& p : mesh.nodes) {
    for (int c = 0; c < 3; ++c) fnv(h, std::llround(p[c] * 1e9));
  }
  fnv(h, static_cast<std::int64_t>(mesh.tets.size()));
  for (const Tet& t : mesh.tets) {
    for (const int v : t) fnv(h, v);
  }
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

void write_calibration(const std::filesystem::path& path, const Calibration& c) {
  nlohmann::ordered_json j;
  j["schema"] = kSchema;
  j["version"] = kVersion;
  j["granularity"] = c.granularity;
  j["model"] = {{"scene", c.scene},
                {"name", c.model},
                {"kind", c.model_kind},
                {"stiffness", c.stiffness},
                {"volume_term", c.volume_term},
                {"volume_moduli", c.volume_moduli},
                {"poisson_ratio", c.poisson_ratio},
                {"youngs_modulus_Pa", c.youngs_modulus}};
  j["mesh"] = {{"hash", c.mesh_hash}, {"vessel", c.vessel}, {"level", c.level},
               {"nodes", c.nodes},    {"springs", c.springs}, {"tets", c.tets}};
  if (c.granularity != "per_spring") {
    nlohmann::ordered_json f = nlohmann::ordered_json::object();
    for (std::size_t i = 0; i < c.names.size(); ++i) f[c.names[i]] = c.factors[i];
    j["factors"] = f;
  } else {
    // Per spring, in the network's spring order; kappa apart.
    std::vector<double> springs;
    double kappa = 1.0;
    bool has_kappa = false;
    nlohmann::ordered_json halves = nlohmann::ordered_json::object();  // κ per half of the wall
    for (std::size_t i = 0; i < c.names.size(); ++i) {
      if (c.names[i] == "kappa") {
        kappa = c.factors[i];
        has_kappa = true;
      } else if (c.names[i].rfind("kappa/", 0) == 0) {
        halves[c.names[i]] = c.factors[i];
      } else {
        springs.push_back(c.factors[i]);
      }
    }
    j["spring_factors"] = springs;
    if (has_kappa) j["kappa_factor"] = kappa;
    if (!halves.empty()) j["kappa_factors"] = halves;
  }
  nlohmann::ordered_json loads = nlohmann::ordered_json::array();
  for (const auto& l : c.training_loads) {
    nlohmann::ordered_json e = {{"name", l.name}, {"type", kind_name(l.kind)},
                                {"magnitude", l.magnitude}};
    if (l.kind == LoadKind::contact) e["point_m"] = {l.point.x(), l.point.y(), l.point.z()};
    loads.push_back(e);
  }
  j["training_loads"] = loads;
  nlohmann::ordered_json cases = nlohmann::ordered_json::array();
  for (const auto& fc : c.fit_cases) {
    cases.push_back({{"case", fc.name},
                     {"relative_l2_before", fc.relative_l2_before},
                     {"relative_l2_after", fc.relative_l2_after}});
  }
  j["fit"] = {{"method", c.method},
              {"smoothness", c.smoothness},
              {"ridge", c.ridge},
              {"objective_before", c.objective_before},
              {"objective_after", c.objective_after},
              {"iterations", c.iterations},
              {"stop_reason", c.stop_reason},
              {"training_cases_linearised", cases}};
  write_file_atomically(path, [&](std::ostream& out) { out << j.dump(1) << "\n"; });
}

namespace {

/// The model the calibration applies to and the mesh it belongs to.
void read_model_and_mesh(const nlohmann::json& j, const std::string& file, Calibration& c) {
  const auto model = member<nlohmann::json>(j, "model", file);
  const std::string mfile = file + ": model";
  c.scene = member<std::string>(model, "scene", mfile);
  c.model = member<std::string>(model, "name", mfile);
  c.model_kind = member<std::string>(model, "kind", mfile);
  c.stiffness = member<std::string>(model, "stiffness", mfile);
  c.volume_term = member<bool>(model, "volume_term", mfile);
  // Files written before the homogenised rule have no volume_moduli: golec.
  c.volume_moduli = model.contains("volume_moduli")
                        ? member<std::string>(model, "volume_moduli", mfile)
                        : std::string("golec");
  c.poisson_ratio = member<double>(model, "poisson_ratio", mfile);
  c.youngs_modulus = member<double>(model, "youngs_modulus_Pa", mfile);
  const auto mesh = member<nlohmann::json>(j, "mesh", file);
  const std::string meshfile = file + ": mesh";
  c.mesh_hash = member<std::string>(mesh, "hash", meshfile);
  c.vessel = member<std::string>(mesh, "vessel", meshfile);
  c.level = member<int>(mesh, "level", meshfile);
  c.nodes = member<std::size_t>(mesh, "nodes", meshfile);
  c.springs = member<std::size_t>(mesh, "springs", meshfile);
  c.tets = member<std::size_t>(mesh, "tets", meshfile);
}

/// The factors: by class name, or per spring (with κ, or κ per half of the wall); each > 0.
void read_factors(const nlohmann::json& j, const std::string& file, Calibration& c) {
  if (c.granularity != "per_spring") {
    const auto f = member<nlohmann::json>(j, "factors", file);
    if (!f.is_object() || f.empty()) {
      throw InputError(file + ": key \"factors\": expected an object of name: factor");
    }
    for (const auto& [name, v] : f.items()) {
      if (!v.is_number()) throw InputError(file + ": factors." + name + ": expected a number");
      c.names.push_back(name);
      c.factors.push_back(v.get<double>());
    }
  } else {
    const auto f = member<std::vector<double>>(j, "spring_factors", file);
    for (std::size_t i = 0; i < f.size(); ++i) {
      c.names.push_back("spring/" + std::to_string(i));
      c.factors.push_back(f[i]);
    }
    if (j.contains("kappa_factor")) {
      c.names.emplace_back("kappa");
      c.factors.push_back(member<double>(j, "kappa_factor", file));
    }
    if (j.contains("kappa_factors")) {  // κ per half of the wall
      const auto k = member<nlohmann::json>(j, "kappa_factors", file);
      for (const char* name : {"kappa/inner", "kappa/outer"}) {
        if (!k.is_object() || !k.contains(name) || !k[name].is_number()) {
          throw InputError(file + ": key \"kappa_factors\": expected numbers \"kappa/inner\" and "
                           "\"kappa/outer\"");
        }
        c.names.emplace_back(name);
        c.factors.push_back(k[name].get<double>());
      }
    }
  }
  for (std::size_t i = 0; i < c.factors.size(); ++i) {
    if (!(c.factors[i] > 0.0) || !std::isfinite(c.factors[i])) {
      throw InputError(file + ": factor of \"" + c.names[i] + "\" is " +
                       std::to_string(c.factors[i]) + "; expected a finite factor > 0");
    }
  }
}

/// What the file records of the fit: its training loads and how it went (optional keys).
void read_training_loads_and_fit(const nlohmann::json& j, const std::string& file,
                                 Calibration& c) {
  if (j.contains("training_loads")) {
    for (const auto& l : j["training_loads"]) {
      CalibrationLoad load;
      load.name = member<std::string>(l, "name", file + ": training_loads");
      load.kind = parse_load_kind(member<std::string>(l, "type", file + ": training_loads"),
                                  file + ": training_loads.type");
      load.magnitude = member<double>(l, "magnitude", file + ": training_loads");
      if (l.contains("point_m")) {
        const auto p = member<std::vector<double>>(l, "point_m", file + ": training_loads");
        if (p.size() == 3) load.point = Vec3(p[0], p[1], p[2]);
      }
      c.training_loads.push_back(load);
    }
  }
  if (j.contains("fit") && j["fit"].is_object()) {
    const auto& fit = j["fit"];
    c.method = fit.value("method", "");
    c.smoothness = fit.value("smoothness", 0.0);
    c.ridge = fit.value("ridge", 0.0);
    c.objective_before = fit.value("objective_before", 0.0);
    c.objective_after = fit.value("objective_after", 0.0);
    c.iterations = fit.value("iterations", 0);
    c.stop_reason = fit.value("stop_reason", "");
  }
}

}  // namespace

Calibration read_calibration(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(file + ": cannot open the calibration file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw InputError(file + ": expected a JSON object");
  if (member<std::string>(j, "schema", file) != kSchema) {
    throw InputError(file + ": key \"schema\": expected \"" + kSchema + "\"");
  }
  if (member<int>(j, "version", file) != kVersion) {
    throw InputError(file + ": key \"version\": expected " + std::to_string(kVersion));
  }
  Calibration c;
  c.granularity = member<std::string>(j, "granularity", file);
  if (c.granularity != "groups" && c.granularity != "wall_layers" &&
      c.granularity != "edge_types" && c.granularity != "per_section_spring" &&
      c.granularity != "per_spring") {
    throw InputError(file + ": key \"granularity\": found \"" + c.granularity +
                     "\", expected \"groups\", \"wall_layers\", \"edge_types\", "
                     "\"per_section_spring\" or \"per_spring\"");
  }
  read_model_and_mesh(j, file, c);
  read_factors(j, file, c);
  read_training_loads_and_fit(j, file, c);
  return c;
}

void set_calibration_parameters(Calibration& c, const msm::StiffnessParameters& params,
                                const Eigen::VectorXd& theta) {
  c.names = params.names;
  c.factors.clear();
  for (int p = 0; p < params.size(); ++p) c.factors.push_back(std::exp(theta[p]));
}

std::pair<msm::StiffnessParameters, Eigen::VectorXd> calibration_parameters(
    const Calibration& c, const std::string& source, const msm::BuiltNetwork& built,
    const VesselParams& vessel) {
  const bool has_kappa = std::any_of(c.names.begin(), c.names.end(), [](const std::string& n) {
    return n == "kappa" || n.rfind("kappa/", 0) == 0;
  });
  if (has_kappa && !built.terms.volume_kappa) {
    throw InputError(source + ": the calibration scales kappa, but the model has no volume term");
  }
  msm::StiffnessParameters params;
  if (c.granularity == "per_spring") {
    const bool halves = std::find(c.names.begin(), c.names.end(), "kappa/inner") != c.names.end();
    params = msm::per_spring_parameters(built.network, has_kappa, halves ? &vessel : nullptr);
    if (c.factors.size() != static_cast<std::size_t>(params.size())) {
      throw InputError(source + ": spring_factors has " +
                       std::to_string(c.factors.size() - (has_kappa ? (halves ? 2 : 1) : 0)) +
                       " factors, the model's network has " +
                       std::to_string(built.network.springs.size()) + " springs");
    }
  } else if (c.granularity == "wall_layers" || c.granularity == "edge_types") {
    params = msm::wall_layer_parameters(built.network, vessel, has_kappa,
                                        c.granularity == "edge_types");
  } else if (c.granularity == "per_section_spring") {
    const bool halves = std::find(c.names.begin(), c.names.end(), "kappa/inner") != c.names.end();
    params = msm::per_section_spring_parameters(built.network, vessel, has_kappa, halves);
  } else {
    params = msm::group_parameters(built.network, vessel, has_kappa);
  }
  std::map<std::string, double> by_name;
  for (std::size_t i = 0; i < c.names.size(); ++i) by_name[c.names[i]] = c.factors[i];
  if (c.granularity == "wall_layers" || c.granularity == "edge_types") {
    // A layer class the fitted mesh did not have (a level-0 mesh has two element layers through
    // the wall, so e.g. no radial edge has its mean in the middle third; a level-1 mesh does):
    // the geometric mean of the same direction's factors in the layers the file has (log factors
    // interpolated through the wall).
    for (const std::string& name : params.names) {
      if (by_name.count(name) || name.rfind("volume/", 0) != 0) continue;
      const std::string type = name.substr(0, name.rfind('/') + 1);
      double log_sum = 0.0;
      int found = 0;
      for (const char* layer : {"inner", "middle", "outer"}) {
        const auto it = by_name.find(type + layer);
        if (it != by_name.end()) {
          log_sum += std::log(it->second);
          ++found;
        }
      }
      if (found > 0) by_name[name] = std::exp(log_sum / found);
    }
  }
  Eigen::VectorXd theta(params.size());
  for (int p = 0; p < params.size(); ++p) {
    const auto it = by_name.find(params.names[static_cast<std::size_t>(p)]);
    if (it == by_name.end()) {
      throw InputError(source + ": factors: no factor for the spring class \"" +
                       params.names[static_cast<std::size_t>(p)] +
                       "\" of this model's network; expected one per class");
    }
    theta[p] = std::log(it->second);
  }
  return {params, theta};
}

void apply_calibration(const Calibration& c, const std::string& source, msm::BuiltNetwork& built,
                       const TetMesh& mesh, const VesselParams& vessel, const ModelSpec& spec,
                       double youngs_modulus, double nu, bool transfer) {
  const std::string kind = to_string(spec.kind);
  if (c.model_kind != kind) {
    throw InputError(source + ": model.kind: fitted for a " + c.model_kind + " model, applied to a " +
                     kind + " model");
  }
  if (c.stiffness != msm::to_string(spec.stiffness) || c.volume_term != spec.volume_term) {
    throw InputError(source + ": model: fitted for stiffness \"" + c.stiffness + "\"" +
                     (c.volume_term ? " with" : " without") + " the volume term, applied to \"" +
                     msm::to_string(spec.stiffness) + "\"" +
                     (spec.volume_term ? " with" : " without") + " it");
  }
  if (c.volume_term && c.volume_moduli != msm::to_string(spec.volume_moduli)) {
    throw InputError(source + ": model.volume_moduli: fitted on the volume term's \"" +
                     c.volume_moduli + "\" rule, applied to a model with \"" +
                     msm::to_string(spec.volume_moduli) + "\"");
  }
  if (std::abs(c.poisson_ratio - nu) > 1e-12 ||
      std::abs(c.youngs_modulus - youngs_modulus) > 1e-9 * youngs_modulus) {
    throw InputError(source + ": model: fitted at E = " + std::to_string(c.youngs_modulus) +
                     " Pa, nu = " + std::to_string(c.poisson_ratio) + "; applied at E = " +
                     std::to_string(youngs_modulus) + " Pa, nu = " + std::to_string(nu) +
                     " (a calibration holds at the material it was fitted at)");
  }
  const std::string hash = mesh_hash(mesh);
  if (hash != c.mesh_hash) {
    if (!transfer) {
      throw InputError(source + ": mesh.hash: the calibration belongs to mesh " + c.mesh_hash +
                       " (" + c.vessel + "), this model's mesh is " + hash + " (" +
                       describe(vessel) +
                       "); expected the same mesh, or calibration_transfer = true for a group "
                       "calibration");
    }
    if (c.granularity == "per_spring" || c.granularity == "per_section_spring") {
      throw InputError(source + ": mesh.hash: a " + c.granularity + " calibration (mesh " +
                       c.mesh_hash + ") cannot transfer to another mesh (" + hash +
                       "): its factors are indexed by that mesh's springs");
    }
  }
  auto [params, theta] = calibration_parameters(c, source, built, vessel);
  msm::apply_stiffness_factors(built.network, built.terms.volume_kappa, params, theta);
}

}  // namespace vessel
