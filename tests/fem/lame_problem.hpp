#pragma once
/// The Lamé verification problem on the short structured tube: pressure on the inner wall,
/// axial rollers (u_z = 0) on both ends, in-plane rigid motion pinned without restraining u_r.
#include "fem_reference/elasticity.hpp"
#include "fem_reference/lame.hpp"

namespace vessel::test {

inline constexpr double kLamePressure = 10.0;  // Pa

inline fem::ElasticityProblem lame_problem(double nu, int degree, fem::Formulation f) {
  fem::ElasticityProblem p;
  p.material.poisson_ratio = nu;
  p.options.degree = degree;
  p.options.formulation = f;
  p.options.solver = fem::LinearSolver::automatic;  // direct up to 20k DoFs, then AMG-CG (1e-10)
  p.dirichlet = {fem::DirichletCondition::roller("inlet", 2),
                 fem::DirichletCondition::roller("outlet", 2)};
  p.point_constraints = tube_in_plane_pins(3e-3, 0.0);  // meshes/supports.hpp
  p.pressures = {{"inner_wall", kLamePressure}};
  return p;
}

inline fem::LameCylinder lame_exact(double nu) {
  return {.inner_radius = 3e-3,
          .outer_radius = 4e-3,
          .pressure = kLamePressure,
          .youngs_modulus = 14.24e3,
          .poisson_ratio = nu};
}

}  // namespace vessel::test
