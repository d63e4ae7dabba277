/// Three-mesh studies of the finite-strain reference (label slow): Rivlin's tube (Taylor–Hood)
/// and the manufactured solution (P1, P2) on levels 0, 1, 2, with the observed orders between
/// consecutive levels.
#include <gtest/gtest.h>

#include <iostream>

#include "fem_reference/convergence.hpp"
#include "hyperelastic_problems.hpp"

using namespace vessel;
using namespace vessel::fem;

namespace {

/// The orders between levels 0–1 and 1–2, printed.
std::vector<double> orders(const std::vector<double>& e, const char* what) {
  std::vector<double> p;
  for (std::size_t k = 1; k < e.size(); ++k) {
    p.push_back(observed_order(e[k - 1], e[k]));
    std::cout << "  " << what << " observed order, levels " << k - 1 << "-" << k << ": " << p.back()
              << "\n";
  }
  return p;
}

}  // namespace

TEST(RivlinTubeFemSlow, TaylorHoodConvergesWithOrderThree) {
  // Levels 0, 1, 2 (3.8k, 25k and about 170k DoFs; level 2 by FGMRES-block, above the UMFPACK
  // limit of the mixed system).
  std::vector<double> e;
  for (int level = 0; level <= 2; ++level) e.push_back(test::rivlin_run(level).error);
  const auto p = orders(e, "Rivlin P2-P1");
  // P2 displacement on curved (quadratic) walls: order 3 in L2.
  for (const double order : p) EXPECT_NEAR(order, 3.0, 0.3);
  EXPECT_LT(e.back(), 3e-5);
}

TEST(ManufacturedFiniteStrainSlow, P1AndP2OnThreeMeshes) {
  for (const int degree : {1, 2}) {
    std::vector<double> e;
    for (int level = 0; level <= 2; ++level)
      e.push_back(test::manufactured_run(degree, level).error);
    const auto p = orders(e, degree == 1 ? "manufactured P1" : "manufactured P2");
    for (const double order : p) EXPECT_NEAR(order, degree + 1.0, 0.3);
  }
}
