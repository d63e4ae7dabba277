#include "msm/rods/corde_rod.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include "msm/rods/cosserat_terms.hpp"
#include "msm/rods/element_assembly.hpp"
#include "msm/form/form_sum.hpp"
#include "msm/rods/rod_loads.hpp"
#include "msm/rods/vec3.hpp"

namespace vessel::msm::rods {

namespace {

/// Bending and torsion at a vertex: q_a (4), q_b (4).
template <class T>
T darboux_energy(const std::array<T, 8>& q, double lbar, double EI, double GJ, DarbouxMeasure m) {
  const V3<T> omega =
      m == DarbouxMeasure::quaternion ? darboux_vector(q, lbar) : rotation_darboux_vector(q, lbar);
  return 0.5 * lbar * (EI * (omega.x * omega.x + omega.y * omega.y) + GJ * omega.z * omega.z);
}

/// (κ/2) l |Γ|²: P0 (3), P1 (3), q (4).
template <class T>
T alignment_energy(const std::array<T, 10>& q, double kappa, double l) {
  const V3<T> d = stretch_shear_strain(q, l);
  return 0.5 * kappa * l * dot(d, d);
}

template <class T>
T stretch_constraint(const std::array<T, 6>& q, double l) {
  const V3<T> e = V3<T>(q[3], q[4], q[5]) - V3<T>(q[0], q[1], q[2]);
  return dot(e, e) - l * l;
}

template <class T>
T unit_constraint(const std::array<T, 4>& q) {
  return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0;
}

template <int N>
std::array<int, N> consecutive(int first) {
  std::array<int, N> d{};
  for (int k = 0; k < N; ++k) d[k] = first + k;
  return d;
}

}  // namespace

CordeRod::CordeRod(RodLayout layout, double alignment, bool inextensible, DarbouxMeasure measure)
    : Rod(std::move(layout)), inextensible_(inextensible), measure_(measure) {
  // GJ = G·2I = G·A d²/8 → G·A = 8 GJ/d², the first material edge's d² = 16 I/A = 16 EI/EA.
  const SectionStiffness& s = layout_.section[1];
  const double d2 = 16.0 * s.EI / s.EA;
  kappa_ = alignment > 0.0 ? alignment : 0.9 * 8.0 * s.GJ / d2;
  const Eigen::Vector3d t = (layout_.rest[1] - layout_.rest[0]).normalized();
  Eigen::Matrix3d R;
  R.col(0) = layout_.normal;
  R.col(1) = t.cross(layout_.normal);
  R.col(2) = t;
  frame0_ = Eigen::Quaterniond(R);
}

void CordeRod::normalise_quaternions(VectorXd& x) const {
  for (int j = 0; j < layout_.num_edges(); ++j) x.segment<4>(quaternion_dof(j)).normalize();
}

int CordeRod::num_dofs() const { return 3 * num_nodes() + 4 * layout_.num_edges(); }

VectorXd CordeRod::rest_state() const {
  VectorXd x(num_dofs());
  for (int i = 0; i < num_nodes(); ++i) x.segment<3>(3 * i) = layout_.rest[i];
  for (int j = 0; j < layout_.num_edges(); ++j) {
    x.segment<4>(quaternion_dof(j)) << frame0_.w(), frame0_.x(), frame0_.y(), frame0_.z();
  }
  return x;
}

std::vector<char> CordeRod::clamp_fixed() const {
  std::vector<char> fixed(num_dofs(), 0);
  const auto fix = [&](int first, int count) {
    for (int k = 0; k < count; ++k) fixed[first + k] = 1;
  };
  fix(0, 6);  // ghost node and clamp node
  fix(quaternion_dof(0), 4);
  if (layout_.clamp_end) {
    fix(3 * layout_.tip_node, 6);
    fix(quaternion_dof(layout_.num_edges() - 1), 4);
  }
  return fixed;
}

VectorXd CordeRod::lumped_mass() const {
  VectorXd m = VectorXd::Zero(num_dofs());
  for (int i = 0; i < num_nodes(); ++i) m.segment<3>(3 * i).setConstant(layout_.node_mass(i));
  for (int j = 0; j < layout_.num_edges(); ++j) {
    if (layout_.ghost[j]) continue;
    // ½ω·Iω with ω = 2 Im(q̄ q̇): 4ρI l per component for an isotropic section (I = J/2).
    m.segment<4>(quaternion_dof(j)).setConstant(4.0 * 0.5 * layout_.section[j].rhoJ * layout_.length[j]);
  }
  return m;
}

namespace {

/// Visits the Darboux vertices (8 quaternion dofs) and the alignment edges (10 dofs).
template <class Vertex, class Edge>
void for_each_energy(const CordeRod& rod, Vertex&& vertex, Edge&& edge) {
  const RodLayout& L = rod.layout();
  for (int i = 1; i + 1 < L.num_nodes(); ++i) {
    const double lbar = L.voronoi_length(i);
    if (lbar <= 0.0) continue;
    std::array<int, 8> dofs{};
    for (int k = 0; k < 4; ++k) {
      dofs[k] = rod.quaternion_dof(i - 1) + k;
      dofs[4 + k] = rod.quaternion_dof(i) + k;
    }
    vertex(dofs, lbar, L.vertex_mean(i, &SectionStiffness::EI), L.vertex_mean(i, &SectionStiffness::GJ));
  }
  for (int j = 0; j < L.num_edges(); ++j) {
    if (L.ghost[j]) continue;
    std::array<int, 10> dofs{};
    for (int k = 0; k < 6; ++k) dofs[k] = 3 * j + k;
    for (int k = 0; k < 4; ++k) dofs[6 + k] = rod.quaternion_dof(j) + k;
    edge(dofs, L.length[j]);
  }
}

}  // namespace

double CordeRod::energy(const VectorXd& x) const {
  double e = 0.0;
  for_each_energy(
      *this,
      [&](const std::array<int, 8>& d, double lbar, double EI, double GJ) {
        e += darboux_energy(double_inputs<8>(x, d), lbar, EI, GJ, measure_);
      },
      [&](const std::array<int, 10>& d, double l) {
        e += alignment_energy(double_inputs<10>(x, d), kappa_, l);
      });
  return e;
}

void CordeRod::gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs());
  for_each_energy(
      *this,
      [&](const std::array<int, 8>& d, double lbar, double EI, double GJ) {
        scatter_gradient<8, false>(darboux_energy(jet_inputs<8, false>(x, d), lbar, EI, GJ, measure_), d, g);
      },
      [&](const std::array<int, 10>& d, double l) {
        scatter_gradient<10, false>(alignment_energy(jet_inputs<10, false>(x, d), kappa_, l), d, g);
      });
}

void CordeRod::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  std::vector<Eigen::Triplet<double>> t;
  for_each_energy(
      *this,
      [&](const std::array<int, 8>& d, double lbar, double EI, double GJ) {
        scatter_hessian<8>(darboux_energy(jet_inputs<8>(x, d), lbar, EI, GJ, measure_), d, project_psd, t);
      },
      [&](const std::array<int, 10>& d, double l) {
        scatter_hessian<10>(alignment_energy(jet_inputs<10>(x, d), kappa_, l), d, project_psd, t);
      });
  H.resize(num_dofs(), num_dofs());
  H.setFromTriplets(t.begin(), t.end());
}

int CordeRod::num_constraints() const {
  int material = 0;
  for (char g : layout_.ghost) material += g ? 0 : 1;
  return (inextensible_ ? 2 : 1) * material;
}

namespace {

/// Visits each material edge's constraints: (row, stretch dofs, rest length) if inextensible,
/// then (next row, q dofs).
template <class Stretch, class Unit>
void for_each_constraint(const CordeRod& rod, Stretch&& stretch, Unit&& unit) {
  int row = 0;
  for (int j = 0; j < rod.layout().num_edges(); ++j) {
    if (rod.layout().ghost[j]) continue;
    if (rod.inextensible()) stretch(row++, consecutive<6>(3 * j), rod.layout().length[j]);
    unit(row++, consecutive<4>(rod.quaternion_dof(j)));
  }
}

}  // namespace

void CordeRod::evaluate(const VectorXd& x, VectorXd& c) const {
  c.resize(num_constraints());
  for_each_constraint(
      *this,
      [&](int r, const std::array<int, 6>& d, double l) {
        c[r] = stretch_constraint(double_inputs<6>(x, d), l);
      },
      [&](int r, const std::array<int, 4>& d) { c[r] = unit_constraint(double_inputs<4>(x, d)); });
}

void CordeRod::jacobian(const VectorXd& x, SparseMatrix& J) const {
  std::vector<Eigen::Triplet<double>> t;
  for_each_constraint(
      *this,
      [&](int r, const std::array<int, 6>& d, double l) {
        const auto c = stretch_constraint(jet_inputs<6>(x, d), l);
        for (int a = 0; a < 6; ++a) t.emplace_back(r, d[a], c.g[a]);
      },
      [&](int r, const std::array<int, 4>& d) {
        const auto c = unit_constraint(jet_inputs<4>(x, d));
        for (int a = 0; a < 4; ++a) t.emplace_back(r, d[a], c.g[a]);
      });
  J.resize(num_constraints(), num_dofs());
  J.setFromTriplets(t.begin(), t.end());
}

void CordeRod::weighted_hessian(const VectorXd& x, const VectorXd& lambda, SparseMatrix& H) const {
  std::vector<Eigen::Triplet<double>> t;
  for_each_constraint(
      *this,
      [&](int r, const std::array<int, 6>& d, double l) {
        scatter_hessian<6>(lambda[r] * stretch_constraint(jet_inputs<6>(x, d), l), d, false, t);
      },
      [&](int r, const std::array<int, 4>& d) {
        scatter_hessian<4>(lambda[r] * unit_constraint(jet_inputs<4>(x, d)), d, false, t);
      });
  H.resize(num_dofs(), num_dofs());
  H.setFromTriplets(t.begin(), t.end());
}

}  // namespace vessel::msm::rods
