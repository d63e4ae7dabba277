#include "fem_reference/detail/weak_form.hpp"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/reference_cell.h>

#include <array>
#include <cmath>

#include "fem_reference/detail/constraints.hpp"

namespace vessel::fem::detail {

dl::Quadrature<kDim> cell_quadrature(int degree) {
  return dl::QGaussSimplex<kDim>(static_cast<unsigned>(degree + 1));
}

dl::Quadrature<kDim - 1> face_quadrature(int degree) {
  return dl::QGaussSimplex<kDim - 1>(static_cast<unsigned>(degree + 1));
}

std::unique_ptr<dl::FiniteElement<kDim>> make_element(int degree, bool mixed) {
  if (mixed) {
    // Taylor–Hood P2–P1 (step-22's u–p pattern on simplices).
    return std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(2), kDim,
                                                dl::FE_SimplexP<kDim>(1), 1);
  }
  return std::make_unique<dl::FESystem<kDim>>(dl::FE_SimplexP<kDim>(degree), kDim);
}

CellValues::CellValues(const dl::Mapping<kDim>& mapping, const dl::FiniteElement<kDim>& fe,
                       int degree)
    : cell(mapping, fe, cell_quadrature(degree),
           dl::update_values | dl::update_gradients | dl::update_JxW_values |
               dl::update_quadrature_points),
      face(mapping, fe, face_quadrature(degree),
           dl::update_values | dl::update_normal_vectors | dl::update_JxW_values) {}

WeakForm::WeakForm(const TetMesh& mesh, const ElasticityProblem& problem, bool mixed,
                   const MeshCorrespondence& mesh_map)
    : mesh_(mesh),
      problem_(problem),
      mesh_map_(mesh_map),
      mixed_(mixed),
      lambda_(problem.material.lambda()),
      mu_(problem.material.mu()) {
  for (const auto& pr : problem.pressures) {
    pressure_tags_.emplace_back(group_boundary_id(mesh, pr.group), pr.pressure);
  }
  triangle_points_.assign(mesh.triangles.size(), {});
  for (const auto& patch : problem.patches) {
    for (const SurfacePoint& q : patch.points) {
      triangle_points_[static_cast<std::size_t>(q.triangle)].push_back(
          {q.barycentric, q.weight * patch.traction});
    }
  }
}

void WeakForm::local_system(const CellIterator& cell, CellValues& values,
                            dl::FullMatrix<double>& k, dl::Vector<double>& f,
                            Vec3* applied) const {
  k = 0.0;
  local_load(cell, values, f, applied, true);
  add_stiffness(values.cell, k);
}

void WeakForm::local_load(const CellIterator& cell, CellValues& values, dl::Vector<double>& f,
                          Vec3* applied, bool with_pressure) const {
  f = 0.0;
  values.cell.reinit(cell);
  add_body_force(values.cell, f, applied);
  const auto& faces = mesh_map_.face_triangle[cell->active_cell_index()];
  for (unsigned face = 0; face < 4; ++face) {
    const int tri = faces[face];
    if (tri < 0) continue;
    if (double p = 0.0; with_pressure && pressure_on(tri, p)) {
      values.face.reinit(cell, face);
      add_pressure(values.face, p, f, applied);
    }
    add_patch_points(cell, tri, f, applied);
  }
}

void WeakForm::point_shapes(const dl::FEValues<kDim>& fev, unsigned q,
                            std::vector<PointShape>& out) const {
  const dl::FEValuesExtractors::Vector disp(0);
  const dl::FEValuesExtractors::Scalar pres(kDim);
  out.resize(fev.dofs_per_cell);
  for (unsigned i = 0; i < fev.dofs_per_cell; ++i) {
    out[i] = {fev[disp].symmetric_gradient(i, q), fev[disp].divergence(i, q),
              mixed_ ? fev[pres].value(i, q) : 0.0};
  }
}

double WeakForm::bilinear(const PointShape& a, const PointShape& b) const {
  if (mixed_) {
    // a(u,v) = ∫ 2μ ε(u):ε(v) − p div v;  −∫ q div u − ∫ p q / λ  (p = −λ div u; step-22
    // pattern, symmetric; λ = ∞ at ν = 0.5 leaves the saddle-point Stokes system).
    const double inv_lambda = std::isinf(lambda_) ? 0.0 : 1.0 / lambda_;
    return 2.0 * mu_ * (a.eps * b.eps) - a.psi * b.div - a.div * b.psi - inv_lambda * a.psi * b.psi;
  }
  // a(u,v) = ∫ λ div u div v + 2μ ε(u):ε(v)  (step-8)
  return lambda_ * a.div * b.div + 2.0 * mu_ * (a.eps * b.eps);
}

void WeakForm::add_stiffness(const dl::FEValues<kDim>& fev, dl::FullMatrix<double>& k) const {
  const unsigned n = fev.dofs_per_cell;
  std::vector<PointShape> shape;
  for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
    point_shapes(fev, q, shape);
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j <= i; ++j) k(i, j) += bilinear(shape[i], shape[j]) * fev.JxW(q);
    }
  }
  for (unsigned i = 0; i < n; ++i)
    for (unsigned j = i + 1; j < n; ++j) k(i, j) = k(j, i);
}

void WeakForm::local_residual(const CellIterator& cell, CellValues& values,
                              const dl::Vector<double>& u, dl::Vector<double>& r) const {
  dl::Vector<double> f(u.size());
  local_load(cell, values, f, nullptr, true);
  r.reinit(u.size());
  add_stiffness_times(values.cell, u, r);
  r -= f;
}

void WeakForm::add_stiffness_times(const dl::FEValues<kDim>& fev, const dl::Vector<double>& u,
                                   dl::Vector<double>& r) const {
  std::vector<PointShape> shape;
  for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
    point_shapes(fev, q, shape);
    PointShape u_h{};  // ε(u_h), div u_h and p_h at the point: a(·, ·) is linear in each
    for (unsigned j = 0; j < shape.size(); ++j) {
      u_h.eps += u(j) * shape[j].eps;
      u_h.div += u(j) * shape[j].div;
      u_h.psi += u(j) * shape[j].psi;
    }
    for (unsigned i = 0; i < shape.size(); ++i) r(i) += bilinear(shape[i], u_h) * fev.JxW(q);
  }
}

void WeakForm::add_body_force(const dl::FEValues<kDim>& fev, dl::Vector<double>& f,
                              Vec3* applied) const {
  const dl::FEValuesExtractors::Vector disp(0);
  const unsigned n = fev.dofs_per_cell;
  const Vec3 rho_g = problem_.material.density * problem_.gravity;
  dl::Tensor<1, kDim> body;
  for (unsigned q = 0; q < fev.n_quadrature_points; ++q) {
    const double jxw = fev.JxW(q);
    Vec3 b = rho_g;
    if (problem_.body_force) b += problem_.body_force(to_vec3(fev.quadrature_point(q)));
    for (unsigned c = 0; c < 3; ++c) body[c] = b[static_cast<int>(c)];
    for (unsigned i = 0; i < n; ++i) f(i) += (fev[disp].value(i, q) * body) * jxw;
    if (applied) *applied += b * jxw;
  }
}

bool WeakForm::pressure_on(int triangle, double& pressure) const {
  bool any = false;
  pressure = 0.0;
  for (const auto& [tag, p] : pressure_tags_) {
    if (tag == mesh_map_.triangle_tag[static_cast<std::size_t>(triangle)]) {
      any = true;
      pressure += p;
    }
  }
  return any;
}

void WeakForm::add_pressure(const dl::FEFaceValues<kDim>& fefv, double pressure,
                            dl::Vector<double>& f, Vec3* applied) const {
  const dl::FEValuesExtractors::Vector disp(0);
  const unsigned n = fefv.dofs_per_cell;
  for (unsigned q = 0; q < fefv.n_quadrature_points; ++q) {
    const dl::Tensor<1, kDim> t = -pressure * fefv.normal_vector(q);  // traction −p n
    const double jxw = fefv.JxW(q);
    for (unsigned i = 0; i < n; ++i) f(i) += (fefv[disp].value(i, q) * t) * jxw;
    if (applied) *applied += Vec3(t[0], t[1], t[2]) * jxw;
  }
}

void WeakForm::add_patch_points(const CellIterator& cell, int triangle, dl::Vector<double>& f,
                                Vec3* applied) const {
  const auto& points = triangle_points_[static_cast<std::size_t>(triangle)];
  if (points.empty()) return;
  // The triangle's nodes as vertices of the unit cell: a point with barycentrics λ_k on the face
  // is ξ = Σ λ_k ξ̂_k in the cell's reference coordinates (exact for the affine cell; on a curved
  // cell the same parameter point of the curved face).
  const auto& tri = mesh_.triangles[static_cast<std::size_t>(triangle)];
  std::array<dl::Point<kDim>, 3> corner;
  for (unsigned k = 0; k < 3; ++k) {
    corner[k] = dl::ReferenceCells::Tetrahedron.vertex<kDim>(
        cell_vertex_of_node(*cell, mesh_map_.vertex_node, tri[k]));
  }
  const auto& fe = cell->get_fe();
  const unsigned n = fe.n_dofs_per_cell();
  for (const PointLoad& p : points) {
    dl::Point<kDim> xi;
    for (unsigned k = 0; k < 3; ++k) xi += p.barycentric[static_cast<int>(k)] * corner[k];
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned c = 0; c < 3; ++c)
        f(i) += p.force[static_cast<int>(c)] * fe.shape_value_component(i, xi, c);
    }
    if (applied) *applied += p.force;
  }
}

}  // namespace vessel::fem::detail
