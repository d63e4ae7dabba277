#include "msm/fem/tet_term.hpp"

#include <cmath>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

TetTerm::TetTerm(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame,
                 const char* name)
    : FourNodeTerm(static_cast<int>(nodes.size())), lame_(lame) {
  if (!std::isfinite(lame.mu) || !std::isfinite(lame.lambda) || lame.mu < 0.0) {
    throw InputError(std::string(name) +
                     ": expected finite Lamé parameters with μ ≥ 0 (Pa), got μ = " +
                     std::to_string(lame.mu) + ", λ = " + std::to_string(lame.lambda));
  }
  const int num_nodes = static_cast<int>(nodes.size());
  shapes_.reserve(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e) {
    for (int v : tets[e]) {
      if (v < 0 || v >= num_nodes) {
        throw InputError(std::string(name) + ": tet " + std::to_string(e) + " refers to node " +
                         std::to_string(v) + ", expected an index below " +
                         std::to_string(num_nodes));
      }
    }
    const Tet& t = tets[e];
    try {
      shapes_.push_back(tet_rest_shape({nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]}));
    } catch (const InputError&) {
      throw InputError(std::string(name) + ": tet " + std::to_string(e) +
                       " has zero rest volume; expected a non-degenerate tetrahedron");
    }
  }
  set_elements(std::move(tets));
}

}  // namespace vessel::msm
