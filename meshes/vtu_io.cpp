#include "meshes/vtu_io.hpp"

#include <charconv>
#include <stdexcept>

#include "meshes/atomic_file.hpp"

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

void write_vtu(const std::filesystem::path& path, const TetMesh& mesh,
               const std::vector<VtuField>& point_fields,
               const std::vector<VtuField>& cell_fields) {
  for (const auto& f : point_fields) check(f, mesh.nodes.size(), "point");
  for (const auto& f : cell_fields) check(f, mesh.tets.size(), "cell");
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << mesh.nodes.size() << "\" NumberOfCells=\""
        << mesh.tets.size() << "\">\n";
    out << "      <PointData>\n";
    write_fields(out, point_fields);
    out << "      </PointData>\n      <CellData>\n";
    write_fields(out, cell_fields);
    out << "      </CellData>\n";
    out << "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
           "format=\"ascii\">\n";
    for (const auto& x : mesh.nodes) {
      put(out, x.x());
      out << ' ';
      put(out, x.y());
      out << ' ';
      put(out, x.z());
      out << '\n';
    }
    out << "        </DataArray>\n      </Points>\n      <Cells>\n";
    out << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : mesh.tets) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
    out << "        </DataArray>\n";
    out << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= mesh.tets.size(); ++i) out << 4 * i << '\n';
    out << "        </DataArray>\n";
    out << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < mesh.tets.size(); ++i) out << kVtkTetra << '\n';
    out << "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
        << "</VTKFile>\n";
  });
}

}  // namespace vessel
