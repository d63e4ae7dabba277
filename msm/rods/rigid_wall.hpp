#pragma once
/// Frictionless one-sided contact of a rod's centreline with a rigid lumen: every node must keep
/// its distance to the wall ≥ the wire's radius, written as a gap g(P) ≥ 0 (the lumen radius less
/// the wire's, less the distance from the lumen's centreline). Solved by an active set on KKT
/// Newton: the most penetrating node joins, a node whose multiplier would pull leaves, so the wall
/// never pulls and carries no force at zero gap.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "msm/rods/constrained_newton.hpp"

namespace vessel::msm::rods {

/// A rigid lumen's gap function of a point: g ≥ 0 inside, with its gradient and Hessian.
class RigidLumen {
 public:
  virtual ~RigidLumen() = default;
  /// g, ∇g and ∇²g at p (the second and third may be null).
  virtual double gap(const Eigen::Vector3d& p, Eigen::Vector3d* gradient,
                     Eigen::Matrix3d* hessian) const = 0;
};

/// A straight tube: axis through `origin` along `axis`, centreline offset allowed `offset`
/// (lumen radius − wire radius): g = offset − |p⊥|.
class StraightTube : public RigidLumen {
 public:
  StraightTube(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis, double offset);
  double gap(const Eigen::Vector3d& p, Eigen::Vector3d* gradient,
             Eigen::Matrix3d* hessian) const override;

 private:
  Eigen::Vector3d origin_, axis_;
  double offset_;
};

/// A bend: a torus of centreline radius `bend_radius` about `centre` in the plane normal to
/// `normal`; g = offset − √((ρ − R)² + h²), ρ the in-plane distance from the centre, h the height.
class TorusBend : public RigidLumen {
 public:
  TorusBend(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double bend_radius,
            double offset);
  double gap(const Eigen::Vector3d& p, Eigen::Vector3d* gradient,
             Eigen::Matrix3d* hessian) const override;

 private:
  Eigen::Vector3d centre_, normal_;
  double radius_, offset_;
};

/// Gap constraints g(P_i) = 0 on a set of active nodes (positions are the first dofs of x), stacked
/// below another constraint set's rows (or alone).
class ActiveContacts : public EqualityConstraints {
 public:
  ActiveContacts(const RigidLumen& lumen, const EqualityConstraints* base, int num_dofs)
      : lumen_(lumen), base_(base), num_dofs_(num_dofs) {}
  std::vector<int> nodes;  ///< active nodes
  [[nodiscard]] int base_rows() const { return base_ ? base_->num_constraints() : 0; }
  [[nodiscard]] int num_constraints() const override;
  void evaluate(const VectorXd& x, VectorXd& c) const override;
  void jacobian(const VectorXd& x, SparseMatrix& J) const override;
  void weighted_hessian(const VectorXd& x, const VectorXd& lambda, SparseMatrix& H) const override;

 private:
  const RigidLumen& lumen_;
  const EqualityConstraints* base_;
  int num_dofs_;
};

struct ContactSolution {
  VectorXd x;
  std::vector<int> nodes;      ///< nodes in contact
  std::vector<double> forces;  ///< the wall's normal force on each, N (≥ 0)
  /// The multipliers of the rod's own equality constraints (none without them), in the
  /// Lagrangian Π + λᵀc: the constraint force on the dofs is −J(x)ᵀλ.
  VectorXd rod_multipliers;
  int active_set_changes = 0;
  double min_gap = 0.0;        ///< over all material nodes at the end, m
};

/// Equilibrium of a rod Form (with its own equality constraints, or none) inside a rigid lumen,
/// from `start`, the nodes `first_node`..`last_node` subject to contact. Throws
/// std::runtime_error if the active set does not settle in `max_changes` changes. `project` maps
/// each Newton iterate back onto part of the rod's constraints (CORDE: unit quaternions), or is
/// empty; `initial_nodes` start the active set (e.g. a nearby solution's contacts).
ContactSolution solve_wall_contact(const Form& rod, const EqualityConstraints* rod_constraints,
                                   const std::vector<char>& fixed, const VectorXd& start,
                                   const RigidLumen& lumen, int first_node, int last_node,
                                   const ConstrainedOptions& options, int max_changes = 40,
                                   const std::function<void(VectorXd&)>& project = {},
                                   const std::vector<int>& initial_nodes = {});

}  // namespace vessel::msm::rods
