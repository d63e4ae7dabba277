#include "verification/harness/external_model.hpp"


#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "meshes/foundation/csv.hpp"
#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "verification/scene_problems.hpp"
#include "verification/harness/timing.hpp"

namespace vessel {

namespace {

const char* load_unit(LoadKind k) {
  return k == LoadKind::contact ? "N" : (k == LoadKind::pressure ? "Pa" : "g");
}

/// The network options of the nodes an outside model gets: the volume model's (every tet-mesh
/// node, its tets) or the surface model's triangle network on the chosen wall; consistent masses.
msm::NetworkOptions exchange_options(const Scene& s, const ModelSpec& m, double nu) {
  msm::NetworkOptions o;
  o.model = m.external.nodes == ExchangeNodes::volume ? msm::ModelType::volume
                                                      : msm::ModelType::surface;
  o.surface = m.external.surface;
  o.topology = msm::Topology::triangles;
  o.stiffness = msm::StiffnessRule::van_gelder;  // unused by the exchange: nodes, cells, masses
  o.stiffness_params.youngs_modulus = s.youngs_modulus;
  o.stiffness_params.poisson_ratio = nu;
  o.mass = msm::MassRule::consistent;
  o.density = s.density;
  return o;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}


double parse_number(const std::string& text, const std::string& where, const std::string& what) {
  char* stop = nullptr;
  const double v = std::strtod(text.c_str(), &stop);
  if (text.empty() || *stop != '\0') {
    throw ExternalModelError(where + ": " + what + ": found \"" + text + "\", expected a number");
  }
  if (!std::isfinite(v)) {
    throw ExternalModelError(where + ": " + what + " is not finite (" + text + ")");
  }
  return v;
}

/// Rows of a CSV file with the given header (every row that many numbers).
std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& path,
                                               const std::vector<std::string>& header) {
  std::ifstream in(path);
  if (!in) throw ExternalModelError(path.string() + ": cannot be read");
  std::string line;
  std::string expected;
  for (const auto& h : header) expected += (expected.empty() ? "" : ",") + h;
  if (!std::getline(in, line)) {
    throw ExternalModelError(path.string() + ": empty; expected the header \"" + expected + "\"");
  }
  if (csv_fields(line) != header) {
    throw ExternalModelError(path.string() + ":1: found header \"" + line + "\", expected \"" +
                             expected + "\"");
  }
  std::vector<std::vector<std::string>> rows;
  std::size_t number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> f = csv_fields(line);
    if (f.size() != header.size()) {
      throw ExternalModelError(path.string() + ":" + std::to_string(number) + ": found " +
                               std::to_string(f.size()) + " fields, expected " +
                               std::to_string(header.size()) + " (" + expected + ")");
    }
    f.push_back(std::to_string(number));  // the line number, for messages
    rows.push_back(std::move(f));
  }
  return rows;
}

std::vector<Vec3> read_displacements_csv(const std::filesystem::path& path, std::size_t nodes) {
  const auto rows = read_csv(path, {"node", "ux", "uy", "uz"});
  if (rows.size() != nodes) {
    throw ExternalModelError(path.string() + ": " + std::to_string(rows.size()) +
                             " nodes, expected " + std::to_string(nodes) +
                             " (one line per node of problem.vtu)");
  }
  std::vector<Vec3> u(nodes, Vec3::Zero());
  std::vector<char> seen(nodes, 0);
  for (const auto& r : rows) {
    const std::string where = path.string() + ":" + r[4];
    char* stop = nullptr;
    const long long node = std::strtoll(r[0].c_str(), &stop, 10);
    if (r[0].empty() || *stop != '\0' || node < 0 || node >= static_cast<long long>(nodes)) {
      throw ExternalModelError(where + ": node \"" + r[0] + "\": expected an index in [0, " +
                               std::to_string(nodes - 1) + "]");
    }
    const auto i = static_cast<std::size_t>(node);
    if (seen[i]) throw ExternalModelError(where + ": node " + r[0] + " given twice");
    seen[i] = 1;
    for (int c = 0; c < 3; ++c) {
      u[i][c] = parse_number(r[1 + c], where, std::string("node ") + r[0] + " u" + "xyz"[c]);
    }
  }
  return u;
}

std::vector<Vec3> read_displacements_vtu(const std::filesystem::path& path, std::size_t nodes) {
  VtuData d;
  try {
    d = read_vtu(path);
  } catch (const InputError& e) {
    throw ExternalModelError(e.what());
  }
  if (d.points.size() != nodes) {
    throw ExternalModelError(path.string() + ": " + std::to_string(d.points.size()) +
                             " points, expected " + std::to_string(nodes) +
                             " (the points of problem.vtu, in its order)");
  }
  const VtuField* f = VtuData::find(d.point_fields, "displacement");
  if (!f || f->components != 3) {
    throw ExternalModelError(path.string() +
                             ": no point data 'displacement' with 3 components; expected it (m)");
  }
  std::vector<Vec3> u(nodes);
  for (std::size_t i = 0; i < nodes; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double v = f->values[3 * i + static_cast<std::size_t>(c)];
      if (!std::isfinite(v)) {
        std::ostringstream s;
        s << path.string() << ": point " << i << " displacement u" << "xyz"[c]
          << " is not finite (" << v << ")";
        throw ExternalModelError(s.str());
      }
      u[i][c] = v;
    }
  }
  return u;
}

void write_manifest(const std::filesystem::path& path, const ExchangeProblem& p) {
  nlohmann::json analysis{{"type", "static"},
                          {"description",
                           "static equilibrium under the loads, from the nodes at rest"}};
  if (p.steps > 0) {
    analysis = {{"type", "dynamic"},
                {"dt_s", p.dt},
                {"steps", p.steps},
                {"duration_s", p.dt * static_cast<double>(p.steps)},
                {"description",
                 "from rest (zero velocity), the loads applied as a step at t = 0 and held; "
                 "answer the displacement after `steps` steps of `dt_s`"}};
  }
  const char* cell_kind = p.cells.vtk_type == 10 ? "tetra" : "triangle";
  const nlohmann::json j{
      {"schema", kExchangeSchema},
      {"schema_version", kExchangeSchemaVersion},
      {"units", {{"length", "m"}, {"force", "N"}, {"mass", "kg"}, {"time", "s"},
                 {"stress", "Pa"}, {"density", "kg/m^3"}}},
      {"case",
       {{"id", p.id},
        {"scene", p.scene},
        {"model", p.model},
        {"poisson_ratio", p.poisson_ratio},
        {"level", p.level},
        {"load", {{"kind", to_string(p.load)}, {"magnitude", p.magnitude},
                  {"unit", load_unit(p.load)}}}}},
      {"material",
       {{"youngs_modulus_pa", p.youngs_modulus},
        {"poisson_ratio", p.poisson_ratio},
        {"density_kg_m3", p.density},
        {"model", "isotropic linear elasticity (the FEM reference's)"}}},
      {"vessel",
       {{"description", describe(p.vessel)},
        {"inner_radius_m", p.vessel.inner_radius},
        {"wall_thickness_m", p.vessel.wall_thickness}}},
      {"problem",
       {{"file", exchange_files::problem},
        {"node_set", to_string(p.node_set)},
        {"surface", p.node_set == ExchangeNodes::surface ? nlohmann::json(msm::to_string(p.surface))
                                                          : nlohmann::json(nullptr)},
        {"nodes", p.nodes.size()},
        {"cells", p.cells.connectivity.size() / static_cast<std::size_t>(p.cells.points_per_cell)},
        {"cell_type", cell_kind},
        {"point_data",
         {{"load_N", "consistent nodal load, N (3 components): the surface loads the FEM "
                     "integrates, lumped to the nodes, plus gravity on mass_kg"},
          {"fixed", "1 where that displacement component is held at zero, else 0 (3 components)"},
          {"mass_kg", "lumped consistent mass, kg"}}},
        {"qoi_node", p.qoi_node},
        {"total_load_N", [&] {
           Vec3 f = Vec3::Zero();
           for (const auto& l : p.loads) f += l;
           return std::vector<double>{f.x(), f.y(), f.z()};
         }()}}},
      {"analysis", analysis},
      {"output",
       {{"displacements", {exchange_files::displacements_csv, exchange_files::displacements_vtu}},
        {"displacements_csv_header", "node,ux,uy,uz"},
        {"displacements_vtu_point_data", "displacement"},
        {"displacement_unit", "m"},
        {"description",
         "write one of the displacement files into this folder: every node of problem.vtu once, "
         "its displacement from rest in m (CSV: node index from 0; VTU: the points of "
         "problem.vtu in order, point data 'displacement' with 3 components)"},
        {"timing", exchange_files::timing},
        {"timing_description",
         "optional: {\"setup_seconds\": s, \"solve_seconds\": s}, the simulator's own time for "
         "its set-up and, after it, for the solve (static: one update; dynamic: all steps); "
         "without it the suite records the process's wall time"},
        {"history", exchange_files::history},
        {"history_description",
         "dynamic problems, optional: time_s,ux,uy,uz of qoi_node over the run (m)"}}}};
  write_file_atomically(path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

}  // namespace

ExchangeNetwork exchange_network(const Scene& s, const ModelSpec& m, const TetMesh& mesh,
                                 int level, double nu) {
  VesselParams vessel = s.vessel;
  vessel.level = level;
  ExchangeNetwork n;
  n.built = msm::build_network(mesh, vessel, exchange_options(s, m, nu));
  n.form = msm::make_model(n.built);
  const msm::SpringNetwork& net = n.built.network;
  if (m.external.nodes == ExchangeNodes::volume) {
    n.cells = tet_cells(net.tets);
    n.description = "volume nodes (tet mesh)";
  } else {
    n.cells = {5, 3, {}};
    for (const auto& t : net.triangles) {
      for (const int v : t) n.cells.connectivity.push_back(static_cast<std::size_t>(v));
    }
    n.description = msm::to_string(m.external.surface) + " wall surface nodes (triangles)";
  }
  return n;
}

std::string file_stem(const std::string& name) {
  std::string stem = name;
  for (char& c : stem) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
  }
  return stem;
}

std::size_t export_exchange(const Scene& s, const std::filesystem::path& cache_dir,
                            const std::filesystem::path& output_dir, std::ostream* log) {
  std::vector<const ModelSpec*> outside;
  for (const auto& m : s.models) {
    if (m.kind == ModelKind::external || m.kind == ModelKind::displacements) outside.push_back(&m);
  }
  if (outside.empty()) {
    throw InputError(s.source.string() +
                     ": no [[models]] table of kind \"external\" or \"displacements\"; "
                     "expected at least one (export writes their exchange folders)");
  }
  const Vec3 qoi = qoi_point(s);
  std::size_t cases = 0;
  for (const int level : s.model_levels) {
    const TetMesh mesh = scene_mesh(s, level, cache_dir);
    for (const double nu : s.poisson_ratios) {
      for (const ModelSpec* m : outside) {
        const ExchangeNetwork network = exchange_network(s, *m, mesh, level, nu);
        for (const double mag : s.load.magnitudes) {
          const ExchangeProblem p = exchange_problem(network, s, *m, mesh, level, nu, mag, qoi);
          const auto dir = write_exchange_case(output_dir / file_stem(m->name), p);
          if (log) *log << "  " << dir.string() << " (" << p.nodes.size() << " nodes)\n";
          ++cases;
        }
      }
    }
  }
  return cases;
}

std::string case_id(double nu, int level, double magnitude) {
  std::ostringstream s;
  s << "nu" << nu << "_L" << level << "_load" << magnitude;
  return s.str();
}

ExchangeProblem exchange_problem(const ExchangeNetwork& n, const Scene& s, const ModelSpec& m,
                                 const TetMesh& mesh, int level, double nu, double magnitude,
                                 const Vec3& qoi) {
  ExchangeProblem p;
  p.id = case_id(nu, level, magnitude);
  p.scene = s.name;
  p.model = m.name;
  p.poisson_ratio = nu;
  p.level = level;
  p.load = s.load.kind;
  p.magnitude = magnitude;
  p.youngs_modulus = s.youngs_modulus;
  p.density = s.density;
  p.vessel = s.vessel;
  p.vessel.level = level;
  p.node_set = m.external.nodes;
  p.surface = m.external.surface;
  p.nodes = n.built.network.nodes;
  p.cells = n.cells;
  p.dt = m.external.dt;
  p.steps = m.external.steps;
  p.problem = msm_problem(s, *n.form, n.built, mesh, magnitude);
  const std::size_t count = p.nodes.size();
  p.loads.resize(count);
  p.fixed.resize(count);
  p.masses.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    const auto k = static_cast<Eigen::Index>(3 * i);
    p.loads[i] = p.problem.external_force.segment<3>(k);
    for (int c = 0; c < 3; ++c) p.fixed[i][c] = p.problem.fixed[3 * i + c];
    p.masses[i] = p.problem.mass[k];
  }
  p.qoi_node = nearest_node(p.nodes, qoi);
  return p;
}

std::filesystem::path write_exchange_case(const std::filesystem::path& root,
                                          const ExchangeProblem& p) {
  const std::filesystem::path dir = root / p.id;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    throw InputError(dir.string() + ": exchange folder cannot be created (" + ec.message() + ")");
  }
  for (const char* stale : {exchange_files::displacements_csv, exchange_files::displacements_vtu,
                            exchange_files::timing, exchange_files::history, exchange_files::log}) {
    std::filesystem::remove(dir / stale, ec);
  }
  VtuField load{"load_N", 3, {}}, fixed{"fixed", 3, {}}, mass{"mass_kg", 1, {}};
  for (std::size_t i = 0; i < p.nodes.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      load.values.push_back(p.loads[i][c]);
      fixed.values.push_back(p.fixed[i][c] ? 1.0 : 0.0);
    }
    mass.values.push_back(p.masses[i]);
  }
  write_vtu(dir / exchange_files::problem, p.nodes, p.cells, {load, fixed, mass});
  write_manifest(dir / exchange_files::manifest, p);
  return dir;
}

ExternalAnswer read_external_answer(const std::filesystem::path& dir, std::size_t nodes) {
  ExternalAnswer a;
  const auto csv = dir / exchange_files::displacements_csv;
  const auto vtu = dir / exchange_files::displacements_vtu;
  if (std::filesystem::exists(csv)) {
    a.u = read_displacements_csv(csv, nodes);
  } else if (std::filesystem::exists(vtu)) {
    a.u = read_displacements_vtu(vtu, nodes);
  } else {
    throw ExternalModelError(dir.string() + ": no answer; expected " +
                             exchange_files::displacements_csv + " or " +
                             exchange_files::displacements_vtu + " there");
  }
  const auto timing = dir / exchange_files::timing;
  if (std::filesystem::exists(timing)) {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(read_text(timing));
    } catch (const nlohmann::json::exception& e) {
      throw ExternalModelError(timing.string() + ": not JSON (" + e.what() + ")");
    }
    if (!j.is_object()) throw ExternalModelError(timing.string() + ": expected a JSON object");
    const auto seconds = [&](const char* key) -> std::optional<double> {
      if (!j.contains(key)) return std::nullopt;
      if (!j[key].is_number() || !std::isfinite(j[key].get<double>()) || j[key].get<double>() < 0) {
        throw ExternalModelError(timing.string() + ": " + key + ": found " + j[key].dump() +
                                 ", expected a time >= 0 s");
      }
      return j[key].get<double>();
    };
    a.setup_seconds = seconds("setup_seconds");
    a.solve_seconds = seconds("solve_seconds");
  }
  const auto history = dir / exchange_files::history;
  if (std::filesystem::exists(history)) {
    for (const auto& r : read_csv(history, {"time_s", "ux", "uy", "uz"})) {
      const std::string where = history.string() + ":" + r[4];
      a.history_time_s.push_back(parse_number(r[0], where, "time_s"));
      Vec3 u;
      for (int c = 0; c < 3; ++c) u[c] = parse_number(r[1 + c], where, std::string("u") + "xyz"[c]);
      a.history_u.push_back(u);
    }
  }
  return a;
}

ExternalAnswer run_external_case(const ExternalSpec& spec, const std::filesystem::path& case_dir,
                                 std::size_t nodes, ProcessResult* process) {
  const std::filesystem::path dir = std::filesystem::absolute(case_dir);
  const std::filesystem::path manifest = dir / exchange_files::manifest;
  const std::filesystem::path log = dir / exchange_files::log;
  std::vector<std::string> argv = spec.command;
  argv.push_back(manifest.string());
  const ProcessResult r =
      run_process(argv, spec.working_dir, {{"VESSELVERIFY_MANIFEST", manifest.string()},
                                           {"VESSELVERIFY_CASE_DIR", dir.string()}},
                  spec.timeout_s, log);
  if (process) *process = r;
  const auto with_log = [&](const std::string& what) {
    const std::string last = log_tail(log, 3);
    return what + (last.empty() ? "" : "; its output ended: " + last) + " (log: " + log.string() +
           ")";
  };
  std::ostringstream limit;
  limit << spec.timeout_s;
  if (r.timed_out) {
    throw ExternalModelError(with_log("timed out after " + limit.str() +
                                      " s (timeout_s); its process group was killed"));
  }
  if (r.signal != 0) {
    throw ExternalModelError(with_log("killed by signal " + std::to_string(r.signal) + " (" +
                                      strsignal(r.signal) + ")"));
  }
  if (r.exit_code != 0) {
    throw ExternalModelError(with_log("exited with code " + std::to_string(r.exit_code)));
  }
  return read_external_answer(dir, nodes);
}

}  // namespace vessel
