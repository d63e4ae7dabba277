#pragma once
/// Frictionless one-sided contact on a condensed compliance: the contact candidates' forces λ
/// (each along its own direction, pushing the wall) and gaps g = g0 + W λ, where W (m/N, symmetric
/// positive definite) is the wall's displacement along each candidate's direction per unit force
/// at each candidate: the compliance a linear wall condenses on its candidates (SOFA's constraint
/// correction). Signorini's conditions: g ≥ 0, λ ≥ 0, λ·g = 0.
#include <Eigen/Dense>
#include <vector>

namespace vessel::contact {

struct SignoriniSolution {
  Eigen::VectorXd force;     ///< λ per candidate, N (≥ 0)
  Eigen::VectorXd gap;       ///< g = g0 + W λ per candidate, m (≥ −tolerance)
  std::vector<char> active;  ///< λ > 0
  int iterations = 0;        ///< active-set changes
};

/// The Signorini conditions as the convex quadratic programme min ½λᵀWλ + g0ᵀλ over λ ≥ 0, by the
/// Lawson–Hanson active-set method (Lawson & Hanson 1974, ch. 23, with AᵀA = W and Aᵀb = −g0):
/// finite, and exact up to round-off on the active set. `gap_tolerance` (m): a candidate whose
/// gap is above −gap_tolerance is not pressed. std::invalid_argument on mismatched sizes.
SignoriniSolution solve_signorini(const Eigen::MatrixXd& W, const Eigen::VectorXd& g0,
                                  double gap_tolerance);

/// A rigid indenter moved by δ along the candidates' directions: gaps g0 = h − δ (h, m: each
/// candidate's gap to the indenter at δ = 0), pressed until the forces sum to `total_force` (N).
struct RigidPress {
  double approach = 0.0;  ///< δ, m
  SignoriniSolution contact;
};

/// Finds δ with Σλ(δ) = total_force: Σλ is piecewise linear, increasing and convex in δ (each
/// candidate that comes into contact stiffens it), so Newton's method on the active set's line
/// reaches it from above in a few active sets. Relative force tolerance 1e-12.
RigidPress press_rigid_indenter(const Eigen::MatrixXd& W, const Eigen::VectorXd& h,
                                double total_force, double gap_tolerance);

}  // namespace vessel::contact
