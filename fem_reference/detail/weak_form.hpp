#pragma once
/// Private to fem_reference: the weak form of small-strain linear elasticity on one cell — the
/// element stiffness of the displacement (step-8) or Taylor–Hood mixed u–p (step-22) form, the
/// body force, pressure on faces and contact-patch tractions at their quadrature points. The one
/// definition the serial and the distributed solver both assemble from, so both solve the same
/// discrete system.
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>

#include <memory>
#include <utility>
#include <vector>

#include "fem_reference/detail/boundary.hpp"
#include "fem_reference/elasticity.hpp"

namespace vessel::fem::detail {

using CellIterator = dl::DoFHandler<kDim>::active_cell_iterator;

/// Gauss rules with degree + 1 points per direction on cells and faces: exact for the stiffness of
/// affine P1 / P2 elements and for P1 / P2 face loads of a uniform pressure.
dl::Quadrature<kDim> cell_quadrature(int degree);
dl::Quadrature<kDim - 1> face_quadrature(int degree);

/// The vector element: P1 or P2 displacement, or Taylor–Hood P2–P1 (u, then p) when mixed.
std::unique_ptr<dl::FiniteElement<kDim>> make_element(int degree, bool mixed);

/// The cell and face values local_system evaluates, at the quadrature of the element's degree.
struct CellValues {
  CellValues(const dl::Mapping<kDim>& mapping, const dl::FiniteElement<kDim>& fe, int degree);
  dl::FEValues<kDim> cell;
  dl::FEFaceValues<kDim> face;
};

class WeakForm {
 public:
  /// `mesh_map` (faces ↔ triangles, vertices ↔ nodes) and `problem` must outlive the form.
  WeakForm(const TetMesh& mesh, const ElasticityProblem& problem, bool mixed,
           const MeshCorrespondence& mesh_map);

  /// The element stiffness k and load f of `cell` (values.cell is left on this cell). Adds the
  /// cell's body force and boundary loads (N) to *applied when given.
  void local_system(const CellIterator& cell, CellValues& values, dl::FullMatrix<double>& k,
                    dl::Vector<double>& f, Vec3* applied) const;

  /// Only the load f of `cell` (values.cell is left on this cell): body force, contact-patch
  /// points and, when `with_pressure`, the pressure on the reference faces (a dead load; the
  /// finite-strain reference applies pressure on the deformed faces itself).
  void local_load(const CellIterator& cell, CellValues& values, dl::Vector<double>& f,
                  Vec3* applied, bool with_pressure) const;

  /// The residual r = k u − f of `cell` at its DoF values u (values.cell is left on this cell),
  /// k u integrated at the quadrature points from u's strain without forming k: the support
  /// reactions' residual at a 30th of local_system's cost for P2.
  void local_residual(const CellIterator& cell, CellValues& values, const dl::Vector<double>& u,
                      dl::Vector<double>& r) const;

  /// Σ of the pressures on `triangle`'s group (Pa); false if no pressure acts on it.
  bool pressure_on(int triangle, double& pressure) const;

  [[nodiscard]] bool mixed() const { return mixed_; }
  [[nodiscard]] double lambda() const { return lambda_; }
  [[nodiscard]] double mu() const { return mu_; }

 private:
  /// One contact-patch quadrature point on a boundary triangle: barycentrics and the force w·t.
  struct PointLoad {
    Vec3 barycentric;
    Vec3 force;
  };

  /// A shape function's (or a field's) ε, div and pressure value at one quadrature point.
  struct PointShape {
    dl::SymmetricTensor<2, kDim> eps;
    double div = 0.0, psi = 0.0;
  };
  /// Every shape function's PointShape at quadrature point q.
  void point_shapes(const dl::FEValues<kDim>& fev, unsigned q, std::vector<PointShape>& out) const;
  /// The integrand of a(u, v) at a point (displacement or mixed form; the formula's one place).
  [[nodiscard]] double bilinear(const PointShape& a, const PointShape& b) const;
  /// a(u, v) at the cell's quadrature points (values.cell reinit'ed on the cell).
  void add_stiffness(const dl::FEValues<kDim>& fev, dl::FullMatrix<double>& k) const;
  /// r_i += a(u_h, φ_i) at the cell's quadrature points, u_h = Σ_j u_j φ_j: k u (add_stiffness's
  /// k) without k.
  void add_stiffness_times(const dl::FEValues<kDim>& fev, const dl::Vector<double>& u,
                           dl::Vector<double>& r) const;
  /// ∫ (ρg + b(x))·v dV.
  void add_body_force(const dl::FEValues<kDim>& fev, dl::Vector<double>& f, Vec3* applied) const;
  /// ∫ −p n·v dA over one face, by the face quadrature.
  void add_pressure(const dl::FEFaceValues<kDim>& fefv, double pressure, dl::Vector<double>& f,
                    Vec3* applied) const;
  /// Σ_q w_q t·v(ξ_q) over the patch points on `triangle`, a face of `cell`.
  void add_patch_points(const CellIterator& cell, int triangle, dl::Vector<double>& f,
                        Vec3* applied) const;
  const TetMesh& mesh_;
  const ElasticityProblem& problem_;
  const MeshCorrespondence& mesh_map_;
  bool mixed_;
  double lambda_, mu_;
  std::vector<std::pair<int, double>> pressure_tags_;   ///< (group tag, p) per pressure load
  std::vector<std::vector<PointLoad>> triangle_points_;  ///< per TetMesh triangle
};

/// The load vector of this rank's cells (every cell on a serial mesh) into `rhs`, without the
/// stiffness matrix but for the cells whose prescribed values u₀ ≠ 0 enter the free rows as
/// −K_e u₀; returns those cells' applied load (N). Call rhs.compress(add) after, on several ranks.
template <class Vector>
Vec3 assemble_load_vector(const WeakForm& form, const dl::Mapping<kDim>& mapping,
                          const dl::DoFHandler<kDim>& dof, int degree,
                          const dl::AffineConstraints<double>& constraints, Vector& rhs) {
  const auto& fe = dof.get_fe();
  CellValues values(mapping, fe, degree);
  const unsigned n = fe.n_dofs_per_cell();
  dl::FullMatrix<double> k(n, n);
  dl::Vector<double> f(n);
  std::vector<dl::types::global_dof_index> dofs(n);
  Vec3 applied = Vec3::Zero();
  const bool lift = constraints.has_inhomogeneities();
  for (const auto& cell : dof.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    cell->get_dof_indices(dofs);
    if (lift) {
      form.local_system(cell, values, k, f, &applied);
      constraints.distribute_local_to_global(f, dofs, rhs, k);
    } else {
      form.local_load(cell, values, f, &applied, true);
      constraints.distribute_local_to_global(f, dofs, rhs);
    }
  }
  return applied;
}

}  // namespace vessel::fem::detail
