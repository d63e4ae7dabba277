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

}  // namespace vessel
