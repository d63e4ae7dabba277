#include "msm/fem/xpbd_fem.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "msm/form/divergence_error.hpp"

namespace vessel::msm {

XpbdFem::XpbdFem(const std::vector<Vec3>& nodes, std::vector<Tet> tets, LameParameters lame,
                 const VectorXd& mass, const std::vector<char>& fixed, XpbdFemOptions options)
    : energy_(nodes, std::move(tets), lame), options_(options) {
  const int n = static_cast<int>(nodes.size());
  if (mass.size() != 3 * n || static_cast<int>(fixed.size()) != 3 * n) {
    throw InputError("XPBD FEM: expected " + std::to_string(3 * n) +
                     " masses and fixed flags (3 per node), got " + std::to_string(mass.size()) +
                     " and " + std::to_string(fixed.size()));
  }
  x_.resize(3 * n);
  for (int i = 0; i < n; ++i) x_.segment<3>(3 * i) = nodes[i];
  rest_ = x_;
  v_.setZero(3 * n);
  inverse_mass_.setZero(3 * n);
  for (int i = 0; i < n; ++i) {
    if (fixed[3 * i] || fixed[3 * i + 1] || fixed[3 * i + 2]) continue;
    for (int d = 0; d < 3; ++d) {
      if (!(mass[3 * i + d] > 0.0)) {
        throw InputError("XPBD FEM: node " + std::to_string(i) +
                         " is free but has no positive mass");
      }
      inverse_mass_[3 * i + d] = 1.0 / mass[3 * i + d];
    }
  }
  for (const TetRestShape& s : energy_.rest_shapes()) {
    compliance_.push_back({1.0 / (lame.mu * s.volume), 1.0 / (lame.lambda * s.volume)});
  }
  lambda_.assign(compliance_.size(), {0.0, 0.0});
  force_lambda_.assign(compliance_.size(), {0.0, 0.0});
  if (options_.carry_multipliers) {
    // The rest shape's own multipliers, −C(X)/α: C_D(I) = √3 ≠ 0, so the deviatoric and
    // hydrostatic constraints hold the rest shape by opposite forces (μV₀ I and −μV₀ I); starting
    // from λ = 0 the first sweeps would collapse the tets towards F = 0.
    Vec12 grad;
    for (std::size_t k = 0; k < compliance_.size(); ++k) {
      for (int c = 0; c < 2; ++c) force_lambda_[k][c] = -evaluate(k, c, grad) / compliance_[k][c];
    }
  }
}

double XpbdFem::evaluate(std::size_t k, int c, Vec12& grad) const {
  const Tet& t = energy_.elements()[k];
  const TetRestShape& s = energy_.rest_shapes()[k];
  const Mat3 F = deformation_gradient({x_.segment<3>(3 * t[0]), x_.segment<3>(3 * t[1]),
                                       x_.segment<3>(3 * t[2]), x_.segment<3>(3 * t[3])},
                                      s);
  if (c == 0) {
    const double r = F.norm();  // C_D = √tr(FᵀF), ∂C_D/∂F = F/C_D
    grad = s.dF_dx.transpose() * vec9(F / r);
    return r;
  }
  grad = s.dF_dx.transpose() * vec9(determinant_gradient(F));
  return F.determinant() - (1.0 + energy_.lame().mu / energy_.lame().lambda);
}

void XpbdFem::set_velocity(const VectorXd& v) {
  if (v.size() != x_.size()) {
    throw InputError("XPBD FEM: expected " + std::to_string(x_.size()) + " velocities, got " +
                     std::to_string(v.size()));
  }
  v_ = v;
  for (Eigen::Index i = 0; i < v_.size(); ++i) {
    if (inverse_mass_[i] == 0.0) v_[i] = 0.0;
  }
}

void XpbdFem::step(double h, const VectorXd& force) {
  ++steps_taken_;
  const double h2 = h * h;
  const auto& tets = energy_.elements();
  const VectorXd start = x_;
  // Prediction with the carried constraint forces; λ starts from them.
  VectorXd f = force;
  Vec12 grad;
  for (std::size_t k = 0; k < tets.size(); ++k) {
    for (int c = 0; c < 2; ++c) {
      lambda_[k][c] = options_.carry_multipliers ? h2 * force_lambda_[k][c] : 0.0;
      if (lambda_[k][c] == 0.0) continue;
      evaluate(k, c, grad);
      for (int a = 0; a < 4; ++a)
        f.segment<3>(3 * tets[k][a]) += force_lambda_[k][c] * grad.segment<3>(3 * a);
    }
  }
  if (!options_.carry_multipliers) f = force;
  x_ += h * v_ + h2 * inverse_mass_.cwiseProduct(f);
  for (int it = 0; it < options_.iterations; ++it) {
    for (std::size_t k = 0; k < tets.size(); ++k) {
      for (int c = 0; c < 2; ++c) {
        const double C = evaluate(k, c, grad);
        const double alpha = compliance_[k][c] / h2;
        double w = 0.0;
        for (int a = 0; a < 4; ++a) {
          w += inverse_mass_[3 * tets[k][a]] * grad.segment<3>(3 * a).squaredNorm();
        }
        const double dl = -(C + alpha * lambda_[k][c]) / (w + alpha);
        lambda_[k][c] += dl;
        for (int a = 0; a < 4; ++a) {
          x_.segment<3>(3 * tets[k][a]) +=
              inverse_mass_[3 * tets[k][a]] * dl * grad.segment<3>(3 * a);
        }
      }
    }
  }
  for (Eigen::Index i = 0; i < x_.size(); ++i) {
    if (!std::isfinite(x_[i])) {
      throw DivergenceError(steps_taken_, static_cast<int>(i / 3), energy_.energy(x_),
                            "XPBD FEM: non-finite position");
    }
  }
  v_ = (1.0 - options_.damping) / h * (x_ - start);
  for (std::size_t k = 0; k < tets.size(); ++k) {
    for (int c = 0; c < 2; ++c) force_lambda_[k][c] = lambda_[k][c] / h2;
  }
}

int XpbdFem::relax(double h, const VectorXd& force, double relative_change, int max_steps) {
  for (int s = 1; s <= max_steps; ++s) {
    const VectorXd before = x_;
    step(h, force);
    double moved = 0.0, displaced = 0.0;
    for (Eigen::Index i = 0; i < x_.size(); i += 3) {
      moved = std::max(moved, (x_.segment<3>(i) - before.segment<3>(i)).norm());
      displaced = std::max(displaced, (x_.segment<3>(i) - rest_.segment<3>(i)).norm());
    }
    if (moved <= relative_change * displaced || moved == 0.0) return s;
  }
  return max_steps;
}

}  // namespace vessel::msm
