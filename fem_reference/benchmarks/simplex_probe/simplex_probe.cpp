// Probes, one at a time and each inside try/catch, what deal.II supports on tetrahedra: global
// refinement, MatrixFree + FEEvaluation with FESystem(FE_SimplexP(k), 3) + QGaussSimplex +
// MappingFE, MatrixFreeTools::compute_diagonal, MGTwoLevelTransfer P2 -> P1 (polynomial) and
// between refinement levels (geometric). Each check compares against an independent value.
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/matrix_free.h>
#include <deal.II/matrix_free/tools.h>
#include <deal.II/multigrid/mg_transfer_global_coarsening.h>

#include <iostream>

using namespace dealii;
using VectorType = LinearAlgebra::distributed::Vector<double>;

template <typename F> void probe(const char *name, F f) {
  try {
    f();
  } catch (std::exception &e) {
    std::cout << name << ": FAILED: " << e.what() << "\n";
  }
}

// Volume of the mesh by the matrix-free integral of u.e_x where u = (1,0,0): vs. 1 (unit cube).
void matrix_free_volume(Triangulation<3> &tria, unsigned degree) {
  FESystem<3> fe(FE_SimplexP<3>(degree), 3);
  MappingFE<3> mapping(FE_SimplexP<3>(1));
  DoFHandler<3> dh(tria);
  dh.distribute_dofs(fe);
  AffineConstraints<double> c;
  c.close();
  MatrixFree<3, double> mf;
  typename MatrixFree<3, double>::AdditionalData ad;
  ad.mapping_update_flags = update_values | update_gradients | update_JxW_values;
  mf.reinit(mapping, dh, c, QGaussSimplex<3>(degree + 1), ad);
  VectorType u, r;
  mf.initialize_dof_vector(u);
  mf.initialize_dof_vector(r);
  // Interpolate (1,0,0): every dof of component 0 is 1 (nodal basis).
  std::vector<types::global_dof_index> idx(fe.n_dofs_per_cell());
  for (auto &cell : dh.active_cell_iterators()) {
    cell->get_dof_indices(idx);
    for (unsigned i = 0; i < idx.size(); ++i)
      if (fe.system_to_component_index(i).first == 0) u[idx[i]] = 1.0;
  }
  // Integral of |u|^2 and of |grad u|^2 (zero for a constant field).
  double vol = 0, grad2 = 0;
  FEEvaluation<3, -1, 0, 3, double> phi(mf);
  for (unsigned c0 = 0; c0 < mf.n_cell_batches(); ++c0) {
    phi.reinit(c0);
    phi.read_dof_values(u);
    phi.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
    for (unsigned q = 0; q < phi.n_q_points; ++q) {
      auto v = phi.get_value(q);
      auto g = phi.get_gradient(q);
      auto s = v * v;
      auto t = scalar_product(g, g);
      for (unsigned l = 0; l < mf.n_active_entries_per_cell_batch(c0); ++l) {
        vol += s[l] * phi.JxW(q)[l];
        grad2 += t[l] * phi.JxW(q)[l];
      }
    }
  }
  std::cout << "MatrixFree FESystem(FE_SimplexP(" << degree << "),3) + QGaussSimplex(" << degree + 1
            << ") + MappingFE: " << dh.n_dofs() << " dofs, integral |u|^2 = " << vol
            << " (exact 1), integral |grad u|^2 = " << grad2 << " (exact 0), dofs/cell "
            << phi.dofs_per_cell << ", q points/cell " << phi.n_q_points << "\n";

  // Diagonal of the vector Laplacian by compute_diagonal vs. FEValues assembly of the same.
  VectorType diag;
  mf.initialize_dof_vector(diag);
  const std::function<void(FEEvaluation<3, -1, 0, 3, double> &)> laplace =
      [](FEEvaluation<3, -1, 0, 3, double> &p) {
        p.evaluate(EvaluationFlags::gradients);
        for (unsigned q = 0; q < p.n_q_points; ++q) p.submit_gradient(p.get_gradient(q), q);
        p.integrate(EvaluationFlags::gradients);
      };
  MatrixFreeTools::compute_diagonal(mf, diag, laplace);
  Vector<double> diag_fe(dh.n_dofs());
  FEValues<3> fv(mapping, fe, QGaussSimplex<3>(degree + 1), update_gradients | update_JxW_values);
  for (auto &cell : dh.active_cell_iterators()) {
    fv.reinit(cell);
    cell->get_dof_indices(idx);
    for (unsigned i = 0; i < idx.size(); ++i)
      for (unsigned q = 0; q < fv.n_quadrature_points; ++q)
        diag_fe[idx[i]] += fv.shape_grad(i, q).norm_square() * fv.JxW(q);
  }
  double err = 0, nrm = 0;
  for (unsigned i = 0; i < dh.n_dofs(); ++i) {
    err = std::max(err, std::abs(diag[i] - diag_fe[i]));
    nrm = std::max(nrm, std::abs(diag_fe[i]));
  }
  std::cout << "MatrixFreeTools::compute_diagonal (vector Laplacian, P" << degree
            << "): max |diag - FEValues diag| / max |diag| = " << err / nrm << "\n";
}

int main(int argc, char **argv) {
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  std::cout << std::unitbuf; // each line out before a crash in a later probe
  Triangulation<3> tria;
  GridGenerator::subdivided_hyper_cube_with_simplices(tria, 2);
  std::cout << "mesh: " << tria.n_active_cells() << " tets\n";
  probe("MatrixFree P1", [&] { matrix_free_volume(tria, 1); });
  probe("MatrixFree P2", [&] { matrix_free_volume(tria, 2); });

  probe("p-transfer P2->P1", [&] {
    DoFHandler<3> dh2(tria), dh1(tria);
    dh2.distribute_dofs(FESystem<3>(FE_SimplexP<3>(2), 3));
    dh1.distribute_dofs(FESystem<3>(FE_SimplexP<3>(1), 3));
    AffineConstraints<double> c1, c2;
    c1.close();
    c2.close();
    MGTwoLevelTransfer<3, VectorType> t;
    t.reinit_polynomial_transfer(dh2, dh1, c2, c1);
    // Prolongate the P1 interpolant of a linear field: P2 values must be that field at P2 nodes.
    VectorType v1(dh1.n_dofs()), v2(dh2.n_dofs());
    MappingFE<3> mapping(FE_SimplexP<3>(1));
    auto fill = [&](DoFHandler<3> &dh, VectorType &v) {
      const auto &fe = dh.get_fe();
      std::vector<types::global_dof_index> idx(fe.n_dofs_per_cell());
      for (auto &cell : dh.active_cell_iterators()) {
        cell->get_dof_indices(idx);
        for (unsigned i = 0; i < idx.size(); ++i) {
          const Point<3> ref = fe.get_unit_support_points()[i];
          const Point<3> x = mapping.transform_unit_to_real_cell(cell, ref);
          const unsigned comp = fe.system_to_component_index(i).first;
          v[idx[i]] = 1.0 + 2.0 * x[0] - 3.0 * x[1] + 0.5 * x[2] + comp;
        }
      }
    };
    fill(dh1, v1);
    VectorType exact(dh2.n_dofs());
    fill(dh2, exact);
    t.prolongate_and_add(v2, v1);
    v2 -= exact;
    std::cout << "MGTwoLevelTransfer::reinit_polynomial_transfer P2->P1 (vector, tets): "
              << "max error of prolongated linear field = " << v2.linfty_norm() << "\n";
  });

  probe("global refinement", [&] {
    Triangulation<3> fine;
    fine.copy_triangulation(tria);
    fine.refine_global(1);
    std::cout << "Triangulation<3>::refine_global on tets: " << tria.n_active_cells() << " -> "
              << fine.n_active_cells() << " tets\n";
  });

  probe("geometric transfer", [&] {
    Triangulation<3> coarse, fine;
    GridGenerator::subdivided_hyper_cube_with_simplices(coarse, 1);
    GridGenerator::subdivided_hyper_cube_with_simplices(fine, 1);
    fine.refine_global(1);
    DoFHandler<3> dhc(coarse), dhf(fine);
    dhc.distribute_dofs(FESystem<3>(FE_SimplexP<3>(1), 3));
    dhf.distribute_dofs(FESystem<3>(FE_SimplexP<3>(1), 3));
    AffineConstraints<double> cc, cf;
    cc.close();
    cf.close();
    MGTwoLevelTransfer<3, VectorType> t;
    t.reinit_geometric_transfer(dhf, dhc, cf, cc);
    std::cout << "MGTwoLevelTransfer::reinit_geometric_transfer between two separate "
                 "Triangulations: set up\n";
  });
  return 0;
}
