#include "msm/stiffness/hybrid_moduli.hpp"

#include <cmath>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

std::string hybrid_refusal(double E, double nu) {
  if (!(E > 0) || !std::isfinite(E)) {
    return "hybrid volume model: expected Young's modulus E > 0 Pa, got " + std::to_string(E);
  }
  if (!(nu >= 0.25 && nu < 0.5)) {
    return "hybrid volume model (volume_term): poisson_ratio ν must be in [0.25, 0.5), got " +
        std::to_string(nu) +
        (nu >= 0.5 ? "; at ν = 0.5 the volume term's κ = λ − μ is infinite (an incompressibility "
                     "constraint, which this penalty model does not offer)"
                   : "; below 1/4 the volume term's κ = λ − μ is negative, and a negative volume "
                     "energy makes sliver tets unstable (the static solver diverged on a gmsh "
                     "cube at ν = 0 and 0.1); volume_moduli = \"homogenised\" reaches lower "
                     "ν with a per-tet stability clip");
  }
  return {};
}

HybridModuli hybrid_moduli(double E, double nu) {
  if (std::string why = hybrid_refusal(E, nu); !why.empty()) throw InputError(why);
  HybridModuli m;
  m.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  m.mu = E / (2 * (1 + nu));
  m.spring_youngs_modulus = 2.5 * m.mu;  // van-gelder: λ_s = μ_s = 0.4·E_s (header)
  m.kappa = m.lambda - m.mu;
  return m;
}

}  // namespace vessel::msm
