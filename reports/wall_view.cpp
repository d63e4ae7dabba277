#include "reports/wall_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "meshes/foundation/errors.hpp"

namespace vessel::reports {

namespace {

const VtuField& require(const VtuData& vtu, const char* name, int components,
                        const std::string& source) {
  const VtuField* f = VtuData::find(vtu.point_fields, name);
  if (!f || f->components != components || f->values.size() != vtu.points.size() * components) {
    throw InputError(source + ": point field '" + name + "' with " + std::to_string(components) +
                     " component(s) per point expected (vesselverify run's fields)");
  }
  return *f;
}

/// The cells of one VTK type, `per_cell` nodes each, in file order.
std::vector<std::size_t> cells_of_type(const VtuData& vtu, int type, std::size_t per_cell) {
  std::vector<std::size_t> out;
  std::size_t begin = 0;
  for (std::size_t c = 0; c < vtu.types.size(); ++c) {
    const std::size_t end = vtu.offsets[c];
    if (vtu.types[c] == type && end - begin == per_cell) {
      out.insert(out.end(), vtu.connectivity.begin() + static_cast<std::ptrdiff_t>(begin),
                 vtu.connectivity.begin() + static_cast<std::ptrdiff_t>(end));
    }
    begin = end;
  }
  return out;
}

}  // namespace

std::vector<std::uint32_t> boundary_faces(const std::vector<std::size_t>& tets,
                                          const std::vector<Vec3>& points) {
  // The face opposite vertex f[3]; keyed by its sorted nodes.
  static constexpr std::array<std::array<int, 4>, 4> kFaces{
      {{1, 2, 3, 0}, {0, 3, 2, 1}, {0, 1, 3, 2}, {0, 2, 1, 3}}};
  std::map<std::array<std::size_t, 3>, std::pair<int, std::array<std::size_t, 3>>> faces;
  for (std::size_t t = 0; t + 3 < tets.size(); t += 4) {
    for (const auto& f : kFaces) {
      std::array<std::size_t, 3> face{tets[t + f[0]], tets[t + f[1]], tets[t + f[2]]};
      const Vec3& a = points[face[0]];
      const Vec3 normal = (points[face[1]] - a).cross(points[face[2]] - a);
      if (normal.dot(points[tets[t + f[3]]] - a) > 0.0) std::swap(face[1], face[2]);  // outwards
      auto key = face;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key, 0, face);
      ++it->second.first;
    }
  }
  std::vector<std::uint32_t> out;
  for (const auto& [key, entry] : faces) {
    if (entry.first != 1) continue;
    for (const std::size_t v : entry.second) out.push_back(static_cast<std::uint32_t>(v));
  }
  return out;
}

WallView wall_view(const VtuData& vtu, const std::string& source) {
  const VtuField& um = require(vtu, "displacement_model_m", 3, source);
  const VtuField& ur = require(vtu, "displacement_reference_m", 3, source);
  const VtuField& err = require(vtu, "error_magnitude_mm", 1, source);
  WallView v;
  std::vector<std::uint32_t> cells;
  if (const auto tets = cells_of_type(vtu, 10, 4); !tets.empty()) {
    cells = boundary_faces(tets, vtu.points);
  } else if (const auto tris = cells_of_type(vtu, 5, 3); !tris.empty()) {
    cells.assign(tris.begin(), tris.end());
    v.network_faces = true;
  } else if (const auto lines = cells_of_type(vtu, 3, 2); !lines.empty()) {
    cells.assign(lines.begin(), lines.end());
    v.lines = true;
  } else {
    throw InputError(source + ": no tetrahedra, triangles or lines to draw");
  }
  // Only the nodes the drawn cells use, renumbered in order of first use.
  std::vector<std::int64_t> drawn(vtu.points.size(), -1);
  std::vector<std::size_t> kept;
  for (std::uint32_t& c : cells) {
    if (drawn[c] < 0) {
      drawn[c] = static_cast<std::int64_t>(kept.size());
      kept.push_back(c);
    }
    c = static_cast<std::uint32_t>(drawn[c]);
  }
  v.indices = std::move(cells);
  std::vector<double> error;
  for (const std::size_t i : kept) {
    error.push_back(err.values[i]);
    for (int c = 0; c < 3; ++c) {
      v.rest_mm.push_back(static_cast<float>(vtu.points[i][c] * 1e3));
      v.u_model_mm.push_back(static_cast<float>(um.values[3 * i + c] * 1e3));
      v.u_reference_mm.push_back(static_cast<float>(ur.values[3 * i + c] * 1e3));
    }
  }
  set_colour(v, error);
  return v;
}

void set_colour(WallView& v, const std::vector<double>& values) {
  v.colour_max = 0.0;
  for (const double x : values) v.colour_max = std::max(v.colour_max, x);
  v.colour_step = v.colour_max > 0.0 ? v.colour_max / 65535.0 : 1.0;
  v.colour_code.clear();
  for (const double x : values) {
    v.colour_code.push_back(static_cast<std::uint16_t>(std::lround(x / v.colour_step)));
  }
}

std::string base64_encode(const void* data, std::size_t bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes; i += 3) {
    const std::uint32_t n = (std::uint32_t{p[i]} << 16) |
                            (i + 1 < bytes ? std::uint32_t{p[i + 1]} << 8 : 0U) |
                            (i + 2 < bytes ? std::uint32_t{p[i + 2]} : 0U);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes ? kAlphabet[(n >> 6) & 63] : '=';
    out += i + 2 < bytes ? kAlphabet[n & 63] : '=';
  }
  return out;
}

std::vector<std::uint8_t> base64_decode(const std::string& text) {
  std::vector<std::uint8_t> out;
  std::uint32_t buffer = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=') break;
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    if (c >= '0' && c <= '9') v = c - '0' + 52;
    if (c == '+') v = 62;
    if (c == '/') v = 63;
    if (v < 0) throw InputError(std::string("base64: unexpected character '") + c + "'");
    buffer = (buffer << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((buffer >> bits) & 0xFF));
    }
  }
  return out;
}

}  // namespace vessel::reports
