#pragma once
/// The energy terms a mass-spring model sums besides its springs, listed once. Each term has its
/// parameter in ModelTerms and one line in make_terms (model_terms.cpp); a new term is its own
/// file in msm/terms/, a field here and that line.
#include <memory>
#include <optional>
#include <vector>

#include "msm/terms/edge_pair_term.hpp"
#include "msm/terms/four_node_blocks.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

/// Which terms a network carries, with their parameters; none: without that term.
struct ModelTerms {
  /// κ (Pa) of the volume term on network.tets (Golec et al. 2020; msm/terms/volume_term.hpp).
  std::optional<double> volume_kappa;
  /// D (N·m) of the Discrete Shells bending term on network.triangles (Grinspun et al. 2003;
  /// msm/terms/bending_term.hpp).
  std::optional<double> bending_rigidity;
  /// The StVK material of the edge-pair term on network.tets (Kikuuwe et al. 2009;
  /// msm/terms/edge_pair_term.hpp).
  std::optional<LameParameters> edge_pairs;

  [[nodiscard]] bool empty() const { return !volume_kappa && !bending_rigidity && !edge_pairs; }
};

/// The terms `terms` asks for, built on the network. InputError if the network lacks the tets or
/// triangles a term needs.
std::vector<std::unique_ptr<FourNodeTerm>> make_terms(const SpringNetwork& network,
                                                      const ModelTerms& terms);

}  // namespace vessel::msm
