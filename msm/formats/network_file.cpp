#include "msm/formats/network_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/tet_locator.hpp"
#include "meshes/vtu_io.hpp"

namespace vessel::msm {

namespace {

using nlohmann::json;

constexpr int kVtkLine = 3;
/// VTU field data: the format's version, and one array per followed group (value 1).
constexpr const char* kVtuVersionArray = "vesselverify_network_version";
constexpr const char* kVtuFollowPrefix = "follow_group_";

std::string number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

[[noreturn]] void fail(const std::string& source, const std::string& item, const std::string& what) {
  throw InputError(source + ": " + item + ": " + what);
}

SpringFamily parse_family(const std::string& name, const std::string& source,
                          const std::string& item) {
  std::string names;
  for (const SpringFamily f : kAllFamilies) {
    if (name == to_string(f)) return f;
    names += (names.empty() ? "" : ", ") + to_string(f);
  }
  fail(source, item, "found family \"" + name + "\", expected one of " + names);
}

// ---- JSON ----------------------------------------------------------------------------------

std::string show(const json& j) {
  std::string s = j.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

/// Refuses keys of `object` not in `known`.
void only_keys(const json& object, const std::vector<std::string>& known, const std::string& source,
               const std::string& item) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(source, item.empty() ? "key \"" + key + "\"" : item + ": key \"" + key + "\"",
           "unknown key; expected one of " + list);
    }
  }
}

const json& require(const json& object, const std::string& key, const std::string& source,
                    const std::string& item, const std::string& expected) {
  const auto it = object.find(key);
  if (it == object.end()) fail(source, item.empty() ? key : item, "missing \"" + key + "\"; expected " + expected);
  return *it;
}

double json_number(const json& j, const std::string& source, const std::string& item,
                   const std::string& expected) {
  if (!j.is_number()) fail(source, item, "found " + show(j) + ", expected " + expected);
  return j.get<double>();
}

int json_index(const json& j, const std::string& source, const std::string& item) {
  if (!j.is_number_integer() || j.get<long long>() < 0 ||
      j.get<long long>() > std::numeric_limits<int>::max()) {
    fail(source, item, "found " + show(j) + ", expected a node index (an integer ≥ 0)");
  }
  return static_cast<int>(j.get<long long>());
}

const json& json_array(const json& j, const std::string& source, const std::string& item,
                       const std::string& expected) {
  if (!j.is_array()) fail(source, item, "found " + show(j) + ", expected " + expected);
  return j;
}

Spring json_spring(const json& j, const std::string& source, const std::string& item) {
  if (!j.is_object()) {
    fail(source, item, "found " + show(j) +
                           ", expected an object {\"nodes\": [a, b], \"stiffness\": k, "
                           "\"rest_length\": l}");
  }
  only_keys(j, {"nodes", "stiffness", "rest_length", "k2", "threshold", "damping", "family"},
            source, item);
  Spring s;
  const json& ends = json_array(require(j, "nodes", source, item, "[a, b], two node indices"),
                                source, item + ".nodes", "[a, b], two node indices");
  if (ends.size() != 2) fail(source, item + ".nodes", "found " + show(ends) + ", expected [a, b], two node indices");
  s.a = json_index(ends[0], source, item + ".nodes[0]");
  s.b = json_index(ends[1], source, item + ".nodes[1]");
  s.law.k1 = json_number(require(j, "stiffness", source, item, "the stiffness k > 0 N/m"), source,
                         item + ".stiffness", "a stiffness > 0 N/m");
  s.rest_length = json_number(require(j, "rest_length", source, item, "the rest length > 0 m"),
                              source, item + ".rest_length", "a rest length > 0 m");
  const bool has_k2 = j.contains("k2"), has_threshold = j.contains("threshold");
  if (has_k2 != has_threshold) {
    fail(source, item, std::string("found \"") + (has_k2 ? "k2" : "threshold") + "\" without \"" +
                           (has_k2 ? "threshold" : "k2") +
                           "\"; expected both (a bilinear spring, seed 001 eq. 1) or neither (Hooke)");
  }
  if (has_k2) {
    s.law.k2 = json_number(j["k2"], source, item + ".k2", "a stiffness k2 > 0 N/m");
    s.law.threshold = json_number(j["threshold"], source, item + ".threshold",
                                  "an elongation threshold > 0 m");
  }
  if (j.contains("damping")) {
    s.damping = json_number(j["damping"], source, item + ".damping", "an axial damping ≥ 0 N·s/m");
  }
  s.family = SpringFamily::structural;
  if (j.contains("family")) {
    if (!j["family"].is_string()) fail(source, item + ".family", "found " + show(j["family"]) + ", expected a string");
    s.family = parse_family(j["family"].get<std::string>(), source, item + ".family");
  }
  return s;
}

std::string json_text(const NetworkFile& f) {
  std::ostringstream out;
  out << "{\n  \"format\": " << json(std::string(kNetworkFormat)).dump()
      << ",\n  \"version\": " << kNetworkFormatVersion
      << ",\n  \"description\": " << json(f.description).dump() << ",\n  \"nodes\": [";
  const auto& net = f.network;
  for (std::size_t i = 0; i < net.nodes.size(); ++i) {
    const Vec3& x = net.nodes[i];
    out << (i ? ",\n    " : "\n    ") << json::array({x.x(), x.y(), x.z()}).dump();
  }
  out << "\n  ],\n  \"masses\": [";
  for (std::size_t i = 0; i < f.masses.size(); ++i) {
    out << (i ? (i % 8 == 0 ? ",\n    " : ", ") : "\n    ") << json(f.masses[i]).dump();
  }
  out << "\n  ],\n  \"springs\": [";
  for (std::size_t k = 0; k < net.springs.size(); ++k) {
    const Spring& s = net.springs[k];
    json j = json::object();
    j["nodes"] = json::array({s.a, s.b});
    j["stiffness"] = s.law.k1;
    j["rest_length"] = s.rest_length;
    if (std::isfinite(s.law.threshold)) {
      j["k2"] = s.law.k2;
      j["threshold"] = s.law.threshold;
    }
    if (s.damping != 0.0) j["damping"] = s.damping;
    if (s.family != SpringFamily::structural) j["family"] = to_string(s.family);  // the default
    out << (k ? ",\n    " : "\n    ") << j.dump();
  }
  out << "\n  ],\n  \"fixed\": {\"nodes\": " << json(f.supports.fixed_nodes).dump()
      << "},\n  \"follow_groups\": " << json(f.supports.follow_groups).dump() << "\n}\n";
  return out.str();
}

// ---- VTU -----------------------------------------------------------------------------------

/// A one-component array of `count` values, or nullptr if absent; InputError if it has another
/// size or more components.
const VtuField* vtu_scalar(const std::vector<VtuField>& fields, const std::string& name,
                           std::size_t count, const std::string& source, const std::string& kind) {
  const VtuField* f = VtuData::find(fields, name);
  if (f && (f->components != 1 || f->values.size() != count)) {
    fail(source, kind + " data \"" + name + "\"",
         "found " + std::to_string(f->values.size()) + " values in " +
             std::to_string(f->components) + " components, expected one value per " + kind);
  }
  return f;
}

/// Every cell a line of two points: one spring.
void check_spring_cells(const VtuData& d, const std::string& source) {
  const std::size_t m = d.types.size();
  for (std::size_t c = 0; c < m; ++c) {
    const std::size_t begin = c == 0 ? 0 : d.offsets[c - 1];
    if (d.types[c] != kVtkLine || d.offsets[c] - begin != 2) {
      fail(source, "cells[" + std::to_string(c) + "]",
           "found VTK cell type " + std::to_string(d.types[c]) + " with " +
               std::to_string(d.offsets[c] - begin) +
               " points, expected a line (type 3) of 2 points: one spring");
    }
  }
}

/// Unknown arrays are refused, as unknown JSON keys are.
void check_array_names(const VtuData& d, const std::string& source) {
  const std::vector<std::string> point_names{"mass", "fixed"};
  const std::vector<std::string> cell_names{"stiffness", "rest_length", "k2", "threshold",
                                            "damping", "family"};
  auto check_names = [&](const std::vector<VtuField>& fields, const std::vector<std::string>& known,
                         const std::string& kind) {
    for (const auto& fl : fields) {
      if (std::find(known.begin(), known.end(), fl.name) == known.end()) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        fail(source, kind + " data \"" + fl.name + "\"", "unknown array; expected one of " + list);
      }
    }
  };
  check_names(d.point_fields, point_names, "point");
  check_names(d.cell_fields, cell_names, "cell");
}

/// The nodal masses and the held nodes.
void read_point_data(const VtuData& d, const std::string& source, NetworkFile& f) {
  const std::size_t n = d.points.size();
  const VtuField* mass = vtu_scalar(d.point_fields, "mass", n, source, "point");
  if (!mass) fail(source, "point data \"mass\"", "missing; expected the nodal masses, kg");
  f.masses = mass->values;
  if (const VtuField* fixed = vtu_scalar(d.point_fields, "fixed", n, source, "point")) {
    for (std::size_t i = 0; i < n; ++i) {
      const double v = fixed->values[i];
      if (v != 0.0 && v != 1.0) {
        fail(source, "nodes[" + std::to_string(i) + "]",
             "found fixed = " + number(v) + ", expected 0 (free) or 1 (held)");
      }
      if (v == 1.0) f.supports.fixed_nodes.push_back(static_cast<int>(i));
    }
  }
}

/// The springs: stiffness, rest length, bilinear law, damping and family per cell.
void read_springs(const VtuData& d, const std::string& source, NetworkFile& f) {
  const std::size_t m = d.types.size();
  const VtuField* k = vtu_scalar(d.cell_fields, "stiffness", m, source, "cell");
  const VtuField* l = vtu_scalar(d.cell_fields, "rest_length", m, source, "cell");
  if (!k) fail(source, "cell data \"stiffness\"", "missing; expected each spring's stiffness, N/m");
  if (!l) fail(source, "cell data \"rest_length\"", "missing; expected each spring's rest length, m");
  const VtuField* k2 = vtu_scalar(d.cell_fields, "k2", m, source, "cell");
  const VtuField* threshold = vtu_scalar(d.cell_fields, "threshold", m, source, "cell");
  if ((k2 == nullptr) != (threshold == nullptr)) {
    fail(source, std::string("cell data \"") + (k2 ? "k2" : "threshold") + "\"",
         std::string("found without \"") + (k2 ? "threshold" : "k2") +
             "\"; expected both (bilinear springs; threshold 0 marks a Hooke spring) or neither");
  }
  const VtuField* damping = vtu_scalar(d.cell_fields, "damping", m, source, "cell");
  const VtuField* family = vtu_scalar(d.cell_fields, "family", m, source, "cell");
  for (std::size_t c = 0; c < m; ++c) {
    Spring s;
    s.a = static_cast<int>(d.connectivity[2 * c]);
    s.b = static_cast<int>(d.connectivity[2 * c + 1]);
    s.law.k1 = k->values[c];
    s.rest_length = l->values[c];
    const std::string item = "springs[" + std::to_string(c) + "]";
    if (threshold && threshold->values[c] != 0.0) {
      s.law.threshold = threshold->values[c];
      s.law.k2 = k2->values[c];
    } else if (k2 && k2->values[c] != 0.0) {
      fail(source, item, "found k2 = " + number(k2->values[c]) +
                             " with threshold 0 (a Hooke spring), expected k2 = 0 there");
    }
    if (damping) s.damping = damping->values[c];
    if (family) {
      const double v = family->values[c];
      if (!(v >= 0) || v >= static_cast<double>(kAllFamilies.size()) || v != std::floor(v)) {
        fail(source, item, "found family code " + number(v) + ", expected 0 to " +
                               std::to_string(kAllFamilies.size() - 1) +
                               " (structural, shear, bend, two_ring, volume)");
      }
      s.family = kAllFamilies[static_cast<std::size_t>(v)];
    }
    f.network.springs.push_back(s);
  }
}

/// The format's version and the followed groups.
void read_field_data(const VtuData& d, const std::string& source, NetworkFile& f) {
  for (const auto& fd : d.field_data) {
    if (fd.name == kVtuVersionArray) {
      if (fd.values.size() != 1 || fd.values[0] != kNetworkFormatVersion) {
        fail(source, std::string("field data \"") + kVtuVersionArray + "\"",
             "found " + (fd.values.empty() ? std::string("no value") : number(fd.values[0])) +
                 ", expected " + std::to_string(kNetworkFormatVersion));
      }
    } else if (fd.name.rfind(kVtuFollowPrefix, 0) == 0) {
      if (fd.values.size() != 1 || fd.values[0] != 1.0) {
        fail(source, "field data \"" + fd.name + "\"", "expected one value, 1 (the group is followed)");
      }
      f.supports.follow_groups.push_back(fd.name.substr(std::string(kVtuFollowPrefix).size()));
    } else {
      fail(source, "field data \"" + fd.name + "\"",
           std::string("unknown array; expected ") + kVtuVersionArray + " or " + kVtuFollowPrefix +
               "<group>");
    }
  }
}

NetworkFile read_network_vtu(const std::filesystem::path& path) {
  const std::string source = path.string();
  const VtuData d = read_vtu(path);
  NetworkFile f;
  f.network.nodes = d.points;
  check_spring_cells(d, source);
  check_array_names(d, source);
  read_point_data(d, source, f);
  read_springs(d, source, f);
  read_field_data(d, source, f);
  return f;
}

void write_network_vtu(const std::filesystem::path& path, const NetworkFile& f) {
  const auto& net = f.network;
  VtuCells cells{kVtkLine, 2, {}};
  VtuField stiffness{"stiffness", 1, {}}, rest{"rest_length", 1, {}}, k2{"k2", 1, {}},
      threshold{"threshold", 1, {}}, damping{"damping", 1, {}}, family{"family", 1, {}};
  bool bilinear = false, damped = false;
  for (const Spring& s : net.springs) {
    cells.connectivity.push_back(static_cast<std::size_t>(s.a));
    cells.connectivity.push_back(static_cast<std::size_t>(s.b));
    stiffness.values.push_back(s.law.k1);
    rest.values.push_back(s.rest_length);
    const bool is_bilinear = std::isfinite(s.law.threshold);
    bilinear = bilinear || is_bilinear;
    k2.values.push_back(is_bilinear ? s.law.k2 : 0.0);
    threshold.values.push_back(is_bilinear ? s.law.threshold : 0.0);
    damped = damped || s.damping != 0.0;
    damping.values.push_back(s.damping);
    const auto code = std::find(kAllFamilies.begin(), kAllFamilies.end(), s.family) - kAllFamilies.begin();
    family.values.push_back(static_cast<double>(code));
  }
  std::vector<VtuField> cell_fields{stiffness, rest};
  if (bilinear) cell_fields.insert(cell_fields.end(), {k2, threshold});
  if (damped) cell_fields.push_back(damping);
  cell_fields.push_back(family);
  VtuField mass{"mass", 1, f.masses};
  VtuField fixed{"fixed", 1, std::vector<double>(net.nodes.size(), 0.0)};
  for (const int i : f.supports.fixed_nodes) fixed.values[static_cast<std::size_t>(i)] = 1.0;
  std::vector<VtuField> field_data{{kVtuVersionArray, 1, {double(kNetworkFormatVersion)}}};
  for (const auto& g : f.supports.follow_groups) field_data.push_back({kVtuFollowPrefix + g, 1, {1.0}});
  write_vtu(path, net.nodes, cells, {mass, fixed}, cell_fields, field_data);
}

void require_extension(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext != ".json" && ext != ".vtu") {
    throw InputError(path.string() + ": network file extension '" + ext +
                     "'; expected .json or .vtu");
  }
}

}  // namespace

void validate_network(const NetworkFile& f, const std::string& source) {
  const auto& net = f.network;
  const std::size_t n = net.nodes.size();
  if (n == 0) fail(source, "nodes", "found none, expected at least two nodes");
  for (std::size_t i = 0; i < n; ++i) {
    if (!net.nodes[i].allFinite()) {
      fail(source, "nodes[" + std::to_string(i) + "]", "found a non-finite coordinate, expected [x, y, z] in m");
    }
  }
  if (f.masses.size() != n) {
    fail(source, "masses", "found " + std::to_string(f.masses.size()) + " masses for " +
                               std::to_string(n) + " nodes, expected one per node");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(f.masses[i] > 0) || !std::isfinite(f.masses[i])) {
      fail(source, "masses[" + std::to_string(i) + "]",
           "found " + number(f.masses[i]) + ", expected a mass > 0 kg");
    }
  }
  if (net.springs.empty()) fail(source, "springs", "found none, expected at least one spring");
  std::map<std::pair<int, int>, std::size_t> pairs;
  std::vector<char> used(n, 0);
  for (std::size_t k = 0; k < net.springs.size(); ++k) {
    const Spring& s = net.springs[k];
    const std::string item = "springs[" + std::to_string(k) + "]";
    for (const int v : {s.a, s.b}) {
      if (v < 0 || static_cast<std::size_t>(v) >= n) {
        fail(source, item, "found node index " + std::to_string(v) + ", expected 0 to " +
                               std::to_string(n - 1) + " (the file has " + std::to_string(n) +
                               " nodes)");
      }
    }
    if (s.a == s.b) {
      fail(source, item, "joins node " + std::to_string(s.a) + " to itself, expected two different nodes");
    }
    if (!(s.law.k1 > 0) || !std::isfinite(s.law.k1)) {
      fail(source, item, "found stiffness " + number(s.law.k1) + ", expected a stiffness > 0 N/m");
    }
    if (!(s.rest_length > 0) || !std::isfinite(s.rest_length)) {
      fail(source, item, "found rest_length " + number(s.rest_length) + ", expected a length > 0 m");
    }
    if (s.law.threshold != std::numeric_limits<double>::infinity()) {  // bilinear
      if (!(s.law.threshold > 0) || !std::isfinite(s.law.threshold)) {
        fail(source, item, "found threshold " + number(s.law.threshold) +
                               ", expected an elongation threshold > 0 m");
      }
      if (!(s.law.k2 > 0) || !std::isfinite(s.law.k2)) {
        fail(source, item, "found k2 " + number(s.law.k2) + ", expected a stiffness k2 > 0 N/m");
      }
    }
    if (!(s.damping >= 0) || !std::isfinite(s.damping)) {
      fail(source, item, "found damping " + number(s.damping) + ", expected an axial damping ≥ 0 N·s/m");
    }
    const auto key = std::minmax(s.a, s.b);
    const auto [it, inserted] = pairs.emplace(std::make_pair(key.first, key.second), k);
    if (!inserted) {
      fail(source, item, "joins nodes " + std::to_string(key.first) + " and " +
                             std::to_string(key.second) + " like springs[" +
                             std::to_string(it->second) + "], expected each pair of nodes once");
    }
    used[static_cast<std::size_t>(s.a)] = used[static_cast<std::size_t>(s.b)] = 1;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!used[i]) {
      fail(source, "nodes[" + std::to_string(i) + "]",
           "is in no spring, expected every node to be joined by a spring (a loose node has no "
           "stiffness)");
    }
  }
  std::set<int> fixed;
  for (std::size_t k = 0; k < f.supports.fixed_nodes.size(); ++k) {
    const int v = f.supports.fixed_nodes[k];
    const std::string item = "fixed.nodes[" + std::to_string(k) + "]";
    if (v < 0 || static_cast<std::size_t>(v) >= n) {
      fail(source, item, "found node index " + std::to_string(v) + ", expected 0 to " +
                             std::to_string(n - 1));
    }
    if (!fixed.insert(v).second) fail(source, item, "found node " + std::to_string(v) + " twice, expected each once");
  }
  std::set<std::string> groups;
  for (std::size_t k = 0; k < f.supports.follow_groups.size(); ++k) {
    const std::string& g = f.supports.follow_groups[k];
    const std::string item = "follow_groups[" + std::to_string(k) + "]";
    if (g.empty()) fail(source, item, "found an empty name, expected a surface group (e.g. \"inlet\")");
    if (!groups.insert(g).second) fail(source, item, "found \"" + g + "\" twice, expected each group once");
  }
}

NetworkFile parse_network_json(std::string_view text, const std::string& source) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(source + ": not valid JSON (byte " + std::to_string(e.byte) + "): " + e.what());
  }
  if (!root.is_object()) {
    throw InputError(source + ": found " + show(root) + ", expected a JSON object with format, " +
                     "version, nodes, masses and springs");
  }
  only_keys(root, {"$schema", "format", "version", "description", "nodes", "masses", "springs", "fixed",
                   "follow_groups"},
            source, "");
  const json& format = require(root, "format", source, "", "\"vesselverify.network\"");
  if (format != std::string(kNetworkFormat)) {
    fail(source, "format", "found " + show(format) + ", expected \"vesselverify.network\"");
  }
  const json& version = require(root, "version", source, "", "1");
  if (!version.is_number_integer() || version.get<long long>() != kNetworkFormatVersion) {
    fail(source, "version", "found " + show(version) + ", expected " + std::to_string(kNetworkFormatVersion));
  }
  NetworkFile f;
  if (root.contains("description")) {
    if (!root["description"].is_string()) fail(source, "description", "found " + show(root["description"]) + ", expected a string");
    f.description = root["description"].get<std::string>();
  }
  const json& nodes = json_array(require(root, "nodes", source, "", "an array of [x, y, z] in m"),
                                 source, "nodes", "an array of [x, y, z] in m");
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string item = "nodes[" + std::to_string(i) + "]";
    const json& x = nodes[i];
    if (!x.is_array() || x.size() != 3) fail(source, item, "found " + show(x) + ", expected [x, y, z] in m");
    Vec3 p;
    for (int c = 0; c < 3; ++c) p[c] = json_number(x[static_cast<std::size_t>(c)], source, item, "[x, y, z] in m");
    f.network.nodes.push_back(p);
  }
  const json& masses = json_array(require(root, "masses", source, "", "one mass per node, kg"),
                                  source, "masses", "an array of masses, kg");
  for (std::size_t i = 0; i < masses.size(); ++i) {
    f.masses.push_back(json_number(masses[i], source, "masses[" + std::to_string(i) + "]", "a mass > 0 kg"));
  }
  const json& springs = json_array(require(root, "springs", source, "", "an array of springs"),
                                   source, "springs", "an array of springs");
  for (std::size_t k = 0; k < springs.size(); ++k) {
    f.network.springs.push_back(json_spring(springs[k], source, "springs[" + std::to_string(k) + "]"));
  }
  if (root.contains("fixed")) {
    const json& fixed = root["fixed"];
    if (!fixed.is_object()) fail(source, "fixed", "found " + show(fixed) + ", expected {\"nodes\": [i, ...]}");
    only_keys(fixed, {"nodes"}, source, "fixed");
    if (fixed.contains("nodes")) {
      const json& list = json_array(fixed["nodes"], source, "fixed.nodes", "an array of node indices");
      for (std::size_t k = 0; k < list.size(); ++k) {
        f.supports.fixed_nodes.push_back(json_index(list[k], source, "fixed.nodes[" + std::to_string(k) + "]"));
      }
    }
  }
  if (root.contains("follow_groups")) {
    const json& list = json_array(root["follow_groups"], source, "follow_groups",
                                  "an array of surface group names");
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (!list[k].is_string()) {
        fail(source, "follow_groups[" + std::to_string(k) + "]", "found " + show(list[k]) + ", expected a group name");
      }
      f.supports.follow_groups.push_back(list[k].get<std::string>());
    }
  }
  validate_network(f, source);
  std::sort(f.supports.fixed_nodes.begin(), f.supports.fixed_nodes.end());
  return f;
}

NetworkFile read_network_file(const std::filesystem::path& path) {
  require_extension(path);
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": network file not found");
  if (lower_extension(path) == ".vtu") {
    NetworkFile f = read_network_vtu(path);
    validate_network(f, path.string());
    return f;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open the network file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_network_json(text.str(), path.string());
}

void write_network_file(const std::filesystem::path& path, const NetworkFile& file) {
  require_extension(path);
  validate_network(file, path.string());
  if (lower_extension(path) == ".vtu") {
    write_network_vtu(path, file);
    return;
  }
  const std::string text = json_text(file);
  write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

NetworkFile network_file_of(const BuiltNetwork& built, NetworkSupports supports,
                            std::string description) {
  if (built.terms.volume_kappa) {
    throw InputError("export network: the hybrid volume model's volume term (κ per tet) is not a "
                     "spring; the network format holds springs only (export without "
                     "--volume-term)");
  }
  if (built.terms.bending_rigidity) {
    throw InputError("export network: the discrete-shells bending term is not a spring; the "
                     "network format holds springs only (export with --bending none)");
  }
  NetworkFile f;
  f.description = std::move(description);
  f.network.nodes = built.network.nodes;
  f.network.springs = built.network.springs;
  f.network.source_node.assign(f.network.nodes.size(), -1);
  f.masses = built.masses;
  std::sort(supports.fixed_nodes.begin(), supports.fixed_nodes.end());
  f.supports = std::move(supports);
  return f;
}

BuiltNetwork network_on_mesh(const NetworkFile& file, const TetMesh& mesh,
                             const std::string& source) {
  for (std::size_t k = 0; k < file.supports.follow_groups.size(); ++k) {
    const std::string& g = file.supports.follow_groups[k];
    if (!mesh.find_group(g, 2)) {
      std::string names;
      for (const auto& group : mesh.groups) {
        if (group.dim == 2) names += (names.empty() ? "" : ", ") + group.name;
      }
      fail(source, "follow_groups[" + std::to_string(k) + "]",
           "found \"" + g + "\", expected a surface group of the vessel mesh (" + names + ")");
    }
  }
  BuiltNetwork built;
  built.network = file.network;
  built.masses = file.masses;
  built.file_supports = file.supports;
  built.file = source;
  std::ostringstream topo;
  topo << "spring network from " << std::filesystem::path(source).filename().string() << " ("
       << file.network.nodes.size() << " nodes, " << file.network.springs.size() << " springs)";
  built.topology = topo.str();
  // source_node: the mesh node at the same position, found among the mesh nodes sorted by x.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double tol = mesh.nodes.empty() ? 0.0 : kNodeMatchTolerance * (hi - lo).norm();
  std::vector<int> by_x(mesh.nodes.size());
  for (std::size_t i = 0; i < by_x.size(); ++i) by_x[i] = static_cast<int>(i);
  std::sort(by_x.begin(), by_x.end(), [&](int a, int b) { return mesh.nodes[a].x() < mesh.nodes[b].x(); });
  auto& source_node = built.network.source_node;
  source_node.assign(built.network.nodes.size(), -1);
  for (std::size_t i = 0; i < built.network.nodes.size(); ++i) {
    const Vec3& x = built.network.nodes[i];
    auto it = std::lower_bound(by_x.begin(), by_x.end(), x.x() - tol,
                               [&](int m, double v) { return mesh.nodes[m].x() < v; });
    double best = tol;
    for (; it != by_x.end() && mesh.nodes[*it].x() <= x.x() + tol; ++it) {
      const double d = (mesh.nodes[*it] - x).norm();
      if (d <= best) {
        best = d;
        source_node[i] = *it;
      }
    }
  }
  return built;
}

void require_nodes_inside(const std::vector<Vec3>& nodes, const TetMesh& mesh, double tolerance,
                          const std::string& source) {
  const TetLocator locator(mesh);
  std::vector<std::size_t> outside;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (locator.find(nodes[i], tolerance) < 0) outside.push_back(i);
  }
  if (outside.empty()) return;
  double farthest = 0.0;
  for (const std::size_t i : outside) {
    double d = std::numeric_limits<double>::infinity();
    for (const Triangle& t : mesh.triangles) {
      const Vec3 c = closest_point_on_triangle(mesh.nodes[static_cast<std::size_t>(t[0])],
                                               mesh.nodes[static_cast<std::size_t>(t[1])],
                                               mesh.nodes[static_cast<std::size_t>(t[2])], nodes[i]);
      d = std::min(d, (c - nodes[i]).norm());
    }
    if (std::isfinite(d)) farthest = std::max(farthest, d);
  }
  std::ostringstream m;
  m << source << ": " << outside.size() << " of " << nodes.size()
    << " nodes lie outside the vessel mesh (nodes ";
  for (std::size_t k = 0; k < std::min<std::size_t>(outside.size(), 5); ++k) {
    m << (k ? ", " : "") << outside[k];
  }
  m << (outside.size() > 5 ? ", ..." : "") << "), up to " << farthest * 1e3
    << " mm from its boundary; expected every node inside the vessel wall (the reference is "
       "evaluated at each node's rest position; are the coordinates in metres?)";
  throw InputError(m.str());
}

}  // namespace vessel::msm
