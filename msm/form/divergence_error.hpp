#pragma once
/// What every time-stepping solver (integrators, PBD) throws when a run blows up: a run that
/// diverges stops with a clear message (step, node, energy) and never writes a result.
#include <stdexcept>
#include <string>

namespace vessel::msm {

/// A run that blew up: a non-finite value, or the energy beyond the limit.
class DivergenceError : public std::runtime_error {
 public:
  DivergenceError(int step, int node, double energy, const std::string& why);
  int step;
  int node;
  double energy;  ///< J
};

}  // namespace vessel::msm
