#include "msm/rods/rod_layout.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::msm::rods {

namespace {

void require_positive(double value, const std::string& key, const std::string& what) {
  if (!(std::isfinite(value) && value > 0.0)) {
    std::ostringstream s;
    s << "rod." << key << ": expected " << what << " > 0, got " << value;
    throw InputError(s.str());
  }
}

}  // namespace

SectionStiffness solid_section(const RodMaterial& material, double diameter) {
  const double pi = std::numbers::pi;
  const double area = pi * diameter * diameter / 4.0;
  const double inertia = pi * std::pow(diameter, 4) / 64.0;
  SectionStiffness s;
  s.EA = material.young * area;
  s.EI = material.young * inertia;
  s.GJ = material.shear * 2.0 * inertia;
  s.rhoA = material.density * area;
  s.rhoJ = material.density * 2.0 * inertia;
  return s;
}

double RodLayout::voronoi_length(int node) const {
  double l = 0.0;
  if (node > 0 && !ghost[node - 1]) l += 0.5 * length[node - 1];
  if (node < num_edges() && !ghost[node]) l += 0.5 * length[node];
  return l;
}

double RodLayout::vertex_mean(int node, double SectionStiffness::*member) const {
  double sum = 0.0, weight = 0.0;
  for (int j : {node - 1, node}) {
    if (j < 0 || j >= num_edges() || ghost[j]) continue;
    sum += length[j] * (section[j].*member);
    weight += length[j];
  }
  return weight > 0.0 ? sum / weight : 0.0;
}

double RodLayout::node_mass(int node) const {
  double m = 0.0;
  for (int j : {node - 1, node}) {
    if (j < 0 || j >= num_edges() || ghost[j]) continue;
    m += 0.5 * length[j] * section[j].rhoA;
  }
  return m;
}

double RodLayout::total_length() const {
  double L = 0.0;
  for (int j = 0; j < num_edges(); ++j) {
    if (!ghost[j]) L += length[j];
  }
  return L;
}

RodLayout make_layout(const RodSpec& spec) {
  require_positive(spec.material.young, "young", "Young's modulus (Pa)");
  require_positive(spec.material.shear, "shear", "shear modulus (Pa)");
  require_positive(spec.material.density, "density", "density (kg/m^3)");
  if (spec.sections.empty()) throw InputError("rod.sections: expected at least one section");
  for (std::size_t k = 0; k < spec.sections.size(); ++k) {
    const auto& s = spec.sections[k];
    const std::string key = "sections[" + std::to_string(k) + "].";
    require_positive(s.length, key + "length", "length (m)");
    require_positive(s.diameter_start, key + "diameter_start", "diameter (m)");
    require_positive(s.diameter_end, key + "diameter_end", "diameter (m)");
    require_positive(s.segments, key + "segments", "number of segments");
  }
  require_positive(spec.direction.norm(), "direction", "a non-zero clamp tangent");
  const Eigen::Vector3d t = spec.direction.normalized();

  RodLayout layout;
  layout.clamp_end = spec.clamp_end;
  const auto add_edge = [&](double l, bool ghost, const SectionStiffness& s) {
    layout.rest.push_back(layout.rest.back() + l * t);
    layout.length.push_back(l);
    layout.ghost.push_back(ghost ? 1 : 0);
    layout.section.push_back(s);
  };
  const double l0 = spec.sections.front().length / spec.sections.front().segments;
  layout.rest.push_back(spec.origin - l0 * t);  // the start clamp's ghost node
  add_edge(l0, true, {});
  layout.first_node = 1;
  for (const auto& s : spec.sections) {
    const double l = s.length / s.segments;
    for (int j = 0; j < s.segments; ++j) {
      const double f = (j + 0.5) / s.segments;
      const double d = (1.0 - f) * s.diameter_start + f * s.diameter_end;
      add_edge(l, false, solid_section(spec.material, d));
    }
  }
  layout.tip_node = layout.num_nodes() - 1;
  if (spec.clamp_end) add_edge(layout.length.back(), true, {});
  // d1 of the clamp: the unit vector normal to t closest to the z axis (or y if t is along z).
  Eigen::Vector3d a = std::abs(t.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
  layout.normal = (a - a.dot(t) * t).normalized();
  return layout;
}

RodSpec uniform_rod(const RodMaterial& material, double length, double diameter, int segments) {
  RodSpec spec;
  spec.material = material;
  spec.sections.push_back({length, diameter, diameter, segments});
  return spec;
}

}  // namespace vessel::msm::rods
