// Writes the bifurcation lumen of the tests (tests/lumen_fixture.hpp), made by gmsh's OpenCASCADE
// kernel, as a binary STL: `make_bifurcation_lumen out.stl`. examples/bifurcation's lumen is its
// output.
#include <iostream>

#include "lumen_fixture.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_bifurcation_lumen OUT.stl\n";
    return 2;
  }
  vessel::test::write_bifurcation_stl(argv[1]);
  std::cout << "wrote " << argv[1] << "\n";
  return 0;
}
