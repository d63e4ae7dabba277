#include "meshes/vtu_io.hpp"

#include <cctype>
#include <cerrno>
#include <optional>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "meshes/atomic_file.hpp"
#include "meshes/errors.hpp"

namespace vessel {

namespace {

constexpr int kVtkTetra = 10;

void put(std::ostream& out, double x) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);
  out.write(buf, res.ptr - buf);
}

void check(const VtuField& f, std::size_t count, const char* kind) {
  if (f.components < 1 || f.values.size() != count * static_cast<std::size_t>(f.components)) {
    throw std::invalid_argument(std::string("VTU ") + kind + " field '" + f.name + "' has " +
                                std::to_string(f.values.size()) + " values, expected " +
                                std::to_string(count) + " × " + std::to_string(f.components));
  }
}

void write_fields(std::ostream& out, const std::vector<VtuField>& fields) {
  for (const auto& f : fields) {
    out << "        <DataArray type=\"Float64\" Name=\"" << f.name
        << "\" NumberOfComponents=\"" << f.components << "\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < f.values.size(); ++i) {
      put(out, f.values[i]);
      out << ((i + 1) % static_cast<std::size_t>(f.components) == 0 ? '\n' : ' ');
    }
    out << "        </DataArray>\n";
  }
}

}  // namespace

void write_vtu(const std::filesystem::path& path, const std::vector<Vec3>& points,
               const VtuCells& cells, const std::vector<VtuField>& point_fields,
               const std::vector<VtuField>& cell_fields) {
  const auto per_cell = static_cast<std::size_t>(cells.points_per_cell);
  if (per_cell == 0 || cells.connectivity.size() % per_cell != 0) {
    throw std::invalid_argument("VTU cells: " + std::to_string(cells.connectivity.size()) +
                                " connectivity entries are not a multiple of " +
                                std::to_string(cells.points_per_cell) + " points per cell");
  }
  for (const std::size_t p : cells.connectivity) {
    if (p >= points.size()) {
      throw std::invalid_argument("VTU cells: point " + std::to_string(p) + " of " +
                                  std::to_string(points.size()));
    }
  }
  const std::size_t n_cells = cells.connectivity.size() / per_cell;
  for (const auto& f : point_fields) check(f, points.size(), "point");
  for (const auto& f : cell_fields) check(f, n_cells, "cell");
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << points.size() << "\" NumberOfCells=\"" << n_cells
        << "\">\n";
    out << "      <PointData>\n";
    write_fields(out, point_fields);
    out << "      </PointData>\n      <CellData>\n";
    write_fields(out, cell_fields);
    out << "      </CellData>\n";
    out << "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
           "format=\"ascii\">\n";
    for (const auto& x : points) {
      put(out, x.x());
      out << ' ';
      put(out, x.y());
      out << ' ';
      put(out, x.z());
      out << '\n';
    }
    out << "        </DataArray>\n      </Points>\n      <Cells>\n";
    out << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < cells.connectivity.size(); ++i) {
      out << cells.connectivity[i] << ((i + 1) % per_cell == 0 ? '\n' : ' ');
    }
    out << "        </DataArray>\n";
    out << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= n_cells; ++i) out << per_cell * i << '\n';
    out << "        </DataArray>\n";
    out << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n_cells; ++i) out << cells.vtk_type << '\n';
    out << "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
        << "</VTKFile>\n";
  });
}

VtuCells tet_cells(const std::vector<Tet>& tets) {
  VtuCells cells{kVtkTetra, 4, {}};
  cells.connectivity.reserve(4 * tets.size());
  for (const auto& t : tets) {
    for (const int v : t) cells.connectivity.push_back(static_cast<std::size_t>(v));
  }
  return cells;
}

void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuField>& point_fields,
               const std::vector<VtuField>& cell_fields) {
  write_vtu(path, mesh.nodes, tet_cells(mesh.tets), point_fields, cell_fields);
}

namespace {

/// A minimal reader of the XML VTK writes: tags and their attributes, no entities or CDATA.
struct VtuText {
  std::string text;
  std::string file;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file + ": " + what);
  }

  /// The attribute `name` of the tag starting at `tag` (up to its '>'), or "".
  [[nodiscard]] std::string attribute(std::size_t tag, const std::string& name) const {
    const std::size_t end = text.find('>', tag);
    std::size_t at = tag;
    while (true) {
      at = text.find(name + "=", at);
      if (at == std::string::npos || at > end) return "";
      const char before = text[at - 1];
      if (before == ' ' || before == '\t' || before == '\n' || before == '\r') break;
      at += name.size();
    }
    const std::size_t q = at + name.size() + 1;
    const char quote = text[q];
    if (quote != '"' && quote != '\'') return "";
    const std::size_t close = text.find(quote, q + 1);
    return text.substr(q + 1, close - q - 1);
  }

  /// The body of the element `<name ...>...</name>` within [from, to), or nullopt; an empty
  /// element `<name/>` gives an empty body.
  [[nodiscard]] std::optional<std::pair<std::size_t, std::size_t>> element(
      const std::string& name, std::size_t from, std::size_t to) const {
    std::size_t at = from;
    while (true) {
      at = text.find("<" + name, at);
      if (at == std::string::npos || at >= to) return std::nullopt;
      const char next = text[at + 1 + name.size()];
      if (next == ' ' || next == '>' || next == '/' || next == '\n' || next == '\t' || next == '\r') break;
      ++at;
    }
    const std::size_t open_end = text.find('>', at);
    if (open_end == std::string::npos) fail("unterminated <" + name + "> tag");
    if (text[open_end - 1] == '/') return std::make_pair(open_end + 1, open_end + 1);
    const std::size_t close = text.find("</" + name + ">", open_end);
    if (close == std::string::npos || close > to) fail("<" + name + "> is not closed");
    return std::make_pair(open_end + 1, close);
  }

  /// Every DataArray in [from, to): its name, components and values.
  [[nodiscard]] std::vector<VtuField> arrays(std::size_t from, std::size_t to,
                                             const std::string& where) const {
    std::vector<VtuField> out;
    std::size_t at = from;
    while (true) {
      const std::size_t tag = text.find("<DataArray", at);
      if (tag == std::string::npos || tag >= to) break;
      const auto body = element("DataArray", tag, to);
      VtuField f;
      f.name = attribute(tag, "Name");
      const std::string format = attribute(tag, "format");
      if (format != "ascii") {
        fail(where + " DataArray '" + f.name + "': found format=\"" + format +
             "\", expected format=\"ascii\" (binary and appended data are not read)");
      }
      const std::string comps = attribute(tag, "NumberOfComponents");
      f.components = comps.empty() ? 1 : std::atoi(comps.c_str());
      if (f.components < 1) fail(where + " DataArray '" + f.name + "': NumberOfComponents \"" + comps + "\"");
      const char* p = text.c_str() + body->first;
      const char* end = text.c_str() + body->second;
      while (true) {
        while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
        if (p >= end) break;
        char* stop = nullptr;
        errno = 0;
        const double v = std::strtod(p, &stop);
        if (stop == p || stop > end) {
          fail(where + " DataArray '" + f.name + "': value " + std::to_string(f.values.size() + 1) +
               " is not a number (\"" + std::string(p, std::min<std::size_t>(12, end - p)) + "\")");
        }
        f.values.push_back(v);
        p = stop;
      }
      out.push_back(std::move(f));
      at = body->second;
    }
    return out;
  }
};

std::size_t count_attribute(const VtuText& t, std::size_t tag, const std::string& name) {
  const std::string v = t.attribute(tag, name);
  char* stop = nullptr;
  const long long n = std::strtoll(v.c_str(), &stop, 10);
  if (v.empty() || *stop != '\0' || n < 0) t.fail("<Piece> " + name + ": found \"" + v + "\", expected a count");
  return static_cast<std::size_t>(n);
}

void check_count(const VtuText& t, const VtuField& f, std::size_t count, const std::string& where) {
  if (f.values.size() != count * static_cast<std::size_t>(f.components)) {
    t.fail(where + " DataArray '" + f.name + "': " + std::to_string(f.values.size()) +
           " values, expected " + std::to_string(count) + " × " + std::to_string(f.components));
  }
}

}  // namespace

const VtuField* VtuData::point_field(const std::string& name) const {
  for (const auto& f : point_fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

const VtuField* VtuData::cell_field(const std::string& name) const {
  for (const auto& f : cell_fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

VtuData read_vtu(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": VTU file not found or unreadable");
  VtuText t;
  t.file = path.string();
  std::ostringstream buf;
  buf << in.rdbuf();
  t.text = buf.str();
  const std::size_t grid = t.text.find("<UnstructuredGrid");
  if (t.text.find("<VTKFile") == std::string::npos || grid == std::string::npos) {
    t.fail("not a VTK UnstructuredGrid file; expected <VTKFile type=\"UnstructuredGrid\">");
  }
  if (t.text.find("<AppendedData") != std::string::npos) {
    t.fail("appended data is not read; expected DataArrays in format=\"ascii\"");
  }
  const std::size_t piece = t.text.find("<Piece", grid);
  if (piece == std::string::npos) t.fail("no <Piece>; expected one");
  const std::size_t n_points = count_attribute(t, piece, "NumberOfPoints");
  const std::size_t n_cells = count_attribute(t, piece, "NumberOfCells");
  const auto piece_body = t.element("Piece", piece, t.text.size());
  const auto [from, to] = *piece_body;
  VtuData d;
  if (const auto pd = t.element("PointData", from, to)) {
    d.point_fields = t.arrays(pd->first, pd->second, "<PointData>");
    for (const auto& f : d.point_fields) check_count(t, f, n_points, "<PointData>");
  }
  if (const auto cd = t.element("CellData", from, to)) {
    d.cell_fields = t.arrays(cd->first, cd->second, "<CellData>");
    for (const auto& f : d.cell_fields) check_count(t, f, n_cells, "<CellData>");
  }
  const auto pts = t.element("Points", from, to);
  if (!pts) t.fail("no <Points>; expected the point coordinates");
  const std::vector<VtuField> coords = t.arrays(pts->first, pts->second, "<Points>");
  if (coords.size() != 1 || coords[0].components != 3) {
    t.fail("<Points>: expected one DataArray with NumberOfComponents=\"3\"");
  }
  check_count(t, coords[0], n_points, "<Points>");
  for (std::size_t i = 0; i < n_points; ++i) {
    d.points.emplace_back(coords[0].values[3 * i], coords[0].values[3 * i + 1],
                          coords[0].values[3 * i + 2]);
  }
  if (const auto cells = t.element("Cells", from, to)) {
    const std::vector<VtuField> arrays = t.arrays(cells->first, cells->second, "<Cells>");
    const auto find = [&](const std::string& name) -> const VtuField& {
      for (const auto& f : arrays) {
        if (f.name == name) return f;
      }
      t.fail("<Cells>: no DataArray '" + name + "'");
    };
    const VtuField& conn = find("connectivity");
    const VtuField& offsets = find("offsets");
    const VtuField& types = find("types");
    check_count(t, offsets, n_cells, "<Cells>");
    check_count(t, types, n_cells, "<Cells>");
    std::size_t previous = 0;
    for (std::size_t c = 0; c < n_cells; ++c) {
      const double o = offsets.values[c];
      if (o < static_cast<double>(previous) || o > static_cast<double>(conn.values.size())) {
        t.fail("<Cells>: offset " + std::to_string(c) + " out of order or beyond the connectivity");
      }
      previous = static_cast<std::size_t>(o);
      d.offsets.push_back(previous);
      d.cell_types.push_back(static_cast<int>(types.values[c]));
    }
    for (const double v : conn.values) {
      if (v < 0 || v >= static_cast<double>(n_points)) {
        t.fail("<Cells>: connectivity names point " + std::to_string(static_cast<long long>(v)) +
               " of " + std::to_string(n_points));
      }
      d.connectivity.push_back(static_cast<std::size_t>(v));
    }
  } else if (n_cells > 0) {
    t.fail("no <Cells>; expected " + std::to_string(n_cells) + " cells");
  }
  return d;
}

}  // namespace vessel
