/// Natural frequencies and mode shapes of the serial displacement system: K x = ω² M x by
/// shift-invert Lanczos (Spectra) with CHOLMOD factorisations.
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fem_reference/cholmod_solve.hpp"
#include "fem_reference/detail/serial_solver.hpp"
#include "meshes/foundation/errors.hpp"

namespace vessel::fem {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

/// (K − σM)⁻¹ for Spectra's shift-invert mode, by CHOLMOD's supernodal Cholesky (K − σM is SPD
/// for σ < 0).
class ShiftInvertCholmod {
 public:
  using Scalar = double;
  ShiftInvertCholmod(const SpMat& k, const SpMat& m) : k_(k), m_(m) {}
  [[nodiscard]] Eigen::Index rows() const { return k_.rows(); }
  [[nodiscard]] Eigen::Index cols() const { return k_.cols(); }
  void set_shift(const double& sigma) {
    const SpMat a = k_ - sigma * m_;
    try {
      factor_ = std::make_unique<CholmodFactor>(a);
    } catch (const std::runtime_error&) {
      throw std::runtime_error("modal analysis: factorisation of K - sigma M failed");
    }
  }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = factor_->solve(x);
  }

 private:
  const SpMat& k_;
  const SpMat& m_;
  std::unique_ptr<CholmodFactor> factor_;
};

}  // namespace

ModalResult ElasticitySolver::modes(int count) const {
  const auto& im = *impl_;
  if (im.mixed) {
    throw InputError(
        "modal analysis needs the displacement formulation (P1 or P2); the mixed "
        "Taylor-Hood system has no pressure mass: use nu below the mixed threshold");
  }
  if (count < 1) throw InputError("modal analysis: number of modes must be >= 1");
  if (!(im.problem.material.density > 0.0)) {
    throw InputError("modal analysis needs density > 0 (the mass matrix)");
  }
  const auto t0 = detail::Clock::now();
  // K and the consistent mass M_ij = ∫ ρ φ_i·φ_j on the free DoFs (not Dirichlet or point
  // constrained): the constraints made homogeneous.
  auto sys = im.assemble_free_system(true);
  const int n_free = static_cast<int>(sys.K.rows());
  if (n_free <= count) throw InputError("modal analysis: fewer free DoFs than modes requested");
  const SpMat& k = sys.K;
  const SpMat& m = sys.M;
  const std::vector<int>& free_index = sys.free_index;

  ShiftInvertCholmod op(k, m);
  Spectra::SparseSymMatProd<double> bop(m);
  const int ncv = std::min(n_free, std::max(2 * count + 1, 30));
  // σ slightly below zero keeps K − σM positive definite even without constraints (rigid modes).
  const double sigma = -1.0;  // (rad/s)²
  Spectra::SymGEigsShiftSolver<ShiftInvertCholmod, Spectra::SparseSymMatProd<double>,
                               Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, count, ncv, sigma);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw std::runtime_error("modal analysis: the Lanczos iteration did not converge");
  }
  const Eigen::VectorXd lambda = eigs.eigenvalues();
  const Eigen::MatrixXd vectors = eigs.eigenvectors();
  ModalResult out;
  out.n_dofs = static_cast<std::size_t>(n_free);
  for (int e = 0; e < lambda.size(); ++e) {
    out.frequencies_hz.push_back(std::sqrt(std::max(lambda[e], 0.0)) / (2.0 * std::numbers::pi));
    std::vector<Vec3> shape = im.nodal([&](Index d) {
      const int fi = free_index[d];
      return fi < 0 ? 0.0 : vectors(fi, e);
    });
    double mx = 0.0;
    for (const auto& u : shape) mx = std::max(mx, u.norm());
    if (mx > 0.0)
      for (auto& u : shape) u /= mx;
    out.mode_shapes.push_back(std::move(shape));
  }
  out.seconds = detail::seconds_since(t0);
  return out;
}

}  // namespace vessel::fem
