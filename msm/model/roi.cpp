#include "msm/model/roi.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

namespace vessel::msm {

std::vector<char> nodes_beyond(const std::vector<Vec3>& nodes, const Vec3& centre, double radius) {
  std::vector<char> out(nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) out[i] = (nodes[i] - centre).norm() > radius;
  return out;
}

std::vector<char> held_nodes(const Problem& full, const Vec3& centre, double radius) {
  const auto n = static_cast<std::size_t>(full.num_dofs() / 3);
  std::vector<char> held(n, 0);
  std::size_t moving = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 x = full.rest.segment<3>(3 * static_cast<Eigen::Index>(i));
    const bool all_fixed = full.fixed[3 * i] && full.fixed[3 * i + 1] && full.fixed[3 * i + 2];
    held[i] = all_fixed || (x - centre).norm() > radius;
    moving += !held[i];
  }
  if (moving == 0) {
    throw std::runtime_error("region of interest of radius " + std::to_string(radius * 1e3) +
                             " mm holds every node: no node within it moves (expected a radius "
                             "larger than the node spacing at the contact)");
  }
  return held;
}

RoiNetwork restrict_network(const SpringNetwork& full, const std::vector<char>& held,
                            bool carry_triangles) {
  const std::size_t n = full.nodes.size();
  std::vector<char> keep(n, 0);
  for (std::size_t i = 0; i < n; ++i) keep[i] = !held[i];
  for (const Spring& s : full.springs) {
    if (!held[s.a] || !held[s.b]) keep[s.a] = keep[s.b] = 1;  // the boundary ring
  }
  // Likewise a tet with a moving node: its held nodes bound it (the volume and edge-pair terms;
  // the edge-pair model has no springs to find them by).
  for (const Tet& t : full.tets) {
    if (held[t[0]] && held[t[1]] && held[t[2]] && held[t[3]]) continue;
    for (int v : t) keep[v] = 1;
  }
  // Triangles for the bending term: a hinge moves when any of its four nodes does, and its two
  // triangles are then one with a moving node and one sharing an edge with it.
  std::vector<Triangle> carried;
  if (carry_triangles) {
    std::set<std::pair<int, int>> moving_edges;
    auto edge = [](int p, int q) { return std::make_pair(std::min(p, q), std::max(p, q)); };
    for (const Triangle& t : full.triangles) {
      if (held[t[0]] && held[t[1]] && held[t[2]]) continue;
      for (int k = 0; k < 3; ++k) moving_edges.insert(edge(t[k], t[(k + 1) % 3]));
    }
    for (const Triangle& t : full.triangles) {
      bool near = false;
      for (int k = 0; k < 3; ++k) near = near || moving_edges.count(edge(t[k], t[(k + 1) % 3]));
      if (!near) continue;
      carried.push_back(t);
      for (int v : t) keep[v] = 1;
    }
  }
  RoiNetwork roi;
  std::vector<int> to_roi(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    to_roi[i] = static_cast<int>(roi.full_index.size());
    roi.full_index.push_back(static_cast<int>(i));
    roi.network.nodes.push_back(full.nodes[i]);
    roi.network.source_node.push_back(full.source_node.empty() ? -1 : full.source_node[i]);
    roi.moving_nodes += !held[i];
  }
  for (const Spring& s : full.springs) {
    if (held[s.a] && held[s.b]) continue;
    Spring r = s;
    r.a = to_roi[s.a];
    r.b = to_roi[s.b];
    roi.network.springs.push_back(r);
  }
  roi.network.thickness = full.thickness;
  for (const Triangle& t : carried) {
    roi.network.triangles.push_back({to_roi[t[0]], to_roi[t[1]], to_roi[t[2]]});
  }
  // Tets with a moving node are carried (their nodes are all kept, above), for the volume and
  // edge-pair terms. Triangles only with carry_triangles (above): the spring model and the solvers
  // other than PBD use springs only.
  for (std::size_t e = 0; e < full.tets.size(); ++e) {
    const Tet& t = full.tets[e];
    if (held[t[0]] && held[t[1]] && held[t[2]] && held[t[3]]) continue;
    roi.network.tets.push_back({to_roi[t[0]], to_roi[t[1]], to_roi[t[2]], to_roi[t[3]]});
    if (!full.tet_kappa_factors.empty()) {
      roi.network.tet_kappa_factors.push_back(full.tet_kappa_factors[e]);
    }
  }
  return roi;
}

Problem restrict_problem(const Problem& full, const RoiNetwork& roi, const std::vector<char>& held,
                         const Form& form) {
  const auto m = static_cast<Eigen::Index>(roi.full_index.size());
  Problem p;
  p.form = &form;
  p.rest.resize(3 * m);
  p.external_force.resize(3 * m);
  p.mass.resize(3 * m);
  p.fixed.assign(static_cast<std::size_t>(3 * m), 1);
  for (Eigen::Index k = 0; k < m; ++k) {
    const int i = roi.full_index[static_cast<std::size_t>(k)];
    p.rest.segment<3>(3 * k) = full.rest.segment<3>(3 * i);
    p.external_force.segment<3>(3 * k) = full.external_force.segment<3>(3 * i);
    p.mass.segment<3>(3 * k) = full.mass.segment<3>(3 * i);
    if (!held[static_cast<std::size_t>(i)]) {
      for (int c = 0; c < 3; ++c) p.fixed[3 * k + c] = full.fixed[3 * i + c];
    }
  }
  return p;
}

}  // namespace vessel::msm
