#include "msm/terms/bending_term.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "meshes/foundation/errors.hpp"
#include "msm/terms/four_node_blocks.hpp"

namespace vessel::msm {

namespace {

using Mat3 = Eigen::Matrix3d;
using Mat3x12 = Eigen::Matrix<double, 3, 12>;
using Row12 = Eigen::Matrix<double, 1, 12>;

/// [a]×: the matrix of a × ·.
Mat3 cross_matrix(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

/// ∂(x_j − x0)/∂(x0, x1, x2, x3): −I in x0's columns, I in x_j's.
Mat3x12 difference_jacobian(int j) {
  Mat3x12 J = Mat3x12::Zero();
  J.block<3, 3>(0, 0) = -Mat3::Identity();
  J.block<3, 3>(0, 3 * j) = Mat3::Identity();
  return J;
}

/// The pieces of θ's gradient (header): e, its length, both normals, G = ‖e‖·N/‖N‖² per triangle
/// (∂θ/∂x2 = −G_A, ∂θ/∂x3 = −G_B) and where x2, x3 project on the edge (α).
struct HingeGeometry {
  Vec3 e, a, b, NA, NB, GA, GB;
  double L = 0.0, alpha2 = 0.0, alpha3 = 0.0;
  explicit HingeGeometry(const std::array<Vec3, 4>& x)
      : e(x[1] - x[0]), a(x[2] - x[0]), b(x[3] - x[0]) {
    NA = e.cross(a);
    NB = b.cross(e);
    L = e.norm();
    GA = L / NA.squaredNorm() * NA;
    GB = L / NB.squaredNorm() * NB;
    const double L2 = L * L;
    alpha2 = a.dot(e) / L2;
    alpha3 = b.dot(e) / L2;
  }
};

}  // namespace

double plate_bending_rigidity(double E, double thickness, double nu) {
  if (!(E > 0) || !std::isfinite(E)) {
    throw InputError("bending (discrete-shells): expected Young's modulus E > 0 Pa, got " +
                     std::to_string(E));
  }
  if (!(thickness > 0) || !std::isfinite(thickness)) {
    throw InputError("bending (discrete-shells): expected a wall thickness t > 0 m, got " +
                     std::to_string(thickness));
  }
  if (!(nu >= 0.0 && nu < 1.0)) {
    throw InputError("bending (discrete-shells): expected Poisson's ratio in [0, 1), got " +
                     std::to_string(nu));
  }
  return E * thickness * thickness * thickness / (12.0 * (1.0 - nu * nu));
}

double discrete_shells_hinge_stiffness(double D, double edge_length, double area_sum) {
  // Grinspun et al. 2003: W = k_B·3‖ē‖²/Ā·(θ − θ̄)² with k_B = D/6 (header) = ½·(D‖ē‖²/Ā)(θ − θ̄)².
  return D * edge_length * edge_length / area_sum;
}

double dihedral_angle(const std::array<Vec3, 4>& x) {
  const Vec3 e = x[1] - x[0];
  const Vec3 NA = e.cross(x[2] - x[0]);
  const Vec3 NB = (x[3] - x[0]).cross(e);
  // atan2 of (sin, cos) scaled by ‖N_A‖‖N_B‖ (and ‖e‖ for the sine): the scale cancels.
  return std::atan2(NA.cross(NB).dot(e) / e.norm(), NA.dot(NB));
}

Vec12 dihedral_angle_gradient(const std::array<Vec3, 4>& x) {
  const HingeGeometry h(x);
  Vec12 g;
  g.segment<3>(0) = (1 - h.alpha2) * h.GA + (1 - h.alpha3) * h.GB;
  g.segment<3>(3) = h.alpha2 * h.GA + h.alpha3 * h.GB;
  g.segment<3>(6) = -h.GA;
  g.segment<3>(9) = -h.GB;
  return g;
}

Mat12 dihedral_angle_hessian(const std::array<Vec3, 4>& x) {
  // The chain rule through the gradient's expressions: each piece's 3×12 (or 1×12) Jacobian with
  // respect to (x0, x1, x2, x3).
  const HingeGeometry h(x);
  const Mat3x12 Je = difference_jacobian(1), Ja = difference_jacobian(2),
                Jb = difference_jacobian(3);
  const Vec3 ehat = h.e / h.L;
  const Row12 dL = ehat.transpose() * Je;
  const Mat3x12 dNA = -cross_matrix(h.a) * Je + cross_matrix(h.e) * Ja;  // N_A = e × a
  const Mat3x12 dNB = cross_matrix(h.b) * Je - cross_matrix(h.e) * Jb;   // N_B = b × e
  // G = L·N/‖N‖²: dG = N/‖N‖²·dL + L·(I − 2nnᵀ)/‖N‖²·dN.
  auto dG = [&](const Vec3& N, const Mat3x12& dN) -> Mat3x12 {
    const double n2 = N.squaredNorm();
    const Vec3 n = N / std::sqrt(n2);
    return N / n2 * dL + h.L / n2 * (Mat3::Identity() - 2.0 * n * n.transpose()) * dN;
  };
  const Mat3x12 dGA = dG(h.NA, dNA), dGB = dG(h.NB, dNB);
  // α = (v·e)/L²: dα = (eᵀdv + vᵀde)/L² − 2(v·e)/L⁴·eᵀde.
  const double L2 = h.L * h.L;
  auto dalpha = [&](const Vec3& v, const Mat3x12& Jv) -> Row12 {
    return (h.e.transpose() * Jv + v.transpose() * Je) / L2 -
           2.0 * v.dot(h.e) / (L2 * L2) * h.e.transpose() * Je;
  };
  const Row12 da2 = dalpha(h.a, Ja), da3 = dalpha(h.b, Jb);
  Mat12 H;
  H.block<3, 12>(0, 0) = (1 - h.alpha2) * dGA - h.GA * da2 + (1 - h.alpha3) * dGB - h.GB * da3;
  H.block<3, 12>(3, 0) = h.alpha2 * dGA + h.GA * da2 + h.alpha3 * dGB + h.GB * da3;
  H.block<3, 12>(6, 0) = -dGA;
  H.block<3, 12>(9, 0) = -dGB;
  return H;
}

double hinge_energy(const std::array<Vec3, 4>& x, double rest_angle, double k) {
  const double d = dihedral_angle(x) - rest_angle;
  return 0.5 * k * d * d;
}

Vec12 hinge_gradient(const std::array<Vec3, 4>& x, double rest_angle, double k) {
  return k * (dihedral_angle(x) - rest_angle) * dihedral_angle_gradient(x);
}

Mat12 hinge_hessian(const std::array<Vec3, 4>& x, double rest_angle, double k, bool project_psd) {
  const double d = dihedral_angle(x) - rest_angle;
  const Vec12 g = dihedral_angle_gradient(x);
  Mat12 H = k * g * g.transpose();
  if (d != 0.0) {
    const Mat12 Htheta = dihedral_angle_hessian(x);
    H += (0.5 * k * d) * (Htheta + Htheta.transpose());  // symmetric to the last bit
  }
  if (!project_psd) return H;
  if (d == 0.0 && k >= 0.0) return H;  // k·∇θ∇θᵀ: already PSD
  return psd_projection(H);
}

std::vector<std::array<int, 4>> interior_hinges(const std::vector<Triangle>& triangles) {
  // Per undirected edge: the directed edges (p → q) that run along it and their opposite vertex.
  struct Side {
    int p, q, opposite;
  };
  std::map<std::pair<int, int>, std::vector<Side>> sides;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int p = t[k], q = t[(k + 1) % 3], r = t[(k + 2) % 3];
      sides[{std::min(p, q), std::max(p, q)}].push_back({p, q, r});
    }
  }
  std::vector<std::array<int, 4>> out;
  for (const auto& [edge, s] : sides) {
    if (s.size() != 2) continue;  // boundary or non-manifold edge
    out.push_back({s[0].p, s[0].q, s[0].opposite, s[1].opposite});
  }
  return out;
}

BendingTerm::BendingTerm(const std::vector<Vec3>& nodes, const std::vector<Triangle>& triangles,
                         double bending_rigidity)
    : FourNodeTerm(static_cast<int>(nodes.size())), rigidity_(bending_rigidity) {
  const int num_nodes = static_cast<int>(nodes.size());
  if (!std::isfinite(bending_rigidity) || bending_rigidity < 0.0) {
    throw InputError("bending term: expected a finite bending rigidity D >= 0 N·m, got " +
                     std::to_string(bending_rigidity));
  }
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    for (int v : triangles[f]) {
      if (v < 0 || v >= num_nodes) {
        throw InputError("bending term: triangle " + std::to_string(f) + " refers to node " +
                         std::to_string(v) + ", expected an index below " +
                         std::to_string(num_nodes));
      }
    }
  }
  for (const auto& q : interior_hinges(triangles)) {
    const std::array<Vec3, 4> x{nodes[q[0]], nodes[q[1]], nodes[q[2]], nodes[q[3]]};
    const double A = triangle_area(x[0], x[1], x[2]) + triangle_area(x[0], x[3], x[1]);
    const double L = (x[1] - x[0]).norm();
    if (!(triangle_area(x[0], x[1], x[2]) > 0.0) || !(triangle_area(x[0], x[3], x[1]) > 0.0)) {
      throw InputError("bending term: a triangle on the edge (" + std::to_string(q[0]) + ", " +
                       std::to_string(q[1]) + ") has zero area; expected non-degenerate triangles");
    }
    hinges_.push_back(
        {q, dihedral_angle(x), discrete_shells_hinge_stiffness(bending_rigidity, L, A)});
  }
  std::vector<std::array<int, 4>> elements;
  elements.reserve(hinges_.size());
  for (const Hinge& h : hinges_) elements.push_back(h.nodes);
  set_elements(std::move(elements));
}

double BendingTerm::element_energy(std::size_t k, const std::array<Vec3, 4>& x) const {
  return hinge_energy(x, hinges_[k].rest_angle, hinges_[k].stiffness);
}

Vec12 BendingTerm::element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const {
  return hinge_gradient(x, hinges_[k].rest_angle, hinges_[k].stiffness);
}

Mat12 BendingTerm::element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                   bool project_psd) const {
  return hinge_hessian(x, hinges_[k].rest_angle, hinges_[k].stiffness, project_psd);
}

}  // namespace vessel::msm
