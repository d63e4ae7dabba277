#include "meshes/msh_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace {

// gmsh element types (gmsh reference manual, "MSH file format").
constexpr int kGmshPoint = 15;
constexpr int kGmshLine = 1;
constexpr int kGmshTriangle = 2;
constexpr int kGmshTet = 4;

int nodes_per_element(int type) {
  switch (type) {
    case kGmshPoint: return 1;
    case kGmshLine: return 2;
    case kGmshTriangle: return 3;
    case kGmshTet: return 4;
    default: return -1;
  }
}

/// Line-oriented reader that knows the file name and line number of everything it reports.
class MshReader {
 public:
  MshReader(std::istream& in, std::string source) : path_(std::move(source)), in_(in) {}

  /// Reads the next line into line(); false at end of file.
  bool next() {
    if (!std::getline(in_, line_)) return false;
    ++line_no_;
    if (!line_.empty() && line_.back() == '\r') line_.pop_back();
    return true;
  }

  /// Reads the next line, failing with "truncated" if the file ends inside `section`.
  const std::string& next_in(const std::string& section) {
    if (!next()) {
      throw InputError(path_ + ":" + std::to_string(line_no_) +
                       ": file is truncated: it ends inside " + section + " (expected $End" +
                       (section.empty() ? section : section.substr(1)) + ")");
    }
    return line_;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_ + ":" + std::to_string(line_no_) + ": " + what);
  }

  /// Whitespace-separated tokens of the current line; they view it, so use them before next().
  std::vector<std::string_view> tokens() const {
    std::vector<std::string_view> out;
    std::string_view s(line_);
    std::size_t i = 0;
    while (i < s.size()) {
      while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
      if (i > start) out.push_back(s.substr(start, i - start));
    }
    return out;
  }

  /// Tokens of the current line, at least `n` of them.
  std::vector<std::string_view> tokens_at_least(std::size_t n, const char* what) const {
    auto t = tokens();
    if (t.size() < n) {
      const bool at_end = in_.peek() == std::char_traits<char>::eof();
      fail(std::string("expected ") + what + " (" + std::to_string(n) + " values), found '" +
           line_ + "'" + (at_end ? "; the file ends here: it is truncated" : ""));
    }
    return t;
  }

  template <class T>
  T number(std::string_view tok, const char* what) const {
    T value{};
    const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
    if (ec != std::errc() || ptr != tok.data() + tok.size()) {
      fail(std::string("expected ") + what + ", found '" + std::string(tok) + "'");
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) {
        fail(std::string("non-finite ") + what + " '" + std::string(tok) +
             "'; expected a finite number");
      }
    }
    return value;
  }

  const std::string& line() const { return line_; }
  const std::string& path() const { return path_; }
  long line_number() const { return line_no_; }

 private:
  std::string path_;
  std::istream& in_;
  std::string line_;
  long line_no_ = 0;
};

struct GroupKey {
  int dim;
  int tag;
  auto operator<=>(const GroupKey&) const = default;
};

/// Accumulates nodes, elements and group membership while a file is parsed.
class MeshBuilder {
 public:
  explicit MeshBuilder(MshReader& reader) : r_(reader) {}

  void add_node(std::size_t tag, const Vec3& x) {
    if (!index_.emplace(tag, static_cast<int>(mesh_.nodes.size())).second) {
      r_.fail("node tag " + std::to_string(tag) + " is defined twice");
    }
    mesh_.nodes.push_back(x);
  }

  void set_group_name(int dim, int tag, std::string name) { names_[{dim, tag}] = std::move(name); }

  /// Adds one element of `type` with gmsh node tags, belonging to the given physical groups.
  void add_element(int type, std::size_t element_tag, const std::vector<std::size_t>& node_tags,
                   const std::vector<int>& physical_tags) {
    if (type == kGmshPoint || type == kGmshLine) return;
    if (type != kGmshTriangle && type != kGmshTet) {
      r_.fail("element type " + std::to_string(type) +
              " is not supported: vesselverify needs linear tetrahedra (type 4) and triangles "
              "(type 2); re-mesh with first-order simplices");
    }
    std::vector<int> nodes;
    for (std::size_t t : node_tags) {
      const auto it = index_.find(t);
      if (it == index_.end()) {
        r_.fail("element refers to node tag " + std::to_string(t) + ", which is not in $Nodes");
      }
      nodes.push_back(it->second);
    }
    const int dim = type == kGmshTet ? 3 : 2;
    const std::size_t tets_before = mesh_.tets.size();
    const int element = dim == 3 ? add_unique(nodes, tet_index_, mesh_.tets)
                                 : add_unique(nodes, tri_index_, mesh_.triangles);
    if (mesh_.tets.size() > tets_before) {  // a new tet: remember where it came from
      ElementOrigin o{r_.line_number(), element_tag, {}};
      std::copy(node_tags.begin(), node_tags.end(), o.node_tags.begin());
      origins_.push_back(o);
    }
    for (int tag : physical_tags) members_[{dim, tag}].push_back(element);
  }

  TetMesh finish() {
    if (mesh_.tets.empty()) {
      throw InputError(r_.path() +
                       ": the mesh has no tetrahedra; expected a 3D tetrahedral vessel wall mesh");
    }
    for (auto& [key, elements] : members_) {
      std::sort(elements.begin(), elements.end());
      elements.erase(std::unique(elements.begin(), elements.end()), elements.end());
      const auto name = names_.find(key);
      mesh_.groups.push_back({name == names_.end() ? std::string() : name->second, key.dim,
                              key.tag, std::move(elements)});
    }
    remove_unused_nodes(mesh_);
    const bool flipped = orient_tets(mesh_);
    if (flipped) {
      for (auto& o : origins_) std::swap(o.node_tags[2], o.node_tags[3]);
    }
    // Inverted or zero-volume tets make every model meaningless (the FEM's Jacobian is singular or
    // of the wrong sign, springs get infinite stiffness): refuse them here, where each tet's line
    // is known, so every user of a .msh file is protected.
    require_positive_volumes(mesh_, r_.path(), origins_, flipped);
    orient_boundary_outward(mesh_);
    return std::move(mesh_);
  }

 private:
  template <std::size_t N>
  static int add_unique(const std::vector<int>& nodes, std::map<std::array<int, N>, int>& index,
                        std::vector<std::array<int, N>>& elements) {
    std::array<int, N> e{};
    std::copy(nodes.begin(), nodes.end(), e.begin());
    std::array<int, N> key = e;
    std::sort(key.begin(), key.end());
    const auto [it, inserted] = index.emplace(key, static_cast<int>(elements.size()));
    if (inserted) elements.push_back(e);
    return it->second;
  }

  MshReader& r_;
  TetMesh mesh_;
  std::unordered_map<std::size_t, int> index_;
  std::map<std::array<int, 4>, int> tet_index_;
  std::map<std::array<int, 3>, int> tri_index_;
  std::map<GroupKey, std::vector<int>> members_;
  std::map<GroupKey, std::string> names_;
  std::vector<ElementOrigin> origins_;  ///< one per tet, parallel to mesh_.tets
};

void read_physical_names(MshReader& r, MeshBuilder& b) {
  const std::string section = "$PhysicalNames";
  r.next_in(section);
  const auto count = r.number<long>(r.tokens_at_least(1, "number of physical names")[0],
                                    "number of physical names");
  for (long i = 0; i < count; ++i) {
    r.next_in(section);
    const auto t = r.tokens_at_least(3, "'dim tag \"name\"'");
    const auto dim = r.number<int>(t[0], "physical dimension");
    const auto tag = r.number<int>(t[1], "physical tag");
    const auto open = r.line().find('"');
    const auto close = r.line().rfind('"');
    if (open == std::string::npos || close == open) r.fail("expected a quoted physical name");
    b.set_group_name(dim, tag, r.line().substr(open + 1, close - open - 1));
  }
  if (r.next_in(section) != "$EndPhysicalNames") r.fail("expected $EndPhysicalNames");
}

void read_nodes_v22(MshReader& r, MeshBuilder& b) {
  const std::string section = "$Nodes";
  r.next_in(section);
  const auto count = r.number<long>(r.tokens_at_least(1, "number of nodes")[0], "number of nodes");
  for (long i = 0; i < count; ++i) {
    r.next_in(section);
    const auto t = r.tokens_at_least(4, "'tag x y z'");
    b.add_node(r.number<std::size_t>(t[0], "node tag"),
               Vec3(r.number<double>(t[1], "x coordinate"), r.number<double>(t[2], "y coordinate"),
                    r.number<double>(t[3], "z coordinate")));
  }
  if (r.next_in(section) != "$EndNodes") r.fail("expected $EndNodes after " + std::to_string(count) + " nodes");
}

void read_elements_v22(MshReader& r, MeshBuilder& b) {
  const std::string section = "$Elements";
  r.next_in(section);
  const auto count =
      r.number<long>(r.tokens_at_least(1, "number of elements")[0], "number of elements");
  std::vector<std::size_t> nodes;
  for (long i = 0; i < count; ++i) {
    r.next_in(section);
    const auto t = r.tokens_at_least(3, "'tag type ntags ...'");
    const int type = r.number<int>(t[1], "element type");
    const int ntags = r.number<int>(t[2], "number of element tags");
    if (ntags < 0) r.fail("negative number of element tags " + std::to_string(ntags));
    const int nn = nodes_per_element(type);
    if (nn < 0) b.add_element(type, 0, {}, {});  // refuses the unsupported type, naming it
    const std::size_t expected = 3 + static_cast<std::size_t>(ntags) + static_cast<std::size_t>(nn);
    if (t.size() < expected) {
      r.fail("element line has " + std::to_string(t.size()) + " values, expected " +
             std::to_string(expected));
    }
    std::vector<int> physical;
    if (ntags > 0) {
      const int tag = r.number<int>(t[3], "physical tag");
      if (tag != 0) physical.push_back(tag);  // 0: the element is in no physical group
    }
    nodes.clear();
    for (int k = 0; k < nn; ++k) {
      nodes.push_back(r.number<std::size_t>(t[3 + static_cast<std::size_t>(ntags + k)], "node tag"));
    }
    b.add_element(type, r.number<std::size_t>(t[0], "element tag"), nodes, physical);
  }
  if (r.next_in(section) != "$EndElements") r.fail("expected $EndElements after " + std::to_string(count) + " elements");
}

using EntityPhysicals = std::map<GroupKey, std::vector<int>>;

EntityPhysicals read_entities_v41(MshReader& r) {
  const std::string section = "$Entities";
  r.next_in(section);
  const auto head = r.tokens_at_least(4, "'numPoints numCurves numSurfaces numVolumes'");
  std::array<long, 4> counts{};  // parsed now: the tokens view a line the loop overwrites
  for (int dim = 0; dim < 4; ++dim) counts[dim] = r.number<long>(head[dim], "entity count");
  EntityPhysicals physicals;
  for (int dim = 0; dim < 4; ++dim) {
    const long count = counts[dim];
    for (long i = 0; i < count; ++i) {
      r.next_in(section);
      const auto t = r.tokens_at_least(dim == 0 ? 5 : 8, "an entity record");
      const int tag = r.number<int>(t[0], "entity tag");
      const std::size_t nphys_at = dim == 0 ? 4 : 7;
      const auto nphys = r.number<long>(t[nphys_at], "number of physical tags");
      if (t.size() < nphys_at + 1 + static_cast<std::size_t>(nphys)) {
        r.fail("entity record lists fewer physical tags than its count " + std::to_string(nphys));
      }
      auto& tags = physicals[{dim, tag}];
      for (long k = 0; k < nphys; ++k) {
        tags.push_back(std::abs(r.number<int>(t[nphys_at + 1 + k], "physical tag")));
      }
    }
  }
  if (r.next_in(section) != "$EndEntities") r.fail("expected $EndEntities");
  return physicals;
}

void read_nodes_v41(MshReader& r, MeshBuilder& b) {
  const std::string section = "$Nodes";
  r.next_in(section);
  const auto head = r.tokens_at_least(4, "'numEntityBlocks numNodes minNodeTag maxNodeTag'");
  const auto blocks = r.number<long>(head[0], "number of node blocks");
  std::vector<std::size_t> tags;
  for (long blk = 0; blk < blocks; ++blk) {
    r.next_in(section);
    const auto t = r.tokens_at_least(4, "'entityDim entityTag parametric numNodesInBlock'");
    const bool parametric = r.number<int>(t[2], "parametric flag") != 0;
    const auto n = r.number<long>(t[3], "number of nodes in block");
    tags.clear();
    for (long i = 0; i < n; ++i) {
      r.next_in(section);
      tags.push_back(r.number<std::size_t>(r.tokens_at_least(1, "a node tag")[0], "node tag"));
    }
    for (long i = 0; i < n; ++i) {
      r.next_in(section);
      const auto c = r.tokens_at_least(parametric ? 4 : 3, "'x y z'");
      b.add_node(tags[i], Vec3(r.number<double>(c[0], "x coordinate"),
                               r.number<double>(c[1], "y coordinate"),
                               r.number<double>(c[2], "z coordinate")));
    }
  }
  if (r.next_in(section) != "$EndNodes") r.fail("expected $EndNodes");
}

void read_elements_v41(MshReader& r, MeshBuilder& b, const EntityPhysicals& physicals) {
  const std::string section = "$Elements";
  r.next_in(section);
  const auto head =
      r.tokens_at_least(4, "'numEntityBlocks numElements minElementTag maxElementTag'");
  const auto blocks = r.number<long>(head[0], "number of element blocks");
  std::vector<std::size_t> nodes;
  const std::vector<int> none;
  for (long blk = 0; blk < blocks; ++blk) {
    r.next_in(section);
    const auto t = r.tokens_at_least(4, "'entityDim entityTag elementType numElementsInBlock'");
    const int dim = r.number<int>(t[0], "entity dimension");
    const int entity = r.number<int>(t[1], "entity tag");
    const int type = r.number<int>(t[2], "element type");
    const auto n = r.number<long>(t[3], "number of elements in block");
    const auto phys = physicals.find({dim, entity});
    const std::vector<int>& groups = phys == physicals.end() ? none : phys->second;
    const int nn = nodes_per_element(type);
    for (long i = 0; i < n; ++i) {
      r.next_in(section);
      const auto e = r.tokens_at_least(1 + static_cast<std::size_t>(std::max(nn, 0)),
                                       "'elementTag nodeTags...'");
      nodes.clear();
      for (int k = 0; k < std::max(nn, 0); ++k) {
        nodes.push_back(r.number<std::size_t>(e[1 + k], "node tag"));
      }
      b.add_element(type, r.number<std::size_t>(e[0], "element tag"), nodes, groups);
    }
  }
  if (r.next_in(section) != "$EndElements") r.fail("expected $EndElements");
}

}  // namespace

TetMesh read_msh(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": mesh file not found");
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open mesh file for reading");
  return parse_msh(in, path.string());
}

TetMesh parse_msh(std::istream& in, const std::string& source) {
  MshReader r(in, source);
  MeshBuilder builder(r);
  if (!r.next()) throw InputError(source + ": mesh file is empty");
  if (r.line() != "$MeshFormat") {
    r.fail("not a gmsh .msh file: expected '$MeshFormat', found '" + r.line().substr(0, 40) + "'");
  }
  r.next_in("$MeshFormat");
  const auto fmt = r.tokens_at_least(3, "'version file-type data-size'");
  const std::string version(fmt[0]);
  if (version != "2.2" && version != "4.1") {
    r.fail("unsupported .msh version " + version + "; expected 2.2 or 4.1");
  }
  if (fmt[1] != "0") {
    r.fail("binary .msh files are not supported; expected ASCII (save with "
           "'gmsh -save -format msh41' and Mesh.Binary = 0)");
  }
  if (r.next_in("$MeshFormat") != "$EndMeshFormat") r.fail("expected $EndMeshFormat");

  const bool v41 = version == "4.1";
  EntityPhysicals physicals;
  bool have_nodes = false;
  bool have_elements = false;
  while (r.next()) {
    const std::string section = r.line();  // a copy: next_in() overwrites the line
    if (section.empty()) continue;
    if (section == "$PhysicalNames") {
      read_physical_names(r, builder);
    } else if (section == "$Entities" && v41) {
      physicals = read_entities_v41(r);
    } else if (section == "$Nodes") {
      v41 ? read_nodes_v41(r, builder) : read_nodes_v22(r, builder);
      have_nodes = true;
    } else if (section == "$Elements") {
      if (!have_nodes) r.fail("$Elements before $Nodes");
      v41 ? read_elements_v41(r, builder, physicals) : read_elements_v22(r, builder);
      have_elements = true;
    } else if (section[0] == '$') {
      const std::string end = "$End" + section.substr(1);  // skip sections we do not use
      while (r.next_in(section) != end) {
      }
    } else {
      r.fail("expected a section header starting with '$', found '" + section.substr(0, 40) + "'");
    }
  }
  if (!have_nodes || !have_elements) {
    throw InputError(source + ": file is truncated or incomplete: " +
                     (!have_nodes ? "no $Nodes section" : "no $Elements section"));
  }
  return builder.finish();
}

namespace {

void put(std::ostream& out, double x) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);  // shortest exact round trip
  out.write(buf, res.ptr - buf);
}

void write_physical_names(std::ostream& out, const TetMesh& mesh) {
  out << "$PhysicalNames\n" << mesh.groups.size() << "\n";
  for (const auto& g : mesh.groups) out << g.dim << " " << g.tag << " \"" << g.name << "\"\n";
  out << "$EndPhysicalNames\n";
}

void write_v22(std::ostream& out, const TetMesh& mesh) {
  out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  write_physical_names(out, mesh);
  out << "$Nodes\n" << mesh.nodes.size() << "\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    out << i + 1;
    for (int k = 0; k < 3; ++k) {
      out << ' ';
      put(out, mesh.nodes[i][k]);
    }
    out << '\n';
  }
  out << "$EndNodes\n";
  std::size_t count = 0;
  for (const auto& g : mesh.groups) count += g.elements.size();
  out << "$Elements\n" << count << "\n";
  std::size_t id = 1;
  for (const auto& g : mesh.groups) {
    for (int e : g.elements) {
      out << id++ << ' ' << (g.dim == 3 ? kGmshTet : kGmshTriangle) << " 2 " << g.tag << ' '
          << g.tag;
      if (g.dim == 3) {
        for (int n : mesh.tets[e]) out << ' ' << n + 1;
      } else {
        for (int n : mesh.triangles[e]) out << ' ' << n + 1;
      }
      out << '\n';
    }
  }
  out << "$EndElements\n";
}

void write_v41(std::ostream& out, const TetMesh& mesh) {
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  write_physical_names(out, mesh);
  // One entity per physical group, tagged like the group; bounding boxes are the mesh's.
  Vec3 lo = Vec3::Constant(0.0);
  Vec3 hi = Vec3::Constant(0.0);
  if (!mesh.nodes.empty()) {
    lo = hi = mesh.nodes.front();
    for (const auto& x : mesh.nodes) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
  }
  std::array<int, 4> per_dim{};
  for (const auto& g : mesh.groups) ++per_dim[g.dim];
  out << "$Entities\n" << per_dim[0] << ' ' << per_dim[1] << ' ' << per_dim[2] << ' ' << per_dim[3] << '\n';
  for (int dim = 0; dim < 4; ++dim) {
    for (const auto& g : mesh.groups) {
      if (g.dim != dim) continue;
      out << g.tag;
      for (int k = 0; k < 3; ++k) {
        out << ' ';
        put(out, lo[k]);
      }
      for (int k = 0; k < 3; ++k) {
        out << ' ';
        put(out, hi[k]);
      }
      out << " 1 " << g.tag << " 0\n";
    }
  }
  out << "$EndEntities\n";
  // All nodes in one block, classified on the first volume entity (or the first group's).
  const auto* home = mesh.find_group(group_names::wall, 3);
  if (home == nullptr && !mesh.groups.empty()) home = &mesh.groups.front();
  const int home_dim = home ? home->dim : 3;
  const int home_tag = home ? home->tag : 1;
  const std::size_t n = mesh.nodes.size();
  out << "$Nodes\n1 " << n << " 1 " << n << '\n' << home_dim << ' ' << home_tag << " 0 " << n << '\n';
  for (std::size_t i = 0; i < n; ++i) out << i + 1 << '\n';
  for (const auto& x : mesh.nodes) {
    put(out, x[0]);
    out << ' ';
    put(out, x[1]);
    out << ' ';
    put(out, x[2]);
    out << '\n';
  }
  out << "$EndNodes\n";
  std::size_t count = 0;
  for (const auto& g : mesh.groups) count += g.elements.size();
  out << "$Elements\n" << mesh.groups.size() << ' ' << count << " 1 " << count << '\n';
  std::size_t id = 1;
  for (const auto& g : mesh.groups) {
    out << g.dim << ' ' << g.tag << ' ' << (g.dim == 3 ? kGmshTet : kGmshTriangle) << ' '
        << g.elements.size() << '\n';
    for (int e : g.elements) {
      out << id++;
      if (g.dim == 3) {
        for (int v : mesh.tets[e]) out << ' ' << v + 1;
      } else {
        for (int v : mesh.triangles[e]) out << ' ' << v + 1;
      }
      out << '\n';
    }
  }
  out << "$EndElements\n";
}

}  // namespace

void write_msh(std::ostream& out, const TetMesh& mesh, MshVersion version) {
  version == MshVersion::v22 ? write_v22(out, mesh) : write_v41(out, mesh);
}

void write_msh(const std::filesystem::path& path, const TetMesh& mesh, MshVersion version) {
  write_file_atomically(path, [&](std::ostream& out) { write_msh(out, mesh, version); });
}

TetMesh as_stored(const TetMesh& mesh) {
  std::stringstream text;
  write_msh(text, mesh);
  return parse_msh(text, "generated mesh");
}

}  // namespace vessel
