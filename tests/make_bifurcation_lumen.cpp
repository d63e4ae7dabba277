// Writes the lumens of the tests (tests/lumen_fixture.hpp), made by gmsh's OpenCASCADE kernel, as
// binary STLs: `make_bifurcation_lumen out.stl` the bent tube with a side branch
// (examples/bifurcation's lumen), `make_bifurcation_lumen --y out.stl` the Y-bifurcation and
// `make_bifurcation_lumen --y-holed out.stl` the same with two holes in its junction.
#include <iostream>
#include <string>

#include "lumen_fixture.hpp"

int main(int argc, char** argv) {
  const std::string kind = argc == 3 ? argv[1] : "";
  if (!(argc == 2 || (argc == 3 && (kind == "--y" || kind == "--y-holed")))) {
    std::cerr << "usage: make_bifurcation_lumen [--y | --y-holed] OUT.stl\n";
    return 2;
  }
  const char* out = argv[argc - 1];
  if (argc == 2) {
    vessel::test::write_bifurcation_stl(out);
  } else {
    vessel::test::YBifurcationSpec spec;
    spec.holes = kind == "--y-holed";
    vessel::write_stl(out, vessel::test::y_bifurcation_lumen(spec), vessel::StlFormat::binary);
  }
  std::cout << "wrote " << out << "\n";
  return 0;
}
