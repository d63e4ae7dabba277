#pragma once
/// The msm FEM tests' tube: a structured closed annulus of Kuhn tets (inner radius 2 mm, wall
/// 1 mm, length 6 mm), its axis along z, and a Problem on it with the end z = 0 held and lumped
/// masses ρV₀/4 per corner (ρ = 1000 kg/m³).
#include <cmath>
#include <numbers>

#include "msm/fem/tet_term.hpp"
#include "tests/fixtures/kuhn_block.hpp"

namespace vessel::msm::test {

inline TetMesh fem_tube(int nr = 1, int ntheta = 12, int nz = 3) {
  TetMesh m = vessel::test::kuhn_block(nr, ntheta, nz, 1.0);
  auto id = [&](int i, int j, int k) { return (k * (ntheta + 1) + j) * (nr + 1) + i; };
  for (int k = 0; k <= nz; ++k) {
    for (int j = 0; j <= ntheta; ++j) {
      for (int i = 0; i <= nr; ++i) {
        const double r = 2e-3 + 1e-3 * i / nr, th = 2.0 * std::numbers::pi * j / ntheta;
        m.nodes[id(i, j, k)] = Vec3(r * std::cos(th), r * std::sin(th), 6e-3 * k / nz);
      }
    }
  }
  // Close the annulus: the nodes at θ = 2π are those at θ = 0 (the map (r, θ, z) keeps the
  // orientation, its Jacobian determinant being r > 0).
  for (Tet& t : m.tets) {
    for (int& v : t) {
      const int i = v % (nr + 1), j = (v / (nr + 1)) % (ntheta + 1),
                k = v / ((nr + 1) * (ntheta + 1));
      if (j == ntheta) v = id(i, 0, k);
    }
  }
  remove_unused_nodes(m);
  return m;
}

inline VectorXd flat_positions(const std::vector<Vec3>& nodes) {
  VectorXd x(3 * nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) x.segment<3>(3 * i) = nodes[i];
  return x;
}

/// Rest positions, lumped masses, the z = 0 end held, no load (the caller sets it).
inline Problem fem_tube_problem(const TetMesh& mesh, const TetTerm& term) {
  Problem p;
  p.form = &term;
  p.rest = flat_positions(mesh.nodes);
  p.external_force = VectorXd::Zero(p.rest.size());
  p.mass = VectorXd::Zero(p.rest.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    for (int v : mesh.tets[e]) {
      p.mass.segment<3>(3 * v).array() += 1000.0 * term.rest_shapes()[e].volume / 4.0;
    }
  }
  p.fixed.assign(p.rest.size(), 0);
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (mesh.nodes[i].z() < 1e-9) p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
  }
  return p;
}

/// A load along +x spread evenly over the nodes of the free end (z = 6 mm), N in total.
inline void load_free_end(const TetMesh& mesh, Problem& p, double total) {
  std::vector<int> end;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (mesh.nodes[i].z() > 6e-3 - 1e-9) end.push_back(static_cast<int>(i));
  }
  p.external_force.setZero();
  for (int i : end) p.external_force[3 * i] = total / static_cast<double>(end.size());
}

}  // namespace vessel::msm::test
