#include "msm/form/divergence_error.hpp"

#include <iomanip>
#include <sstream>

namespace vessel::msm {

namespace {
std::string four_digits(double v) {
  std::ostringstream s;
  s << std::setprecision(4) << v;
  return s.str();
}
}  // namespace

DivergenceError::DivergenceError(int step_, int node_, double energy_, const std::string& why)
    : std::runtime_error("diverged at step " + std::to_string(step_) + ", node " +
                         std::to_string(node_) + ", energy " + four_digits(energy_) + " J: " +
                         why + " (reduce the time step or use implicit-euler); no result written"),
      step(step_),
      node(node_),
      energy(energy_) {}

}  // namespace vessel::msm
