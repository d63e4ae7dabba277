#include "msm/rods/rigid_wall.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <stdexcept>
#include <string>

#include "msm/rods/jet.hpp"
#include "msm/rods/vec3.hpp"

namespace vessel::msm::rods {

namespace {

template <class T>
T tube_gap(const V3<T>& p, const Eigen::Vector3d& origin, const Eigen::Vector3d& axis, double offset) {
  const V3<T> q = p - lift<T>(origin);
  const V3<T> r = q - dot(q, lift<T>(axis)) * lift<T>(axis);
  return offset - norm(r);
}

template <class T>
T torus_gap(const V3<T>& p, const Eigen::Vector3d& centre, const Eigen::Vector3d& normal,
            double radius, double offset) {
  using std::sqrt;
  const V3<T> q = p - lift<T>(centre);
  const T h = dot(q, lift<T>(normal));
  const V3<T> inplane = q - h * lift<T>(normal);
  const T rho = norm(inplane);
  const T dr = rho - radius;
  return offset - sqrt(dr * dr + h * h);
}

/// Value, gradient and Hessian of f at p by Jet<3>.
template <class F>
double evaluate_gap(const F& f, const Eigen::Vector3d& p, Eigen::Vector3d* gradient,
                    Eigen::Matrix3d* hessian) {
  if (!gradient && !hessian) return f(V3<double>(p));
  const Jet<3> g = f(V3<Jet<3>>(Jet<3>::variable(p.x(), 0), Jet<3>::variable(p.y(), 1),
                                Jet<3>::variable(p.z(), 2)));
  if (gradient) *gradient = g.g;
  if (hessian) *hessian = g.h;
  return g.v;
}

}  // namespace

StraightTube::StraightTube(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis, double offset)
    : origin_(origin), axis_(axis.normalized()), offset_(offset) {}

double StraightTube::gap(const Eigen::Vector3d& p, Eigen::Vector3d* gradient,
                         Eigen::Matrix3d* hessian) const {
  return evaluate_gap([&](const auto& y) { return tube_gap(y, origin_, axis_, offset_); }, p,
                      gradient, hessian);
}

TorusBend::TorusBend(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal,
                     double bend_radius, double offset)
    : centre_(centre), normal_(normal.normalized()), radius_(bend_radius), offset_(offset) {}

double TorusBend::gap(const Eigen::Vector3d& p, Eigen::Vector3d* gradient,
                      Eigen::Matrix3d* hessian) const {
  return evaluate_gap(
      [&](const auto& y) { return torus_gap(y, centre_, normal_, radius_, offset_); }, p, gradient,
      hessian);
}

int ActiveContacts::num_constraints() const {
  return base_rows() + static_cast<int>(nodes.size());
}

void ActiveContacts::evaluate(const VectorXd& x, VectorXd& c) const {
  c.resize(num_constraints());
  if (base_) {
    VectorXd cb;
    base_->evaluate(x, cb);
    c.head(base_rows()) = cb;
  }
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    c[base_rows() + k] = lumen_.gap(x.segment<3>(3 * nodes[k]), nullptr, nullptr);
  }
}

void ActiveContacts::jacobian(const VectorXd& x, SparseMatrix& J) const {
  std::vector<Eigen::Triplet<double>> t;
  if (base_) {
    SparseMatrix Jb;
    base_->jacobian(x, Jb);
    for (int k = 0; k < Jb.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(Jb, k); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    Eigen::Vector3d g;
    lumen_.gap(x.segment<3>(3 * nodes[k]), &g, nullptr);
    for (int a = 0; a < 3; ++a) t.emplace_back(base_rows() + k, 3 * nodes[k] + a, g[a]);
  }
  J.resize(num_constraints(), num_dofs_);
  J.setFromTriplets(t.begin(), t.end());
}

void ActiveContacts::weighted_hessian(const VectorXd& x, const VectorXd& lambda,
                                      SparseMatrix& H) const {
  std::vector<Eigen::Triplet<double>> t;
  if (base_) {
    SparseMatrix Hb;
    base_->weighted_hessian(x, lambda.head(base_rows()), Hb);
    for (int k = 0; k < Hb.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(Hb, k); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    Eigen::Matrix3d h;
    lumen_.gap(x.segment<3>(3 * nodes[k]), nullptr, &h);
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        t.emplace_back(3 * nodes[k] + a, 3 * nodes[k] + b, lambda[base_rows() + k] * h(a, b));
      }
    }
  }
  H.resize(num_dofs_, num_dofs_);
  H.setFromTriplets(t.begin(), t.end());
}

ContactSolution solve_wall_contact(const Form& rod, const EqualityConstraints* rod_constraints,
                                   const std::vector<char>& fixed, const VectorXd& start,
                                   const RigidLumen& lumen, int first_node, int last_node,
                                   const ConstrainedOptions& options, int max_changes,
                                   const std::function<void(VectorXd&)>& project,
                                   const std::vector<int>& initial_nodes) {
  ActiveContacts contacts(lumen, rod_constraints, rod.num_dofs());
  contacts.nodes = initial_nodes;
  ConstrainedProblem p;
  p.form = &rod;
  p.constraints = &contacts;
  p.rest = start;
  p.external_force = VectorXd::Zero(start.size());
  p.fixed = fixed;
  p.project = project;
  ContactSolution s;
  VectorXd x = start;
  VectorXd lambda = VectorXd::Zero(contacts.num_constraints());
  for (int change = 0; change <= max_changes; ++change) {
    const ConstrainedResult r = solve_constrained(p, x, lambda, options);
    x = r.x;
    lambda = r.lambda;
    // L = Π + Σ λ g: the wall's force on node k is −λ_k ∇g; it pushes inwards iff λ_k ≤ 0.
    int pulling = -1;
    double most_pull = 0.0;
    for (std::size_t k = 0; k < contacts.nodes.size(); ++k) {
      const double l = lambda[contacts.base_rows() + k];
      if (l > most_pull) {
        most_pull = l;
        pulling = static_cast<int>(k);
      }
    }
    if (pulling >= 0) {
      contacts.nodes.erase(contacts.nodes.begin() + pulling);
      lambda = VectorXd(lambda.head(contacts.base_rows() + pulling)).eval();
      VectorXd rest_l = r.lambda.tail(r.lambda.size() - contacts.base_rows() - pulling - 1);
      lambda.conservativeResize(contacts.num_constraints());
      lambda.tail(rest_l.size()) = rest_l;
      ++s.active_set_changes;
      continue;
    }
    int deepest = -1;
    double min_gap = 0.0;
    for (int i = first_node; i <= last_node; ++i) {
      if (std::find(contacts.nodes.begin(), contacts.nodes.end(), i) != contacts.nodes.end()) continue;
      const double g = lumen.gap(x.segment<3>(3 * i), nullptr, nullptr);
      if (g < min_gap) {
        min_gap = g;
        deepest = i;
      }
    }
    if (deepest < 0) {
      s.x = x;
      s.nodes = contacts.nodes;
      s.rod_multipliers = lambda.head(contacts.base_rows());
      for (std::size_t k = 0; k < contacts.nodes.size(); ++k) {
        Eigen::Vector3d g;
        lumen.gap(x.segment<3>(3 * contacts.nodes[k]), &g, nullptr);
        s.forces.push_back(-lambda[contacts.base_rows() + k] * g.norm());
      }
      s.min_gap = std::numeric_limits<double>::infinity();
      for (int i = first_node; i <= last_node; ++i) {
        s.min_gap = std::min(s.min_gap, lumen.gap(x.segment<3>(3 * i), nullptr, nullptr));
      }
      return s;
    }
    contacts.nodes.push_back(deepest);
    lambda.conservativeResize(contacts.num_constraints());
    lambda[lambda.size() - 1] = 0.0;
    ++s.active_set_changes;
  }
  throw std::runtime_error("solve_wall_contact: the active set did not settle in " +
                           std::to_string(max_changes) + " changes");
}

}  // namespace vessel::msm::rods
