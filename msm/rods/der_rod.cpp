#include "msm/rods/der_rod.hpp"

#include <array>
#include <cmath>

#include "msm/rods/element_assembly.hpp"
#include "msm/rods/vec3.hpp"

namespace vessel::msm::rods {

namespace {

struct VertexData {
  double bend = 0.0;   ///< EI/(2 l̄)
  double twist = 0.0;  ///< GJ/(2 l̄)
  Eigen::Vector3d t0, u0, t1, u1;  ///< stored reference tangents and directors of the two edges
};

template <class T>
V3<T> transport(const V3<T>& u, const V3<T>& a, const V3<T>& b) {
  const V3<T> axis = cross(a, b);
  const T c = dot(a, b);
  return c * u + cross(axis, u) + (dot(axis, u) / (1.0 + c)) * axis;
}

/// Bending and twisting energy at one interior vertex: x_{i−1}, x_i, x_{i+1}, θ_{i−1}, θ_i.
template <class T>
T vertex_energy(const std::array<T, 11>& q, const VertexData& d) {
  using std::atan2;
  const V3<T> x0(q[0], q[1], q[2]), x1(q[3], q[4], q[5]), x2(q[6], q[7], q[8]);
  const V3<T> e0 = x1 - x0, e1 = x2 - x1;
  const T n0 = norm(e0), n1 = norm(e1);
  const V3<T> kb = (2.0 / (n0 * n1 + dot(e0, e1))) * cross(e0, e1);
  const T bend = d.bend * dot(kb, kb);
  const V3<T> t0 = (1.0 / n0) * e0, t1 = (1.0 / n1) * e1;
  const V3<T> u0 = transport(lift<T>(d.u0), lift<T>(d.t0), t0);
  const V3<T> u1 = transport(lift<T>(d.u1), lift<T>(d.t1), t1);
  const V3<T> v = transport(u0, t0, t1);
  const T reference_twist = atan2(dot(cross(v, u1), t1), dot(v, u1));
  const T m = q[10] - q[9] + reference_twist;
  return bend + d.twist * m * m;
}

/// ½ EA l (|e|/l − 1)² of one edge: x_j, x_{j+1}.
template <class T>
T stretch_energy(const std::array<T, 6>& q, double EA, double l) {
  const V3<T> e = V3<T>(q[3], q[4], q[5]) - V3<T>(q[0], q[1], q[2]);
  const T strain = norm(e) / l - 1.0;
  return 0.5 * EA * l * strain * strain;
}

}  // namespace

Eigen::Vector3d parallel_transport(const Eigen::Vector3d& u, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b) {
  const V3<double> r = transport(V3<double>(u), V3<double>(a), V3<double>(b));
  return {r.x, r.y, r.z};
}

DerRod::DerRod(RodLayout layout) : Rod(std::move(layout)) {
  for (int j = 0; j < layout_.num_edges(); ++j) {
    ref_t_.push_back((layout_.rest[j + 1] - layout_.rest[j]).normalized());
    ref_u_.push_back(layout_.normal);
  }
}

int DerRod::num_dofs() const { return 3 * num_nodes() + layout_.num_edges(); }

VectorXd DerRod::rest_state() const {
  VectorXd x = VectorXd::Zero(num_dofs());
  for (int i = 0; i < num_nodes(); ++i) x.segment<3>(3 * i) = layout_.rest[i];
  return x;
}

std::vector<char> DerRod::clamp_fixed() const {
  std::vector<char> fixed(num_dofs(), 0);
  const auto fix_node = [&](int i) {
    for (int k = 0; k < 3; ++k) fixed[3 * i + k] = 1;
  };
  fix_node(0);
  fix_node(layout_.first_node);
  fixed[twist_dof(0)] = 1;
  if (layout_.clamp_end) {
    fix_node(layout_.tip_node);
    fix_node(layout_.tip_node + 1);
    fixed[twist_dof(layout_.num_edges() - 1)] = 1;
  }
  return fixed;
}

VectorXd DerRod::lumped_mass() const {
  VectorXd m = VectorXd::Zero(num_dofs());
  for (int i = 0; i < num_nodes(); ++i) m.segment<3>(3 * i).setConstant(layout_.node_mass(i));
  for (int j = 0; j < layout_.num_edges(); ++j) {
    m[twist_dof(j)] = layout_.ghost[j] ? 0.0 : layout_.section[j].rhoJ * layout_.length[j];
  }
  return m;
}

void DerRod::update_reference(const VectorXd& x) {
  for (int j = 0; j < layout_.num_edges(); ++j) {
    const Eigen::Vector3d t = (x.segment<3>(3 * (j + 1)) - x.segment<3>(3 * j)).normalized();
    Eigen::Vector3d u = parallel_transport(ref_u_[j], ref_t_[j], t);
    ref_u_[j] = (u - u.dot(t) * t).normalized();
    ref_t_[j] = t;
  }
}

namespace {

/// Calls visit(dofs, data) for every vertex with material on at least one side, and
/// visit_edge(dofs, EA, l) for every material edge.
template <class Vertex, class Edge>
void for_each_element(const RodLayout& layout, const std::vector<Eigen::Vector3d>& ref_t,
                      const std::vector<Eigen::Vector3d>& ref_u, Vertex&& visit, Edge&& visit_edge) {
  const int n = layout.num_nodes();
  for (int i = 1; i + 1 < n; ++i) {
    const double lbar = layout.voronoi_length(i);
    if (lbar <= 0.0) continue;
    VertexData d;
    d.bend = layout.vertex_mean(i, &SectionStiffness::EI) / (2.0 * lbar);
    d.twist = layout.vertex_mean(i, &SectionStiffness::GJ) / (2.0 * lbar);
    d.t0 = ref_t[i - 1];
    d.u0 = ref_u[i - 1];
    d.t1 = ref_t[i];
    d.u1 = ref_u[i];
    std::array<int, 11> dofs{};
    for (int k = 0; k < 9; ++k) dofs[k] = 3 * (i - 1) + k;
    dofs[9] = 3 * n + i - 1;
    dofs[10] = 3 * n + i;
    visit(dofs, d);
  }
  for (int j = 0; j < layout.num_edges(); ++j) {
    if (layout.ghost[j]) continue;
    std::array<int, 6> dofs{};
    for (int k = 0; k < 6; ++k) dofs[k] = 3 * j + k;
    visit_edge(dofs, layout.section[j].EA, layout.length[j]);
  }
}

}  // namespace

double DerRod::energy(const VectorXd& x) const {
  double e = 0.0;
  for_each_element(
      layout_, ref_t_, ref_u_,
      [&](const std::array<int, 11>& dofs, const VertexData& d) {
        e += vertex_energy(double_inputs<11>(x, dofs), d);
      },
      [&](const std::array<int, 6>& dofs, double EA, double l) {
        e += stretch_energy(double_inputs<6>(x, dofs), EA, l);
      });
  return e;
}

void DerRod::gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs());
  for_each_element(
      layout_, ref_t_, ref_u_,
      [&](const std::array<int, 11>& dofs, const VertexData& d) {
        scatter_gradient<11, false>(vertex_energy(jet_inputs<11, false>(x, dofs), d), dofs, g);
      },
      [&](const std::array<int, 6>& dofs, double EA, double l) {
        scatter_gradient<6, false>(stretch_energy(jet_inputs<6, false>(x, dofs), EA, l), dofs, g);
      });
}

void DerRod::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  std::vector<Eigen::Triplet<double>> triplets;
  for_each_element(
      layout_, ref_t_, ref_u_,
      [&](const std::array<int, 11>& dofs, const VertexData& d) {
        scatter_hessian<11>(vertex_energy(jet_inputs<11>(x, dofs), d), dofs, project_psd, triplets);
      },
      [&](const std::array<int, 6>& dofs, double EA, double l) {
        scatter_hessian<6>(stretch_energy(jet_inputs<6>(x, dofs), EA, l), dofs, project_psd,
                           triplets);
      });
  H.resize(num_dofs(), num_dofs());
  H.setFromTriplets(triplets.begin(), triplets.end());
}

}  // namespace vessel::msm::rods
