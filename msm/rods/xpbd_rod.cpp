#include "msm/rods/xpbd_rod.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <stdexcept>

#include "msm/rods/cosserat_terms.hpp"

namespace vessel::msm::rods {

XpbdRod::XpbdRod(RodLayout layout, double alignment, XpbdOptions options)
    : model_(std::move(layout), alignment, false), options_(options) {
  if (options_.warm_start && options_.solver == XpbdSolver::gauss_seidel) {
    throw std::invalid_argument(
        "XpbdRod: warm-started multipliers need XpbdSolver::direct (with Gauss–Seidel sweeps the "
        "carried multipliers diverge: tests/rods/test_xpbd.cpp)");
  }
  x_ = model_.rest_state();
  v_ = VectorXd::Zero(x_.size());
  const VectorXd m = model_.lumped_mass();
  const auto fixed = model_.clamp_fixed();
  inverse_mass_ = VectorXd::Zero(x_.size());
  for (int i = 0; i < m.size(); ++i)
    inverse_mass_[i] = (fixed[i] || m[i] <= 0.0) ? 0.0 : 1.0 / m[i];
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
  quaternion_mass_.assign(L.num_edges(), 0.0);
  for (int j = 0; j < L.num_edges(); ++j) {
    const double w = inverse_mass_[model_.quaternion_dof(j)];
    quaternion_mass_[j] = w > 0.0 ? 1.0 / w : 0.0;
  }
  build_blocks();
  build_couplings();
  const std::size_t n = blocks_.size();
  lambda_.assign(n, Eigen::Vector3d::Zero());
  force_lambda_.assign(n, Eigen::Vector3d::Zero());
  jacobians_.assign(n, BlockJacobian::Zero());
  residuals_.assign(n, Eigen::Vector3d::Zero());
  // Constraint blocks two by two (6 rows): couplings reach two blocks, so only neighbouring
  // pairs couple, and the system is block tridiagonal.
  const int pairs = (static_cast<int>(n) + 1) / 2;
  system_.resize(pairs);
  rhs_ = VectorXd::Zero(6 * pairs);
  contact_lambda_.assign(L.num_nodes(), 0.0);
  contact_force_lambda_.assign(L.num_nodes(), 0.0);
  previous_ = VectorXd::Zero(x_.size());
  scratch_ = VectorXd::Zero(x_.size());
  quaternion_stiffness_.assign(quaternion_mass_.size(), 0.0);
}

void XpbdRod::build_blocks() {
  const RodLayout& L = model_.layout();
  for (int i = 1; i < L.num_nodes(); ++i) {
    if (i + 1 < L.num_nodes() && L.voronoi_length(i) > 0.0) {  // bend–twist at vertex i
      Block b;
      b.stretch = false;
      b.dofs_used = 8;
      for (int k = 0; k < 4; ++k) {
        b.dofs[k] = model_.quaternion_dof(i - 1) + k;
        b.dofs[4 + k] = model_.quaternion_dof(i) + k;
      }
      b.length = L.voronoi_length(i);
      const double EI = L.vertex_mean(i, &SectionStiffness::EI);
      const double GJ = L.vertex_mean(i, &SectionStiffness::GJ);
      b.compliance = Eigen::Vector3d(1.0 / EI, 1.0 / EI, 1.0 / GJ) / b.length;
      blocks_.push_back(b);
    }
    if (i < L.num_edges() && !L.ghost[i]) {  // stretch–shear of edge i
      Block b;
      for (int k = 0; k < 6; ++k) b.dofs[k] = 3 * i + k;
      for (int k = 0; k < 4; ++k) b.dofs[6 + k] = model_.quaternion_dof(i) + k;
      b.length = L.length[i];
      b.compliance = Eigen::Vector3d::Constant(1.0 / (model_.alignment() * b.length));
      blocks_.push_back(b);
    }
  }
}

void XpbdRod::build_couplings() {
  const int n = static_cast<int>(blocks_.size());
  // Every free dof must be shared by blocks at most two apart in the chain order (the band).
  std::vector<int> first(x_.size(), n), last(x_.size(), -1);
  for (int a = 0; a < n; ++a) {
    for (int k = 0; k < blocks_[a].dofs_used; ++k) {
      const int d = blocks_[a].dofs[k];
      first[d] = std::min(first[d], a);
      last[d] = std::max(last[d], a);
    }
  }
  for (Eigen::Index d = 0; d < x_.size(); ++d) {
    if (inverse_mass_[d] > 0.0 && last[d] - first[d] > 2) {
      throw std::logic_error("XpbdRod: a dof is shared by blocks more than two apart");
    }
  }
  // Runs of consecutive shared columns on one inverse mass (a node's 3, a quaternion's 4).
  const auto runs = [this](const Block& A, const Block& B) {
    std::vector<Shared> out;
    for (int ka = 0; ka < A.dofs_used; ++ka) {
      for (int kb = 0; kb < B.dofs_used; ++kb) {
        const int dof = A.dofs[ka];
        if (dof != B.dofs[kb] || inverse_mass_[dof] <= 0.0) continue;
        if (!out.empty()) {
          Shared& r = out.back();
          if (r.col_a + r.width == ka && r.col_b + r.width == kb && r.width < 4 &&
              inverse_mass_[r.dof] == inverse_mass_[dof] &&
              (dof < 3 * model_.num_nodes()) == (r.dof < 3 * model_.num_nodes())) {
            ++r.width;
            continue;
          }
        }
        out.push_back({ka, kb, 1, dof, dof < 3 * model_.num_nodes()});
      }
    }
    return out;
  };
  couplings_.assign(n, {});
  own_runs_.assign(n, {});
  for (int a = 0; a < n; ++a) {
    own_runs_[a] = runs(blocks_[a], blocks_[a]);
    for (int d = 1; d <= 2 && a + d < n; ++d)
      couplings_[a][d - 1] = runs(blocks_[a], blocks_[a + d]);
  }
}

namespace {

/// A 3 × 3 block of J W Jᵀ summed in scalars and stored entry by entry: an Eigen matrix
/// written by scalar stores and copied with packet loads stalls on store forwarding.
struct Product3 {
  double m[3][3] = {};
  template <class Destination>
  void store_to(Destination&& d) const {
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
#pragma GCC unroll 3
      for (int r = 0; r < 3; ++r) d(r, c) = m[r][c];
    }
  }
};

/// P += w · J_b(:, cb..cb+W) J_a(:, ca..ca+W)ᵀ for W columns, unrolled on the Jacobians'
/// column-major storage; Symmetric (J_b = J_a): the lower triangle, mirrored.
template <int W, bool Symmetric>
inline void add_dense_product(Product3& P, double w, const double* Jb, const double* Ja) {
  // Operands and sums in locals first: stores into P could alias the Jacobians for the compiler.
  double b[3 * W], a[3 * W], v[3][3];
#pragma GCC unroll 12
  for (int k = 0; k < 3 * W; ++k) {
    b[k] = Jb[k];
    a[k] = Symmetric ? Jb[k] : Ja[k];
  }
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
#pragma GCC unroll 3
    for (int r = Symmetric ? c : 0; r < 3; ++r) {
      double sum = 0.0;
#pragma GCC unroll 4
      for (int k = 0; k < W; ++k) sum += b[3 * k + r] * a[3 * k + c];
      v[r][c] = w * sum;
    }
  }
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
#pragma GCC unroll 3
    for (int r = 0; r < 3; ++r) P.m[r][c] += Symmetric && r < c ? v[c][r] : v[r][c];
  }
}

/// P += w · J_b(:, run) J_a(:, run)ᵀ over one run of shared columns (Symmetric: J_b = J_a).
template <bool Symmetric, class J, class Run>
inline void add_run_product(Product3& P, double w, const J& Jb, const J& Ja, const Run& r) {
  if (r.position) {  // columns ±e_k/l: the product is diagonal, row k = the column's component
    for (int t = 0; t < r.width; ++t) {
      const int k = (r.col_a + t) % 3;
      P.m[k][k] += w * Jb(k, r.col_b + t) * Ja(k, r.col_a + t);
    }
    return;
  }
  const double* b = Jb.data() + 3 * r.col_b;
  const double* a = Ja.data() + 3 * r.col_a;
  if (r.width == 4) {
    add_dense_product<4, Symmetric>(P, w, b, a);
  } else {
    for (int k = 0; k < r.width; ++k) {
      for (int c = 0; c < 3; ++c) {
        for (int i = 0; i < 3; ++i) P.m[i][c] += w * b[3 * k + i] * a[3 * k + c];
      }
    }
  }
}

}  // namespace

void XpbdRod::evaluate(const Block& b, Eigen::Vector3d& c, BlockJacobian& J) const {
  // The quaternions live on the unit sphere: their columns are projected onto its tangent
  // space, J_q (I − q qᵀ), so that no correction (and no carried force) goes into |q|, which
  // the renormalisation would undo while λ kept it.
  if (b.stretch) {
    Eigen::Matrix<double, 10, 1> q;
    for (int k = 0; k < 10; ++k) q[k] = x_[b.dofs[k]];
    stretch_shear_with_jacobian<true>(q, b.length, c, J);
  } else {
    Eigen::Matrix<double, 8, 1> q;
    for (int k = 0; k < 8; ++k) q[k] = x_[b.dofs[k]];
    darboux_with_jacobian<true>(q, b.length, c, J);
    J.rightCols<2>().setZero();
  }
}

void XpbdRod::apply(const Block& b, const BlockJacobian& J, const double* dl) {
  for (int k = 0; k < b.dofs_used; ++k) {
    const double jt_dl = J(0, k) * dl[0] + J(1, k) * dl[1] + J(2, k) * dl[2];
    x_[b.dofs[k]] += inverse_mass_[b.dofs[k]] * jt_dl;
  }
}

void XpbdRod::gauss_seidel_sweep(double h) {
  Eigen::Vector3d c;
  BlockJacobian J;
  for (std::size_t a = 0; a < blocks_.size(); ++a) {
    const Block& b = blocks_[a];
    evaluate(b, c, J);
    Eigen::Matrix<double, 10, 1> w;
    for (int k = 0; k < 10; ++k) w[k] = k < b.dofs_used ? inverse_mass_[b.dofs[k]] : 0.0;
    const Eigen::Vector3d alpha = b.compliance / (h * h);
    Eigen::Matrix3d A = J * w.asDiagonal() * J.transpose();
    A.diagonal() += alpha;
    const Eigen::Vector3d dl = A.ldlt().solve(-c - alpha.cwiseProduct(lambda_[a]));
    apply(b, J, dl.data());
    lambda_[a] += dl;
    // renormalise the block's quaternions
    const int q0 = b.stretch ? b.dofs[6] : b.dofs[0];
    x_.segment<4>(q0).normalize();
    if (!b.stretch) x_.segment<4>(b.dofs[4]).normalize();
  }
  project_contacts();
}

void XpbdRod::assemble(int a, double inverse_h2) {
  const int n = static_cast<int>(blocks_.size());
  const int pair = a / 2, offset = 3 * (a % 2);
  if (a == n) {  // an odd count: the last pair's second half is a unit dummy
    system_.diagonal(pair).block<3, 3>(offset, offset) = Eigen::Matrix3d::Identity();
    rhs_.segment<3>(3 * a).setZero();
    return;
  }
  const Block& b = blocks_[a];
  const BlockJacobian& J = jacobians_[a];
  const Eigen::Vector3d alpha = b.compliance * inverse_h2;
  Product3 A;
  for (const Shared& r : own_runs_[a]) add_run_product<true>(A, inverse_mass_[r.dof], J, J, r);
  for (int k = 0; k < 3; ++k) A.m[k][k] += alpha[k];
  A.store_to(system_.diagonal(pair).block<3, 3>(offset, offset));
  for (int d = 1; d <= 2; ++d) {  // rows of block a+d, columns of block a
    const int other = (a + d) / 2, other_offset = 3 * ((a + d) % 2);
    if (other >= system_.size()) break;
    Product3 M;  // a + d = n: the odd count's dummy, zero
    if (a + d < n) {
      for (const Shared& r : couplings_[a][d - 1])
        add_run_product<false>(M, inverse_mass_[r.dof], jacobians_[a + d], J, r);
    }
    if (other == pair) {
      M.store_to(system_.diagonal(pair).block<3, 3>(other_offset, offset));
    } else {  // other == pair + 1: a + d ≤ a + 2 ≤ 2·pair + 3
      M.store_to(system_.sub(pair).block<3, 3>(other_offset, offset));
    }
  }
  for (int k = 0; k < 3; ++k) rhs_[3 * a + k] = -residuals_[a][k] - alpha[k] * lambda_[a][k];
}

void XpbdRod::direct_iteration(double h) {
  // Contacts first, so that a step ends on the direct solve: projected last, they move the
  // contact nodes off the rod's constraints (a stretch–shear residual ~0.2 at the tip edge),
  // which the next step corrects by spinning the light frames, and at h = 0.1 ms (N = 32) the
  // guidewire's insertion never settles (tests/rods/test_rigid_wall.cpp).
  project_contacts();
  const int n = static_cast<int>(blocks_.size());
  const double inverse_h2 = 1.0 / (h * h);
  for (int a = 0; a < n; ++a) evaluate(blocks_[a], residuals_[a], jacobians_[a]);
  // Block row p of J W Jᵀ + α/h² is assembled (every entry the factorisation reads assigned
  // once) just before it is factorised, and each pair's Δλ applied as soon as it is solved:
  // the solver's dependency chains overlap with that work.
  const auto fill = [&](int p) {
    for (int a = 2 * p; a <= std::min(2 * p + 1, n); ++a) assemble(a, inverse_h2);
  };
  const auto done = [&](int p) {
    for (int a = 2 * p; a <= std::min(2 * p + 1, n - 1); ++a) {
      const double* dl = rhs_.data() + 3 * a;
      apply(blocks_[a], jacobians_[a], dl);
      for (int k = 0; k < 3; ++k) lambda_[a][k] += dl[k];
    }
  };
  system_.assemble_factorize_solve(rhs_, fill, done);
  model_.normalise_quaternions(x_);
}

void XpbdRod::project_contacts() {
  if (lumen_ == nullptr) return;
  for (int i = wall_first_; i <= wall_last_; ++i) {
    const double w = inverse_mass_[3 * i];
    if (w <= 0.0) continue;
    Eigen::Vector3d grad;
    const double g = lumen_->gap(x_.segment<3>(3 * i), &grad, nullptr);
    const double lambda = contact_lambda_[i];
    if (g >= 0.0 && lambda <= 0.0) continue;
    // A hard one-sided constraint: Δλ = −g/(w|∇g|²), the total kept ≥ 0 (pushing only).
    const double updated = std::max(lambda - g / (w * grad.squaredNorm()), 0.0);
    x_.segment<3>(3 * i) += w * (updated - lambda) * grad;
    contact_lambda_[i] = updated;
  }
}

void XpbdRod::predict(double h, const VectorXd& force) {
  const int n = static_cast<int>(blocks_.size());
  VectorXd& shift = scratch_;
  shift.setZero();
  if (options_.warm_start) {
    // The carried constraint forces Jᵀλ at the step's start, in the prediction. (J of the last
    // iteration instead, one evaluation fewer, leaves a one-iteration step cycling about the
    // equilibrium at α ≥ 3: measured.)
    for (int a = 0; a < n; ++a) {
      lambda_[a] = h * h * force_lambda_[a];
      Eigen::Vector3d c;
      BlockJacobian J;
      evaluate(blocks_[a], c, J);
      const Block& b = blocks_[a];
      for (int k = 0; k < b.dofs_used; ++k) {
        shift[b.dofs[k]] += inverse_mass_[b.dofs[k]] * J.col(k).dot(lambda_[a]);
      }
    }
    for (int i = wall_first_; lumen_ != nullptr && i <= wall_last_; ++i) {
      contact_lambda_[i] = h * h * contact_force_lambda_[i];
      if (contact_lambda_[i] == 0.0) continue;
      Eigen::Vector3d grad;
      lumen_->gap(x_.segment<3>(3 * i), &grad, nullptr);
      shift.segment<3>(3 * i) += inverse_mass_[3 * i] * contact_lambda_[i] * grad;
    }
  } else {
    for (auto& l : lambda_) l.setZero();
    std::fill(contact_lambda_.begin(), contact_lambda_.end(), 0.0);
  }
  x_ += h * v_ + h * h * inverse_mass_.cwiseProduct(force) + shift;
  model_.normalise_quaternions(x_);
}

void XpbdRod::stabilise_quaternion_masses(double h) {
  // The carried multipliers' force turns with the frames: its geometric stiffness, bounded per
  // quaternion by Σ (2/l̄)|λ| (bend–twist, bilinear in q_a, q_b) and Σ 4|λ| (stretch–shear,
  // quadratic in q), is treated explicitly by the warm start and made the light frames diverge
  // (α = 3, N = 32, h = 10 ms). Its diagonal is added to the frames' mass (Andrews, Teichmann & Kry
  // 2017, "Geometric stiffness for real-time constrained multibody dynamics"). A steady state does
  // not depend on the masses, so statics are unchanged.
  std::vector<double>& k = quaternion_stiffness_;
  std::fill(k.begin(), k.end(), 0.0);
  const int first_q = model_.quaternion_dof(0);
  for (std::size_t a = 0; a < blocks_.size(); ++a) {
    const Block& b = blocks_[a];
    const double lambda = force_lambda_[a].norm();
    if (b.stretch) {
      k[(b.dofs[6] - first_q) / 4] += 4.0 * lambda;
    } else {
      k[(b.dofs[0] - first_q) / 4] += 2.0 / b.length * lambda;
      k[(b.dofs[4] - first_q) / 4] += 2.0 / b.length * lambda;
    }
  }
  for (std::size_t j = 0; j < k.size(); ++j) {
    if (quaternion_mass_[j] <= 0.0) continue;
    inverse_mass_.segment<4>(first_q + 4 * static_cast<int>(j))
        .setConstant(1.0 / (quaternion_mass_[j] + h * h * k[j]));
  }
}

void XpbdRod::step(double h, const VectorXd& force) {
  previous_ = x_;
  if (options_.warm_start) stabilise_quaternion_masses(h);
  predict(h, force);
  for (int it = 0; it < options_.iterations; ++it) {
    if (options_.solver == XpbdSolver::direct) {
      direct_iteration(h);
    } else {
      gauss_seidel_sweep(h);
    }
  }
  // The step's multipliers as forces: the next step's warm start, and the wall's force.
  for (std::size_t a = 0; a < blocks_.size(); ++a) force_lambda_[a] = lambda_[a] / (h * h);
  for (std::size_t i = 0; i < contact_lambda_.size(); ++i) {
    contact_force_lambda_[i] = contact_lambda_[i] / (h * h);
  }
  v_ = (1.0 - options_.damping) * (x_ - previous_) / h;
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

void XpbdRod::set_wall(const RigidLumen* lumen, int first_node, int last_node) {
  lumen_ = lumen;
  wall_first_ = first_node;
  wall_last_ = last_node;
  std::fill(contact_lambda_.begin(), contact_lambda_.end(), 0.0);
  std::fill(contact_force_lambda_.begin(), contact_force_lambda_.end(), 0.0);
}

std::vector<double> XpbdRod::wall_forces() const {
  std::vector<double> f(contact_force_lambda_.size(), 0.0);
  for (int i = wall_first_; lumen_ != nullptr && i <= wall_last_; ++i) {
    if (contact_force_lambda_[i] <= 0.0) continue;
    Eigen::Vector3d grad;
    lumen_->gap(x_.segment<3>(3 * i), &grad, nullptr);
    f[i] = contact_force_lambda_[i] * grad.norm();
  }
  return f;
}

void XpbdRod::set_state(const VectorXd& x) {
  x_ = x;
  model_.normalise_quaternions(x_);
  v_.setZero();
  for (auto& l : force_lambda_) l.setZero();
  std::fill(contact_force_lambda_.begin(), contact_force_lambda_.end(), 0.0);
}

}  // namespace vessel::msm::rods
