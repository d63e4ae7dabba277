#include "verification/guidewire/wire_exchange.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "meshes/foundation/csv.hpp"
#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/process.hpp"
#include "msm/rods/rod_layout.hpp"

namespace vessel {

namespace {

constexpr const char* kManifest = "manifest.json";
constexpr const char* kCentreline = "centreline.csv";
constexpr const char* kContact = "contact.json";
constexpr const char* kLog = "simulator.log";

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

/// A finite number from CSV text, or WireModelError naming where.
double number(const std::string& text, const std::string& where) {
  char* stop = nullptr;
  const double v = std::strtod(text.c_str(), &stop);
  if (text.empty() || *stop != '\0' || !std::isfinite(v)) {
    throw WireModelError(where + ": found \"" + text + "\", expected a finite number");
  }
  return v;
}


std::vector<Vec3> read_centreline(const std::filesystem::path& path, int nodes) {
  std::ifstream in(path);
  if (!in) throw WireModelError(path.string() + ": no answer (expected node,x,y,z per node)");
  std::string line;
  if (!std::getline(in, line) || csv_fields(line) != std::vector<std::string>{"node", "x", "y", "z"}) {
    throw WireModelError(path.string() + ":1: expected the header \"node,x,y,z\"");
  }
  std::vector<Vec3> p(static_cast<std::size_t>(nodes), Vec3::Constant(NAN));
  std::vector<char> seen(static_cast<std::size_t>(nodes), 0);
  for (int number_of_line = 2; std::getline(in, line); ++number_of_line) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = path.string() + ":" + std::to_string(number_of_line);
    const std::vector<std::string> f = csv_fields(line);
    if (f.size() != 4) throw WireModelError(where + ": expected 4 fields (node,x,y,z)");
    const double k = number(f[0], where);
    if (k != std::floor(k) || k < 0 || k >= nodes) {
      throw WireModelError(where + ": node " + f[0] + " out of range 0.." +
                           std::to_string(nodes - 1));
    }
    const auto i = static_cast<std::size_t>(k);
    if (seen[i]) throw WireModelError(where + ": node " + f[0] + " repeated");
    seen[i] = 1;
    for (int c = 0; c < 3; ++c) p[i][c] = number(f[1 + c], where);
  }
  for (int i = 0; i < nodes; ++i) {
    if (!seen[static_cast<std::size_t>(i)]) {
      throw WireModelError(path.string() + ": node " + std::to_string(i) + " missing (expected " +
                           std::to_string(nodes) + " nodes)");
    }
  }
  return p;
}

}  // namespace

void write_wire_case(const std::filesystem::path& dir, const std::string& scene,
                     const GuidewireSpec& w, double length, const WireLumen& lumen) {
  std::filesystem::create_directories(dir);
  for (const char* answer : {kCentreline, kContact}) std::filesystem::remove(dir / answer);
  const msm::rods::SectionStiffness section =
      msm::rods::solid_section({w.young, w.shear, w.density}, w.diameter);
  nlohmann::json rest = nlohmann::json::array();
  const Vec3 d = w.clamp_direction.normalized();
  for (int i = 0; i <= w.segments; ++i) rest.push_back(vec(w.clamp_point + (length * i / w.segments) * d));
  nlohmann::json l{{"kind", lumen.torus ? "torus" : "straight"},
                   {"centreline_offset_m", lumen.offset},
                   {"description",
                    "rigid, frictionless, one-sided: every node's distance from the lumen's "
                    "centreline (the axis, or the circle of radius bend_radius_m) must stay ≤ "
                    "centreline_offset_m (the lumen's radius less the wire's)"}};
  if (lumen.torus) {
    l["centre_m"] = vec(Vec3::Zero());
    l["normal"] = vec(Vec3::UnitZ());
    l["bend_radius_m"] = lumen.bend_radius;
  } else {
    l["axis_origin_m"] = vec(Vec3::Zero());
    l["axis_direction"] = vec(Vec3::UnitZ());
  }
  const nlohmann::json m{
      {"schema", "vesselverify.exchange"},
      {"schema_version", 1},
      {"units", {{"length", "m"}, {"force", "N"}, {"mass", "kg"}, {"time", "s"}, {"stress", "Pa"},
                 {"density", "kg/m^3"}}},
      {"case", {{"id", "wire"}, {"scene", scene}, {"model", to_string(WireModel::external)}, {"kind", "wire"}}},
      {"wire",
       {{"segments", w.segments},
        {"length_m", length},
        {"rest_centreline_m", rest},
        {"diameter_m", w.diameter},
        {"section", "solid circular"},
        {"material", {{"youngs_modulus_pa", w.young}, {"shear_modulus_pa", w.shear},
                      {"density_kg_m3", w.density}}},
        {"bending_stiffness_Nm2", section.EI},
        {"clamp", {{"point_m", vec(w.clamp_point)}, {"direction", vec(d)}}},
        {"lumen", l}}},
      {"analysis", {{"type", "static"},
                    {"description", "the wire's equilibrium with its rest centreline clamped "
                                    "at its first node (position and tangent), inside the "
                                    "lumen, no other load"}}},
      {"output", {{"centreline", kCentreline}, {"centreline_csv_header", "node,x,y,z"},
                  {"contact", kContact}, {"contact_fields", "force_N (the wall's normal force "
                                                            "on the wire, N, >= 0), node"}}}};
  write_file_atomically(dir / kManifest, [&](std::ostream& out) { out << m.dump(1) << "\n"; });
}

WireAnswer read_wire_answer(const std::filesystem::path& dir, int nodes) {
  WireAnswer a;
  a.centreline = read_centreline(dir / kCentreline, nodes);
  const std::filesystem::path contact = dir / kContact;
  std::ifstream in(contact);
  if (!in) throw WireModelError(contact.string() + ": no answer (expected {\"force_N\", \"node\"})");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    a.force = j.at("force_N").get<double>();
    a.node = j.at("node").get<int>();
  } catch (const nlohmann::json::exception& e) {
    throw WireModelError(contact.string() + ": expected {\"force_N\": number, \"node\": integer} (" +
                         e.what() + ")");
  }
  if (!std::isfinite(a.force) || a.force < 0.0) {
    throw WireModelError(contact.string() + ": force_N must be finite and ≥ 0 (the wall pushes)");
  }
  if (a.node < 0 || a.node >= nodes) {
    throw WireModelError(contact.string() + ": node " + std::to_string(a.node) +
                         " out of range 0.." + std::to_string(nodes - 1));
  }
  return a;
}

WireAnswer run_wire_case(const GuidewireSpec& w, const std::filesystem::path& case_dir, int nodes) {
  const std::filesystem::path dir = std::filesystem::absolute(case_dir);
  const std::filesystem::path manifest = dir / kManifest;
  const std::filesystem::path log = dir / kLog;
  std::vector<std::string> argv = w.command;
  argv.push_back(manifest.string());
  const ProcessResult r = run_process(argv, w.working_dir,
                                      {{"VESSELVERIFY_MANIFEST", manifest.string()},
                                       {"VESSELVERIFY_CASE_DIR", dir.string()}},
                                      w.timeout_s, log);
  const auto fail = [&](const std::string& what) {
    const std::string last = log_tail(log, 3);
    return WireModelError("the wire model " + what +
                          (last.empty() ? "" : "; its output ended: " + last) + " (log: " +
                          log.string() + ")");
  };
  if (r.timed_out) throw fail("timed out (timeout_s)");
  if (r.signal != 0) throw fail("was killed by signal " + std::to_string(r.signal));
  if (r.exit_code != 0) throw fail("exited with code " + std::to_string(r.exit_code));
  return read_wire_answer(dir, nodes);
}

}  // namespace vessel
