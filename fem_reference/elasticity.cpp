/// The serial FEM reference: setup (triangulation, DoFs, constraints, the curved mapping), the
/// public ElasticitySolver entry points, and error norms. Structure after deal.II's step-8
/// (elasticity) and step-22 (mixed u–p). The static solve is in static_solve.cpp, the mixed
/// system's FGMRES in mixed_block_solve.cpp, point evaluation in point_evaluation.cpp, modes and
/// the Newmark transient in modes.cpp and transient.cpp; the weak form, boundary tagging,
/// constraints and post-processing they share with the distributed solver in detail/.
#include "fem_reference/elasticity.hpp"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/component_mask.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe_field.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "fem_reference/detail/constraints.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "fem_reference/detail/validation.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

using detail::Clock;
using detail::seconds_since;

double Material::lambda() const {
  if (poisson_ratio >= 0.5) return std::numeric_limits<double>::infinity();
  // λ = Eν / ((1+ν)(1−2ν))  (e.g. Sadd, Elasticity, 3rd ed., Table 4.1)
  return youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
}

double Material::mu() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }

std::string to_string(Formulation f) {
  switch (f) {
    case Formulation::automatic:
      return "auto";
    case Formulation::displacement:
      return "displacement";
    case Formulation::mixed:
      return "mixed";
  }
  return "?";
}

std::string to_string(LinearSolver s) {
  switch (s) {
    case LinearSolver::automatic:
      return "auto";
    case LinearSolver::direct:
      return "direct";
    case LinearSolver::cg_amg:
      return "cg-amg";
    case LinearSolver::gmres_block:
      return "gmres-block";
    case LinearSolver::matrix_free:
      return "matrix-free";
  }
  return "?";
}

std::vector<CurvedSurface> tube_curved_walls(double a, double b) {
  auto cylinder = [](double r) {
    return [r](const Vec3& x) {
      const double rho = std::hypot(x.x(), x.y());
      return Vec3(x.x() * r / rho, x.y() * r / rho, x.z());
    };
  };
  return {{"inner_wall", cylinder(a)}, {"outer_wall", cylinder(b)}};
}

void ElasticitySolver::Impl::build_triangulation() {
  detail::create_coarse_triangulation(mesh, tria);
  mesh_map = detail::match_and_tag_boundary(tria, mesh);
  // The serial cells keep the TetMesh order (the locator's tet index is the cell's index).
  for (std::size_t c = 0; c < mesh_map.cell_tet.size(); ++c) {
    if (mesh_map.cell_tet[c] != static_cast<int>(c))
      throw std::logic_error("deal.II reordered the cells of the triangulation");
  }
}

void ElasticitySolver::Impl::setup_dofs() {
  const dl::FE_SimplexP<kDim> linear(1);
  linear_mapping = std::make_unique<dl::MappingFE<kDim>>(linear);
  mapping = linear_mapping->clone();
  if (degree == 2 && !problem.curved_surfaces.empty()) setup_curved_mapping();
  fe = detail::make_element(degree, mixed);
  dof.reinit(tria);
  dof.distribute_dofs(*fe);
  cells.assign(mesh.tets.size(), {});
  for (const auto& cell : dof.active_cell_iterators()) cells[cell->active_cell_index()] = cell;

  constraints.clear();
  support_constraints(dof, constraints);
  constraints.close();
  linear_choice = detail::chosen_solver(
      problem.options,
      {mixed, dof.n_dofs(), degree, degree == 2 && !problem.curved_surfaces.empty(), true});
  if (linear_choice.solver != LinearSolver::matrix_free) ensure_matrix();
  rhs.reinit(dof.n_dofs());
  solution.reinit(dof.n_dofs());
}

void ElasticitySolver::Impl::support_constraints(const dl::DoFHandler<kDim>& dof_handler,
                                                 dl::AffineConstraints<double>& c) const {
  detail::add_point_constraints(mesh, problem.point_constraints, dof_handler,
                                mesh_map.vertex_node, c);
  detail::add_dirichlet_constraints(mesh, problem.dirichlet, *mapping, dof_handler, c);
}

void ElasticitySolver::Impl::ensure_matrix() {
  if (!sparsity.empty()) return;
  dl::DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
  dl::DoFTools::make_sparsity_pattern(dof, dsp, constraints, false);
  sparsity.copy_from(dsp);
  matrix.reinit(sparsity);
}

void ElasticitySolver::Impl::setup_curved_mapping() {
  geometry_fe = std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(2), kDim);
  geometry_dof.reinit(tria);
  geometry_dof.distribute_dofs(*geometry_fe);
  geometry_positions.reinit(geometry_dof.n_dofs());
  std::map<int, const CurvedSurface*> by_tag;
  for (const auto& cs : problem.curved_surfaces) {
    by_tag[mesh.require_group(cs.group, 2, "curved surface").tag] = &cs;
  }
  const auto& unit = geometry_fe->get_unit_support_points();
  const unsigned n = geometry_fe->n_dofs_per_cell();
  std::vector<dl::types::global_dof_index> dofs(n);
  // A node on a curved face is shared with cells that touch the surface only along an edge: once
  // projected (from a cell that has the face), it must not be overwritten from such a cell.
  std::vector<bool> projected(geometry_dof.n_dofs(), false);
  for (const auto& cell : geometry_dof.active_cell_iterators()) {
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < n; ++i) {
      if (projected[dofs[i]]) continue;
      const auto x = linear_mapping->transform_unit_to_real_cell(cell, unit[i]);
      Vec3 y(x[0], x[1], x[2]);
      // A P2 node lies on a face iff it is one of the face's vertices or edge midpoints.
      for (unsigned f = 0; f < cell->n_faces(); ++f) {
        if (!cell->face(f)->at_boundary()) continue;
        const auto it = by_tag.find(static_cast<int>(cell->face(f)->boundary_id()));
        if (it == by_tag.end()) continue;
        const auto face = cell->face(f);
        const double h = face->diameter();
        bool on_face = false;
        for (unsigned a = 0; a < 3 && !on_face; ++a) {
          for (unsigned b = a; b < 3 && !on_face; ++b) {
            const auto m = 0.5 * (face->vertex(a) + face->vertex(b));
            on_face = x.distance(m) < 1e-9 * h;
          }
        }
        if (on_face) {
          y = it->second->project(y);
          projected[dofs[i]] = true;
          break;
        }
      }
      geometry_positions(dofs[i]) = y[geometry_fe->system_to_component_index(i).first];
    }
  }
  mapping = std::make_unique<dl::MappingFEField<kDim, kDim, dl::Vector<double>>>(
      geometry_dof, geometry_positions);
  result.curved = true;
}

ElasticitySolver::ElasticitySolver(const TetMesh& mesh, ElasticityProblem problem) {
  detail::validate_problem(mesh, problem);
  const auto t0 = Clock::now();
  impl_ = std::make_unique<Impl>(mesh, std::move(problem));
  auto& im = *impl_;
  im.mixed = detail::uses_mixed_formulation(im.problem);
  im.degree = im.mixed ? 2 : im.problem.options.degree;
  im.build_triangulation();
  im.form = std::make_unique<detail::WeakForm>(im.mesh, im.problem, im.mixed, im.mesh_map);
  im.setup_dofs();
  im.locator = std::make_unique<detail::TetLocator>(im.mesh);
  im.result.element = im.mixed ? "P2-P1 (Taylor-Hood)" : (im.degree == 1 ? "P1" : "P2");
  im.result.formulation = im.mixed ? Formulation::mixed : Formulation::displacement;
  im.result.n_dofs = im.dof.n_dofs();
  if (im.mixed) {
    std::vector<bool> mask(4, false);
    mask[3] = true;
    im.result.n_pressure_dofs =
        dl::DoFTools::extract_dofs(im.dof, dl::ComponentMask(mask)).n_elements();
  }
  im.result.timings.setup = seconds_since(t0);
}

ElasticitySolver::~ElasticitySolver() = default;

const ElasticityResult& ElasticitySolver::solve() {
  auto& im = *impl_;
  auto t0 = Clock::now();
  if (im.linear_choice.solver == LinearSolver::matrix_free) {
    im.assemble_load();
    im.result.timings.assembly = seconds_since(t0);
    t0 = Clock::now();
    im.solve_displacement_matrix_free();
  } else {
    im.assemble();
    im.result.timings.assembly = seconds_since(t0);
    t0 = Clock::now();
    im.solve_linear(true,
                    im.problem.options.keep_factor ? DirectReuse::factor : DirectReuse::nothing);
  }
  im.result.timings.solve = seconds_since(t0);
  t0 = Clock::now();
  im.postprocess();
  im.result.timings.postprocess = seconds_since(t0);
  im.solved = true;
  return im.result;
}

const ElasticityResult& ElasticitySolver::result() const { return impl_->result; }

std::vector<double> ElasticitySolver::solution_dofs() const {
  const auto& im = *impl_;
  if (!im.solved) throw std::logic_error("solution_dofs called before solve()");
  return {im.solution.begin(), im.solution.end()};
}

const ElasticityResult& ElasticitySolver::restore(ElasticityResult result,
                                                  const std::vector<double>& dofs) {
  auto& im = *impl_;
  if (dofs.size() != im.dof.n_dofs() || result.n_dofs != im.dof.n_dofs()) {
    throw std::invalid_argument("restore: " + std::to_string(dofs.size()) +
                                " DoF values for a solver with " +
                                std::to_string(im.dof.n_dofs()) + " DoFs");
  }
  im.solution.reinit(im.dof.n_dofs());
  std::copy(dofs.begin(), dofs.end(), im.solution.begin());
  result.timings.setup = im.result.timings.setup;  // this solver's own set-up
  im.result = std::move(result);
  im.solved = true;
  return im.result;
}

ElasticityResult solve_elasticity(const TetMesh& mesh, const ElasticityProblem& problem) {
  ElasticitySolver solver(mesh, problem);
  return solver.solve();
}

double ElasticitySolver::relative_l2_error(const std::function<Vec3(const Vec3&)>& exact) const {
  const auto& im = *impl_;
  if (!im.solved) throw std::logic_error("relative_l2_error called before solve()");
  // Own loop rather than VectorTools::integrate_difference: with the curved MappingFEField on
  // simplices deal.II 9.4 returns NaN there, so the quadrature points are computed from the
  // geometry field itself (x_q = Σ x_i φ_i(ξ_q)) and only JxW comes from the mapping.
  const dl::QWitherdenVincentSimplex<kDim> quad(static_cast<unsigned>(im.degree + 2));
  const dl::FEValuesExtractors::Vector disp(0);
  dl::FEValues<kDim> fev(*im.mapping, *im.fe, quad, dl::update_values | dl::update_JxW_values);
  dl::FEValues<kDim> lin(*im.linear_mapping, *im.fe, quad, dl::update_quadrature_points);
  std::unique_ptr<dl::FEValues<kDim>> geo;
  if (im.result.curved) {
    geo = std::make_unique<dl::FEValues<kDim>>(*im.linear_mapping, *im.geometry_fe, quad,
                                               dl::update_values);
  }
  std::vector<dl::Tensor<1, kDim>> uh(quad.size());
  std::vector<dl::types::global_dof_index> gdofs(im.geometry_fe ? im.geometry_fe->n_dofs_per_cell()
                                                                : 0);
  double err2 = 0.0, norm2 = 0.0;
  for (const auto& cell : im.dof.active_cell_iterators()) {
    fev.reinit(cell);
    lin.reinit(cell);
    fev[disp].get_function_values(im.solution, uh);
    std::vector<Vec3> xq(quad.size());
    for (unsigned q = 0; q < quad.size(); ++q) {
      const auto& p = lin.quadrature_point(q);
      xq[q] = Vec3(p[0], p[1], p[2]);
    }
    if (geo) {
      const typename dl::DoFHandler<kDim>::active_cell_iterator gcell(
          &im.tria, cell->level(), cell->index(), &im.geometry_dof);
      geo->reinit(gcell);
      gcell->get_dof_indices(gdofs);
      for (unsigned q = 0; q < quad.size(); ++q) {
        Vec3 x = Vec3::Zero();
        for (unsigned i = 0; i < gdofs.size(); ++i) {
          x[im.geometry_fe->system_to_component_index(i).first] +=
              im.geometry_positions(gdofs[i]) * geo->shape_value(i, q);
        }
        xq[q] = x;
      }
    }
    for (unsigned q = 0; q < quad.size(); ++q) {
      const Vec3 u = exact(xq[q]);
      const Vec3 d = Vec3(uh[q][0], uh[q][1], uh[q][2]) - u;
      err2 += d.squaredNorm() * fev.JxW(q);
      norm2 += u.squaredNorm() * fev.JxW(q);
    }
  }
  return std::sqrt(err2 / norm2);
}

double ElasticitySolver::domain_volume() const {
  const auto& im = *impl_;
  dl::FEValues<kDim> fev(*im.mapping, *im.fe, detail::cell_quadrature(2), dl::update_JxW_values);
  double v = 0.0;
  for (const auto& cell : im.dof.active_cell_iterators()) {
    fev.reinit(cell);
    for (unsigned q = 0; q < fev.n_quadrature_points; ++q) v += fev.JxW(q);
  }
  return v;
}

}  // namespace vessel::fem
