#include "msm/model/model_terms.hpp"

#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/bending_term.hpp"
#include "msm/terms/volume_term.hpp"

namespace vessel::msm {

namespace {

void require_tets(const SpringNetwork& network, const std::string& term) {
  if (network.tets.empty()) {
    throw InputError(term + ": the network has no tetrahedra; expected a volume network");
  }
}

}  // namespace

std::vector<std::unique_ptr<FourNodeTerm>> make_terms(const SpringNetwork& network,
                                                      const ModelTerms& terms) {
  std::vector<std::unique_ptr<FourNodeTerm>> made;
  if (terms.volume_kappa) {
    require_tets(network, "volume term");
    made.push_back(std::make_unique<VolumeTerm>(network.nodes, network.tets, *terms.volume_kappa,
                                                network.tet_kappa_factors));
  }
  if (terms.bending_rigidity) {
    if (network.triangles.empty()) {
      throw InputError(
          "bending term (discrete-shells): the network has no triangles; expected a surface "
          "network");
    }
    made.push_back(
        std::make_unique<BendingTerm>(network.nodes, network.triangles, *terms.bending_rigidity));
  }
  if (terms.edge_pairs) {
    require_tets(network, "edge pairs");
    made.push_back(std::make_unique<EdgePairTerm>(network.nodes, network.tets, *terms.edge_pairs));
  }
  return made;
}

}  // namespace vessel::msm
