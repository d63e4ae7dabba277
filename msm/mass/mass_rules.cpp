#include "msm/mass/mass_rules.hpp"

#include <cmath>
#include <numeric>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm {

MassRule parse_mass_rule(const std::string& name) {
  if (name == "uniform") return MassRule::uniform;
  if (name == "seed001") return MassRule::seed001;
  if (name == "consistent") return MassRule::consistent;
  throw InputError("mass rule: expected uniform, seed001 or consistent; got '" + name + "'");
}

std::string to_string(MassRule rule) {
  switch (rule) {
    case MassRule::uniform:
      return "uniform";
    case MassRule::seed001:
      return "seed001";
    case MassRule::consistent:
      return "consistent";
  }
  return "unknown";
}

namespace {
double tet_volume(const SpringNetwork& net, const Tet& t) {
  return std::abs(
      signed_volume(net.nodes[t[0]], net.nodes[t[1]], net.nodes[t[2]], net.nodes[t[3]]));
}
}  // namespace

double network_mass(const SpringNetwork& net, double density) {
  double measure = 0.0;
  if (!net.tets.empty()) {
    for (const Tet& t : net.tets) measure += tet_volume(net, t);
  } else {
    for (const Triangle& t : net.triangles) {
      measure += net.thickness * triangle_area(net.nodes[t[0]], net.nodes[t[1]], net.nodes[t[2]]);
    }
  }
  return density * measure;
}

std::vector<double> seed001_masses_as_printed(const SpringNetwork& net, double total_mass) {
  if (net.tets.empty()) {
    throw InputError("mass rule seed001: needs a tetrahedral (volume) network");
  }
  std::vector<double> Vi(net.nodes.size(), 0.0);
  std::vector<int> Ni(net.nodes.size(), 0);
  double V = 0.0;
  for (const Tet& t : net.tets) {
    const double v = tet_volume(net, t);
    V += v;
    for (int n : t) {
      Vi[n] += v;
      ++Ni[n];
    }
  }
  std::vector<double> m(net.nodes.size(), 0.0);
  for (std::size_t i = 0; i < m.size(); ++i) {
    // seed 001 eq. (2): M_i = M × V_i / (V × N × 3).
    if (Ni[i] > 0) m[i] = total_mass * Vi[i] / (V * Ni[i] * 3.0);
  }
  return m;
}

std::vector<double> nodal_masses(const SpringNetwork& net, MassRule rule, double density) {
  if (!(std::isfinite(density) && density > 0)) {
    throw InputError("density: expected a finite value > 0 kg/m³, got " + std::to_string(density));
  }
  const double M = network_mass(net, density);
  std::vector<double> m(net.nodes.size(), 0.0);
  switch (rule) {
    case MassRule::uniform:
      // seed 000 §III.A: "the mass of the whole object is evenly distributed to each particle".
      std::fill(m.begin(), m.end(), M / static_cast<double>(m.size()));
      break;
    case MassRule::seed001: {
      m = seed001_masses_as_printed(net, M);
      const double sum = std::accumulate(m.begin(), m.end(), 0.0);
      for (double& mi : m) mi *= M / sum;
      break;
    }
    case MassRule::consistent:
      if (!net.tets.empty()) {
        for (const Tet& t : net.tets) {
          const double share = density * tet_volume(net, t) / 4.0;  // ρV/4 per tet vertex
          for (int n : t) m[n] += share;
        }
      } else {
        for (const Triangle& t : net.triangles) {
          const double share = density * net.thickness *
                               triangle_area(net.nodes[t[0]], net.nodes[t[1]], net.nodes[t[2]]) /
                               3.0;  // ρ·A·t/3 per triangle vertex
          for (int n : t) m[n] += share;
        }
      }
      break;
  }
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (!(m[i] > 0)) {
      throw InputError("nodal masses: node " + std::to_string(i) +
                       " has no mass (not part of any element)");
    }
  }
  return m;
}

}  // namespace vessel::msm
