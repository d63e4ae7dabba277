#include "msm/rods/xpbd_rod.hpp"

#include <Eigen/Dense>
#include <array>

#include "msm/rods/cosserat_terms.hpp"
#include "msm/rods/element_assembly.hpp"

namespace vessel::msm::rods {

namespace {

/// C (3) and ∂C/∂q (3 × N) of a vector constraint at the dofs' values.
template <int N, class F>
void constraint_and_jacobian(const F& f, const Eigen::VectorXd& x, const std::array<int, N>& dofs,
                             Eigen::Vector3d& c, Eigen::Matrix<double, 3, N>& J) {
  const V3<Jet<N, false>> r = f(jet_inputs<N, false>(x, dofs));
  c << r.x.v, r.y.v, r.z.v;
  J.row(0) = r.x.g.transpose();
  J.row(1) = r.y.g.transpose();
  J.row(2) = r.z.g.transpose();
}

/// One XPBD correction of a 3-row block with compliance diag(alpha) (already divided by h²).
template <int N>
void correct(Eigen::VectorXd& x, const Eigen::VectorXd& w, const std::array<int, N>& dofs,
             const Eigen::Vector3d& c, const Eigen::Matrix<double, 3, N>& J,
             const Eigen::Vector3d& alpha, Eigen::Vector3d& lambda) {
  Eigen::Matrix<double, N, 1> wd;
  for (int a = 0; a < N; ++a) wd[a] = w[dofs[a]];
  Eigen::Matrix3d A = J * wd.asDiagonal() * J.transpose();
  A.diagonal() += alpha;
  const Eigen::Vector3d dl = A.ldlt().solve(-c - alpha.cwiseProduct(lambda));
  const Eigen::Matrix<double, N, 1> dx = wd.asDiagonal() * (J.transpose() * dl);
  for (int a = 0; a < N; ++a) x[dofs[a]] += dx[a];
  lambda += dl;
}

}  // namespace

XpbdRod::XpbdRod(RodLayout layout, double alignment, XpbdOptions options)
    : model_(std::move(layout), alignment, false), options_(options) {
  x_ = model_.rest_state();
  v_ = VectorXd::Zero(x_.size());
  const VectorXd m = model_.lumped_mass();
  const auto fixed = model_.clamp_fixed();
  inverse_mass_ = VectorXd::Zero(x_.size());
  for (int i = 0; i < m.size(); ++i) inverse_mass_[i] = (fixed[i] || m[i] <= 0.0) ? 0.0 : 1.0 / m[i];
  // Quaternion inertia: the segment's own rotary inertia ρA l³/12 (as a rigid bar about its
  // midpoint), 4× per component; the section's ρI l alone makes the frames ~10⁷ times lighter
  // than the points and the Gauss–Seidel sweeps diverge.
  const RodLayout& L = model_.layout();
  for (int j = 0; j < L.num_edges(); ++j) {
    if (L.ghost[j]) continue;
    const double l = L.length[j];
    const double mq = 4.0 * L.section[j].rhoA * l * l * l / 12.0;
    inverse_mass_.segment<4>(model_.quaternion_dof(j)).setConstant(1.0 / mq);
  }
  lambda_ss_.assign(model_.layout().num_edges(), Eigen::Vector3d::Zero());
  lambda_bt_.assign(model_.layout().num_nodes(), Eigen::Vector3d::Zero());
}

void XpbdRod::project_stretch_shear(int j, double h) {
  const RodLayout& L = model_.layout();
  const auto dofs = edge_dofs(j);
  const double l = L.length[j];
  Eigen::Vector3d c;
  Eigen::Matrix<double, 3, 10> J;
  constraint_and_jacobian<10>([l](const auto& q) { return stretch_shear_strain(q, l); }, x_, dofs, c, J);
  const Eigen::Vector3d alpha = Eigen::Vector3d::Constant(1.0 / (model_.alignment() * l * h * h));
  correct<10>(x_, inverse_mass_, dofs, c, J, alpha, lambda_ss_[j]);
  x_.segment<4>(model_.quaternion_dof(j)).normalize();
}

void XpbdRod::project_bend_twist(int i, double h) {
  const RodLayout& L = model_.layout();
  const double lbar = L.voronoi_length(i);
  const auto dofs = vertex_dofs(i);
  Eigen::Vector3d c;
  Eigen::Matrix<double, 3, 8> J;
  constraint_and_jacobian<8>([lbar](const auto& q) { return darboux_vector(q, lbar); }, x_, dofs, c, J);
  const double EI = L.vertex_mean(i, &SectionStiffness::EI);
  const double GJ = L.vertex_mean(i, &SectionStiffness::GJ);
  const Eigen::Vector3d alpha = Eigen::Vector3d(1.0 / EI, 1.0 / EI, 1.0 / GJ) / (lbar * h * h);
  correct<8>(x_, inverse_mass_, dofs, c, J, alpha, lambda_bt_[i]);
  x_.segment<4>(model_.quaternion_dof(i - 1)).normalize();
  x_.segment<4>(model_.quaternion_dof(i)).normalize();
}

std::array<int, 10> XpbdRod::edge_dofs(int j) const {
  std::array<int, 10> dofs{};
  for (int k = 0; k < 6; ++k) dofs[k] = 3 * j + k;
  for (int k = 0; k < 4; ++k) dofs[6 + k] = model_.quaternion_dof(j) + k;
  return dofs;
}

std::array<int, 8> XpbdRod::vertex_dofs(int i) const {
  std::array<int, 8> dofs{};
  for (int k = 0; k < 4; ++k) {
    dofs[k] = model_.quaternion_dof(i - 1) + k;
    dofs[4 + k] = model_.quaternion_dof(i) + k;
  }
  return dofs;
}

void XpbdRod::step(double h, const VectorXd& force) {
  const VectorXd previous = x_;
  x_ += h * v_ + h * h * inverse_mass_.cwiseProduct(force);
  for (int j = 0; j < model_.layout().num_edges(); ++j) {
    x_.segment<4>(model_.quaternion_dof(j)).normalize();
  }
  const RodLayout& L = model_.layout();
  for (auto& l : lambda_ss_) l.setZero();  // XPBD: the multipliers start at zero each step
  for (auto& l : lambda_bt_) l.setZero();
  for (int it = 0; it < options_.iterations; ++it) {
    for (int j = 0; j < L.num_edges(); ++j) {
      if (!L.ghost[j]) project_stretch_shear(j, h);
    }
    for (int i = 1; i + 1 < L.num_nodes(); ++i) {
      if (L.voronoi_length(i) > 0.0) project_bend_twist(i, h);
    }
  }
  v_ = (1.0 - options_.damping) * (x_ - previous) / h;
}

int XpbdRod::relax(double h, const VectorXd& force, double tolerance, int max_steps) {
  const double L = model_.layout().total_length();
  const int np = 3 * model_.num_nodes();
  for (int s = 1; s <= max_steps; ++s) {
    const VectorXd before = x_.head(np);
    step(h, force);
    if ((x_.head(np) - before).cwiseAbs().maxCoeff() <= tolerance * L) return s;
  }
  return max_steps;
}

}  // namespace vessel::msm::rods
