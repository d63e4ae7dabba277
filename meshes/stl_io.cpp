#include "meshes/stl_io.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kBinaryHeader = 80;
constexpr std::size_t kBinaryFacet = 50;  // normal, 3 vertices (12 float32) + 2-byte attribute

/// Builds an indexed surface from facet corners, merging identical coordinates.
class SurfaceBuilder {
 public:
  /// Adds a facet; returns false if two of its corners coincide (degenerate).
  bool add_facet(const std::array<Vec3, 3>& corners) {
    Triangle t{};
    for (int k = 0; k < 3; ++k) {
      const std::array<double, 3> key{corners[k].x(), corners[k].y(), corners[k].z()};
      const auto [it, inserted] = index_.emplace(key, static_cast<int>(surface_.nodes.size()));
      if (inserted) {
        surface_.nodes.push_back(corners[k]);
        surface_.source_node.push_back(-1);
      }
      t[k] = it->second;
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return false;
    surface_.triangles.push_back(t);
    return true;
  }
  TriangleSurface finish() { return std::move(surface_); }

 private:
  TriangleSurface surface_;
  std::map<std::array<double, 3>, int> index_;
};

/// Binary STL: 80-byte header, facet count, 50 bytes per facet; the size must match exactly.
bool looks_binary(std::string_view data) {
  if (data.size() < kBinaryHeader + 4) return false;
  std::uint32_t count = 0;
  std::memcpy(&count, data.data() + kBinaryHeader, 4);
  return data.size() == kBinaryHeader + 4 + static_cast<std::uintmax_t>(count) * kBinaryFacet;
}

TriangleSurface read_binary(std::string_view data, const std::string& source) {
  std::istringstream in{std::string(data.substr(kBinaryHeader)), std::ios::binary};
  std::uint32_t count = 0;
  in.read(reinterpret_cast<char*>(&count), 4);
  SurfaceBuilder builder;
  for (std::uint32_t f = 0; f < count; ++f) {
    float values[12];  // normal, then the three corners
    char attribute[2];
    in.read(reinterpret_cast<char*>(values), sizeof values);
    in.read(attribute, 2);
    if (!in) {
      throw InputError(source + ": binary STL is truncated at facet " + std::to_string(f) +
                       " of " + std::to_string(count));
    }
    std::array<Vec3, 3> corners;
    for (int k = 0; k < 3; ++k) {
      corners[k] = Vec3(values[3 + 3 * k], values[4 + 3 * k], values[5 + 3 * k]);
      if (!corners[k].allFinite()) {
        throw InputError(source + ": binary STL facet " + std::to_string(f) +
                         " has a non-finite coordinate; expected finite numbers");
      }
    }
    if (!builder.add_facet(corners)) {
      throw InputError(source + ": binary STL facet " + std::to_string(f) +
                       " is degenerate (two corners coincide)");
    }
  }
  return builder.finish();
}

TriangleSurface read_ascii(std::string_view data, const std::string& source) {
  std::istringstream in{std::string(data)};
  std::string line;
  long line_no = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(source + ":" + std::to_string(line_no) + ": " + what);
  };
  auto next_tokens = [&](std::vector<std::string>& tok) {
    while (std::getline(in, line)) {
      ++line_no;
      std::istringstream s(line);
      tok.clear();
      for (std::string w; s >> w;) tok.push_back(w);
      if (!tok.empty()) return true;
    }
    return false;
  };
  std::vector<std::string> tok;
  // Reads the next non-empty line or fails: the file ended where `what` was expected.
  auto require_tokens = [&](const char* what) {
    if (!next_tokens(tok)) fail(std::string("file is truncated: expected ") + what);
  };
  if (!next_tokens(tok) || tok[0] != "solid") {
    fail("not an STL file: expected 'solid' (ASCII) or a binary STL whose size matches its "
         "facet count");
  }
  SurfaceBuilder builder;
  bool ended = false;
  while (next_tokens(tok)) {
    if (tok[0] == "endsolid") {
      ended = true;
      break;
    }
    if (tok[0] != "facet") fail("expected 'facet' or 'endsolid', found '" + tok[0] + "'");
    require_tokens("'outer loop'");
    if (tok.size() != 2 || tok[0] != "outer" || tok[1] != "loop") fail("expected 'outer loop'");
    std::array<Vec3, 3> corners;
    for (int k = 0; k < 3; ++k) {
      require_tokens("'vertex x y z'");
      if (tok.size() != 4 || tok[0] != "vertex") fail("expected 'vertex x y z'");
      for (int c = 0; c < 3; ++c) {
        double v = 0.0;
        const auto& w = tok[1 + c];
        const auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
        if (ec != std::errc() || ptr != w.data() + w.size()) {
          fail("expected a number, found '" + w + "'");
        }
        if (!std::isfinite(v)) fail("non-finite coordinate '" + w + "'; expected a finite number");
        corners[k][c] = v;
      }
    }
    require_tokens("'endloop'");
    if (tok[0] != "endloop") fail("expected 'endloop'");
    require_tokens("'endfacet'");
    if (tok[0] != "endfacet") fail("expected 'endfacet'");
    if (!builder.add_facet(corners)) fail("degenerate facet (two corners coincide)");
  }
  if (!ended) fail("file is truncated: expected 'endsolid'");
  return builder.finish();
}

}  // namespace

TriangleSurface read_stl(const fs::path& path) {
  if (!fs::exists(path)) throw InputError(path.string() + ": STL file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open STL file for reading");
  std::ostringstream data;
  data << in.rdbuf();
  return parse_stl(data.str(), path.string());
}

TriangleSurface parse_stl(std::string_view data, const std::string& source) {
  if (data.empty()) throw InputError(source + ": STL file is empty");
  TriangleSurface s = looks_binary(data) ? read_binary(data, source) : read_ascii(data, source);
  if (s.triangles.empty()) throw InputError(source + ": STL file has no facets");
  return s;
}

void write_stl(const fs::path& path, const TriangleSurface& surface, StlFormat format) {
  auto normal = [&](const Triangle& t) -> Vec3 {
    const Vec3 n = (surface.nodes[t[1]] - surface.nodes[t[0]])
                       .cross(surface.nodes[t[2]] - surface.nodes[t[0]]);
    const double len = n.norm();
    return len > 0 ? Vec3(n / len) : Vec3::Zero();
  };
  if (format == StlFormat::binary) {
    write_file_atomically(
        path,
        [&](std::ostream& out) {
          char header[kBinaryHeader] = {};
          std::snprintf(header, sizeof header, "vesselverify binary STL");
          out.write(header, sizeof header);
          const auto count = static_cast<std::uint32_t>(surface.triangles.size());
          out.write(reinterpret_cast<const char*>(&count), 4);
          for (const auto& t : surface.triangles) {
            float data[12];
            const Vec3 n = normal(t);
            for (int c = 0; c < 3; ++c) data[c] = static_cast<float>(n[c]);
            for (int k = 0; k < 3; ++k) {
              for (int c = 0; c < 3; ++c) {
                data[3 + 3 * k + c] = static_cast<float>(surface.nodes[t[k]][c]);
              }
            }
            out.write(reinterpret_cast<const char*>(data), sizeof data);
            const char attribute[2] = {0, 0};
            out.write(attribute, 2);
          }
        },
        /*binary=*/true);
    return;
  }
  write_file_atomically(path, [&](std::ostream& out) {
    auto put = [&](double x) {
      char buf[32];
      const auto res = std::to_chars(buf, buf + sizeof buf, x);
      out << ' ';
      out.write(buf, res.ptr - buf);
    };
    out << "solid vesselverify\n";
    for (const auto& t : surface.triangles) {
      const Vec3 n = normal(t);
      out << "  facet normal";
      put(n.x());
      put(n.y());
      put(n.z());
      out << "\n    outer loop\n";
      for (int k = 0; k < 3; ++k) {
        out << "      vertex";
        for (int c = 0; c < 3; ++c) put(surface.nodes[t[k]][c]);
        out << '\n';
      }
      out << "    endloop\n  endfacet\n";
    }
    out << "endsolid vesselverify\n";
  });
}

TriangleSurface extract_surface(const TetMesh& mesh, const std::vector<std::string>& group_names,
                                std::string_view source) {
  TriangleSurface s;
  std::vector<int> local(mesh.nodes.size(), -1);
  for (const auto& name : group_names) {
    const auto& group = mesh.require_group(name, 2, source);
    for (int e : group.elements) {
      Triangle t = mesh.triangles[e];
      for (int& n : t) {
        if (local[n] < 0) {
          local[n] = static_cast<int>(s.nodes.size());
          s.nodes.push_back(mesh.nodes[n]);
          s.source_node.push_back(n);
        }
        n = local[n];
      }
      s.triangles.push_back(t);
    }
  }
  return s;
}

double surface_area(const TriangleSurface& s) {
  double a = 0.0;
  for (const auto& t : s.triangles) a += triangle_area(s.nodes[t[0]], s.nodes[t[1]], s.nodes[t[2]]);
  return a;
}

TetMesh surface_as_mesh(const TriangleSurface& surface, const std::string& group) {
  TetMesh mesh;
  mesh.nodes = surface.nodes;
  mesh.triangles = surface.triangles;
  PhysicalGroup g{group, 2, 1, {}};
  g.elements.resize(mesh.triangles.size());
  std::iota(g.elements.begin(), g.elements.end(), 0);
  mesh.groups.push_back(g);
  return mesh;
}

}  // namespace vessel
