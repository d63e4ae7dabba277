#include "meshes/vtu_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "meshes/foundation/atomic_file.hpp"
#include "meshes/foundation/errors.hpp"

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

void write_fields(std::ostream& out, const std::vector<VtuField>& fields, bool tuples = false) {
  for (const auto& f : fields) {
    out << "        <DataArray type=\"Float64\" Name=\"" << f.name
        << "\" NumberOfComponents=\"" << f.components << "\"";
    if (tuples) out << " NumberOfTuples=\"" << f.values.size() / f.components << "\"";
    out << " format=\"ascii\">\n";
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
               const std::vector<VtuField>& cell_fields,
               const std::vector<VtuField>& field_data) {
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
  for (const auto& f : field_data) {
    if (f.components < 1 || f.values.empty() || f.values.size() % f.components != 0) {
      throw std::invalid_argument("VTU field data '" + f.name + "' has " +
                                  std::to_string(f.values.size()) + " values, expected tuples of " +
                                  std::to_string(f.components));
    }
  }
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n";
    if (!field_data.empty()) {
      out << "    <FieldData>\n";
      write_fields(out, field_data, true);
      out << "    </FieldData>\n";
    }
    out << "    <Piece NumberOfPoints=\"" << points.size() << "\" NumberOfCells=\"" << n_cells
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

/// A minimal reader of the XML that VTU files are: elements with attributes, and the text of
/// DataArray elements. Comments and processing instructions are skipped.
class VtuParser {
 public:
  VtuParser(std::string text, std::string file) : text_(std::move(text)), file_(std::move(file)) {}

  [[noreturn]] void fail(std::size_t pos, const std::string& what) const {
    const auto line = 1 + std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(
                                                                     std::min(pos, text_.size())),
                                     '\n');
    throw InputError(file_ + ":" + std::to_string(line) + ": " + what);
  }

  VtuData parse() {
    VtuData d;
    std::vector<std::string> stack;
    bool seen_file = false, seen_piece = false;
    std::size_t n_points = 0, n_cells = 0, piece_pos = 0;
    bool has_points = false;
    std::size_t pos = 0;
    while ((pos = text_.find('<', pos)) != std::string::npos) {
      if (text_.compare(pos, 4, "<!--") == 0) {
        pos = skip_to(pos, "-->");
        continue;
      }
      if (text_.compare(pos, 2, "<?") == 0) {
        pos = skip_to(pos, "?>");
        continue;
      }
      const std::size_t tag_pos = pos;
      Tag tag = read_tag(pos);
      if (tag.closing) {
        if (stack.empty() || stack.back() != tag.name) {
          fail(tag_pos, "closing tag </" + tag.name + "> does not match the open element" +
                            (stack.empty() ? std::string() : " <" + stack.back() + ">"));
        }
        stack.pop_back();
        continue;
      }
      if (tag.name == "VTKFile") {
        seen_file = true;
        if (attribute(tag, "type") != "UnstructuredGrid") {
          fail(tag_pos, "VTKFile type \"" + attribute(tag, "type") +
                            "\"; expected \"UnstructuredGrid\" (a .vtu file)");
        }
        // VTK names a compressor even for ASCII files; it applies only to binary arrays, which
        // each DataArray's format check refuses.
      } else if (tag.name == "AppendedData") {
        fail(tag_pos, "appended (binary) data; expected ASCII data arrays (format=\"ascii\"; in "
                      "ParaView: Save Data with Data Mode \"Ascii\")");
      } else if (tag.name == "Piece") {
        if (seen_piece) fail(tag_pos, "a second <Piece>; expected one piece");
        seen_piece = true;
        piece_pos = tag_pos;
        n_points = count_attribute(tag, "NumberOfPoints", tag_pos);
        n_cells = count_attribute(tag, "NumberOfCells", tag_pos);
      } else if (tag.name == "DataArray") {
        const std::string section = stack.empty() ? "" : stack.back();
        store_array(read_data_array(tag, tag_pos, pos), section, tag_pos, d, has_points);
        continue;
      }
      if (!tag.self_closing) stack.push_back(tag.name);
    }
    if (!seen_file) fail(0, "no <VTKFile> element; expected a VTK XML unstructured grid (.vtu)");
    if (!seen_piece) fail(0, "no <Piece>; expected one piece with points and cells");
    if (!has_points) fail(piece_pos, "no <Points> data array");
    check_piece(d, n_points, n_cells, piece_pos);
    return d;
  }

 private:
  struct Tag {
    std::string name;
    bool closing = false;
    bool self_closing = false;
    std::map<std::string, std::string> attributes;
  };

  /// The DataArray whose start tag `tag` was just read (pos after it): its name, components and
  /// ASCII values; pos ends after its end tag.
  VtuField read_data_array(const Tag& tag, std::size_t tag_pos, std::size_t& pos) const {
    VtuField f;
    f.name = attribute(tag, "Name");
    const std::string comps = attribute(tag, "NumberOfComponents");
    f.components = comps.empty() ? 1 : static_cast<int>(count_attribute(tag, "NumberOfComponents", tag_pos));
    if (f.components < 1) fail(tag_pos, "DataArray \"" + f.name + "\": NumberOfComponents 0; expected >= 1");
    const std::string format = attribute(tag, "format");
    if (format != "ascii") {
      fail(tag_pos, "DataArray \"" + f.name + "\" has format \"" + format +
                        "\"; expected format=\"ascii\" (in ParaView: Save Data with Data "
                        "Mode \"Ascii\")");
    }
    if (!tag.self_closing) {
      const std::size_t end = text_.find("</DataArray>", pos);
      if (end == std::string::npos) fail(tag_pos, "DataArray \"" + f.name + "\" is not closed");
      f.values = numbers(pos, end, f.name);
      pos = end + std::string("</DataArray>").size();
    }
    if (f.values.size() % static_cast<std::size_t>(f.components) != 0) {
      fail(tag_pos, "DataArray \"" + f.name + "\" has " + std::to_string(f.values.size()) +
                        " values, not a multiple of its " + std::to_string(f.components) +
                        " components");
    }
    return f;
  }

  /// Puts a data array where its section says: point, cell or field data, the points, or the
  /// cells' connectivity, offsets and types.
  void store_array(VtuField f, const std::string& section, std::size_t tag_pos, VtuData& d,
                   bool& has_points) const {
    if (section == "PointData") {
      d.point_fields.push_back(std::move(f));
    } else if (section == "CellData") {
      d.cell_fields.push_back(std::move(f));
    } else if (section == "FieldData") {
      d.field_data.push_back(std::move(f));
    } else if (section == "Points") {
      if (f.components != 3) fail(tag_pos, "Points: expected 3 components per point");
      has_points = true;
      for (std::size_t i = 0; i < f.values.size(); i += 3) {
        d.points.emplace_back(f.values[i], f.values[i + 1], f.values[i + 2]);
      }
    } else if (section == "Cells") {
      if (f.name == "connectivity") {
        d.connectivity = indices(f, tag_pos);
      } else if (f.name == "offsets") {
        d.offsets = indices(f, tag_pos);
      } else if (f.name == "types") {
        for (const std::size_t t : indices(f, tag_pos)) d.types.push_back(static_cast<int>(t));
      }
    }
  }

  /// The piece against its declared sizes: as many points and cells as it says, ascending cell
  /// offsets that end at the connectivity's length, connectivity naming existing points, and
  /// point and cell data with one tuple per point and per cell.
  void check_piece(const VtuData& d, std::size_t n_points, std::size_t n_cells,
                   std::size_t piece_pos) const {
    if (d.points.size() != n_points) {
      fail(piece_pos, "NumberOfPoints=" + std::to_string(n_points) + " but the Points array has " +
                          std::to_string(d.points.size()) + " points");
    }
    if (d.offsets.size() != n_cells || d.types.size() != n_cells) {
      fail(piece_pos, "NumberOfCells=" + std::to_string(n_cells) + " but the Cells have " +
                          std::to_string(d.offsets.size()) + " offsets and " +
                          std::to_string(d.types.size()) + " types");
    }
    std::size_t previous = 0;
    for (std::size_t c = 0; c < n_cells; ++c) {
      if (d.offsets[c] <= previous || d.offsets[c] > d.connectivity.size()) {
        fail(piece_pos, "Cells: offset " + std::to_string(d.offsets[c]) + " of cell " +
                            std::to_string(c) + " does not fit a connectivity of " +
                            std::to_string(d.connectivity.size()) + " entries (expected ascending ends)");
      }
      previous = d.offsets[c];
    }
    if (n_cells > 0 && previous != d.connectivity.size()) {
      fail(piece_pos, "Cells: the last offset " + std::to_string(previous) +
                          " is not the connectivity's length " + std::to_string(d.connectivity.size()));
    }
    for (std::size_t k = 0; k < d.connectivity.size(); ++k) {
      if (d.connectivity[k] >= n_points) {
        fail(piece_pos, "Cells: connectivity entry " + std::to_string(k) + " names point " +
                            std::to_string(d.connectivity[k]) + "; expected < " + std::to_string(n_points));
      }
    }
    for (const auto& f : d.point_fields) check_count(f, n_points, "point", piece_pos);
    for (const auto& f : d.cell_fields) check_count(f, n_cells, "cell", piece_pos);
  }

  std::size_t skip_to(std::size_t pos, const char* end) const {
    const std::size_t e = text_.find(end, pos);
    if (e == std::string::npos) fail(pos, std::string("unterminated markup; expected ") + end);
    return e + std::char_traits<char>::length(end);
  }

  /// Reads the tag at text_[pos] == '<'; pos ends after its '>'.
  Tag read_tag(std::size_t& pos) const {
    const std::size_t start = pos;
    const std::size_t end = text_.find('>', pos);
    if (end == std::string::npos) fail(start, "unterminated tag");
    std::string body = text_.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    Tag t;
    if (!body.empty() && body.front() == '/') {
      t.closing = true;
      body.erase(0, 1);
    }
    if (!body.empty() && body.back() == '/') {
      t.self_closing = true;
      body.pop_back();
    }
    std::size_t i = 0;
    while (i < body.size() && !std::isspace(static_cast<unsigned char>(body[i]))) ++i;
    t.name = body.substr(0, i);
    if (t.name.empty()) fail(start, "a tag without a name");
    while (i < body.size()) {
      while (i < body.size() && std::isspace(static_cast<unsigned char>(body[i]))) ++i;
      if (i >= body.size()) break;
      const std::size_t eq = body.find('=', i);
      if (eq == std::string::npos) fail(start, "<" + t.name + ">: attribute without a value");
      std::string key = body.substr(i, eq - i);
      while (!key.empty() && std::isspace(static_cast<unsigned char>(key.back()))) key.pop_back();
      std::size_t q = eq + 1;
      while (q < body.size() && std::isspace(static_cast<unsigned char>(body[q]))) ++q;
      if (q >= body.size() || (body[q] != '"' && body[q] != '\'')) {
        fail(start, "<" + t.name + ">: attribute " + key + " without a quoted value");
      }
      const std::size_t close = body.find(body[q], q + 1);
      if (close == std::string::npos) fail(start, "<" + t.name + ">: unterminated attribute " + key);
      t.attributes[key] = body.substr(q + 1, close - q - 1);
      i = close + 1;
    }
    return t;
  }

  static std::string attribute(const Tag& t, const std::string& key) {
    const auto it = t.attributes.find(key);
    return it == t.attributes.end() ? std::string() : it->second;
  }

  std::size_t count_attribute(const Tag& t, const std::string& key, std::size_t pos) const {
    const std::string v = attribute(t, key);
    std::size_t n = 0;
    const auto r = std::from_chars(v.data(), v.data() + v.size(), n);
    if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size()) {
      fail(pos, "<" + t.name + "> " + key + "=\"" + v + "\"; expected a non-negative integer");
    }
    return n;
  }

  std::vector<double> numbers(std::size_t begin, std::size_t end, const std::string& name) const {
    std::vector<double> out;
    std::size_t i = begin;
    while (i < end) {
      while (i < end && std::isspace(static_cast<unsigned char>(text_[i]))) ++i;
      if (i >= end) break;
      if (text_.compare(i, 15, "<InformationKey") == 0) {  // ParaView's array metadata
        const std::size_t close = text_.find("</InformationKey>", i);
        if (close == std::string::npos || close > end) fail(i, "unterminated <InformationKey>");
        i = close + std::string("</InformationKey>").size();
        continue;
      }
      std::size_t j = i;
      while (j < end && !std::isspace(static_cast<unsigned char>(text_[j]))) ++j;
      double v = 0.0;
      const char* first = text_.data() + i;
      const char* last = text_.data() + j;
      if (*first == '+') ++first;  // from_chars refuses a leading '+', which C's strtod accepts
      const auto r = std::from_chars(first, last, v);
      if (r.ec != std::errc() || r.ptr != last) {
        fail(i, "DataArray \"" + name + "\": value " + std::to_string(out.size()) + " is \"" +
                    text_.substr(i, std::min<std::size_t>(j - i, 40)) + "\"; expected a number");
      }
      out.push_back(v);
      i = j;
    }
    return out;
  }

  std::vector<std::size_t> indices(const VtuField& f, std::size_t pos) const {
    std::vector<std::size_t> out;
    out.reserve(f.values.size());
    for (std::size_t k = 0; k < f.values.size(); ++k) {
      const double v = f.values[k];
      if (!(v >= 0) || v != std::floor(v) || v > 9.0e15) {
        std::ostringstream m;
        m << "Cells: " << f.name << " value " << k << " is " << v
          << "; expected a non-negative integer";
        fail(pos, m.str());
      }
      out.push_back(static_cast<std::size_t>(v));
    }
    return out;
  }

  void check_count(const VtuField& f, std::size_t count, const char* kind, std::size_t pos) const {
    if (f.values.size() != count * static_cast<std::size_t>(f.components)) {
      fail(pos, std::string(kind) + " data \"" + f.name + "\" has " +
                    std::to_string(f.values.size()) + " values; expected " + std::to_string(count) +
                    " " + kind + "s × " + std::to_string(f.components) + " components");
    }
  }

  std::string text_;
  std::string file_;
};

}  // namespace

const VtuField* VtuData::find(const std::vector<VtuField>& fields, const std::string& name) {
  for (const auto& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

VtuData read_vtu(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open the file");
  std::ostringstream text;
  text << in.rdbuf();
  return VtuParser(text.str(), path.string()).parse();
}

}  // namespace vessel
