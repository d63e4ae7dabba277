#include "meshes/self_contact.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "meshes/tet_locator.hpp"

namespace vessel {

SelfPenetration find_self_penetration(const TetMesh& mesh, const std::vector<Vec3>& displacement,
                                      double tolerance) {
  if (displacement.size() != mesh.nodes.size()) {
    throw std::invalid_argument("find_self_penetration: expected one displacement per mesh node");
  }
  TetMesh deformed;
  deformed.nodes.resize(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) deformed.nodes[i] = mesh.nodes[i] + displacement[i];
  deformed.tets = mesh.tets;

  std::vector<char> on_boundary(mesh.nodes.size(), 0);
  for (const Triangle& t : mesh.triangles)
    for (const int v : t) on_boundary[static_cast<std::size_t>(v)] = 1;
  std::vector<char> positive(mesh.tets.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& x = deformed.nodes;
    const Tet& k = mesh.tets[t];
    positive[t] = signed_volume(x[k[0]], x[k[1]], x[k[2]], x[k[3]]) > 0.0;
  }

  const TetLocator locator(deformed);
  SelfPenetration out;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
    if (!on_boundary[v]) continue;
    const Vec3& x = deformed.nodes[v];
    for (const int t : locator.candidates(x)) {
      const Tet& k = mesh.tets[static_cast<std::size_t>(t)];
      if (!positive[static_cast<std::size_t>(t)] ||
          std::find(k.begin(), k.end(), static_cast<int>(v)) != k.end()) {
        continue;
      }
      if (min_barycentric(deformed, k, x) > tolerance) {
        out.nodes.push_back(static_cast<int>(v));
        out.tets.push_back(t);
        break;
      }
    }
  }
  return out;
}

double closest_approach(const TetMesh& mesh, const std::vector<Vec3>& displacement,
                        std::string_view group, double apart) {
  if (displacement.size() != mesh.nodes.size()) {
    throw std::invalid_argument("closest_approach: expected one displacement per mesh node");
  }
  const std::vector<int> nodes = mesh.group_nodes(mesh.require_group(group, 2, "the mesh"));
  double best = std::numeric_limits<double>::infinity();
  const double apart2 = apart * apart;
  for (std::size_t a = 0; a < nodes.size(); ++a) {
    const auto i = static_cast<std::size_t>(nodes[a]);
    const Vec3 xi = mesh.nodes[i] + displacement[i];
    for (std::size_t b = a + 1; b < nodes.size(); ++b) {
      const auto j = static_cast<std::size_t>(nodes[b]);
      if ((mesh.nodes[i] - mesh.nodes[j]).squaredNorm() < apart2) continue;
      best = std::min(best, (xi - mesh.nodes[j] - displacement[j]).norm());
    }
  }
  return best;
}

}  // namespace vessel
