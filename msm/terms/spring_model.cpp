#include "msm/terms/spring_model.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"

namespace vessel::msm {

namespace {
inline Vec3 node(const VectorXd& x, int i) { return x.segment<3>(3 * i); }

void add_block(std::vector<Eigen::Triplet<double>>& t, const Spring& s, const Mat6& H) {
  const int idx[2] = {s.a, s.b};
  for (int p = 0; p < 2; ++p) {
    for (int q = 0; q < 2; ++q) {
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          t.emplace_back(3 * idx[p] + i, 3 * idx[q] + j, H(3 * p + i, 3 * q + j));
        }
      }
    }
  }
}
}  // namespace

SpringModel::SpringModel(const SpringNetwork& network, double point_damping)
    : num_nodes_(static_cast<int>(network.nodes.size())),
      springs_(network.springs),
      point_damping_(point_damping),
      rest_nodes_(network.nodes),
      kernel_(network.springs, static_cast<int>(network.nodes.size()), spring_kernel_threads(),
            network.nodes) {
  if (!(point_damping >= 0)) {
    throw InputError("point_damping k_v: expected a value ≥ 0 N·s/m, got " +
                     std::to_string(point_damping));
  }
  for (std::size_t s = 0; s < springs_.size(); ++s) {
    if (springs_[s].damping != 0.0) damped_.push_back(static_cast<int>(s));
  }
  // The pattern: the full diagonal plus the four 3×3 blocks of every spring.
  const int n = num_dofs();
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(springs_.size() * 36 + static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, 0.0);
  for (const Spring& s : springs_) add_block(t, s, Mat6::Zero());
  pattern_.resize(n, n);
  pattern_.setFromTriplets(t.begin(), t.end());
  pattern_.makeCompressed();
  auto slot = [&](int row, int col) {
    const int* inner = pattern_.innerIndexPtr();
    const int begin = pattern_.outerIndexPtr()[col];
    const int end = pattern_.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(inner + begin, inner + end, row) - inner);
  };
  diagonal_slots_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) diagonal_slots_[i] = slot(i, i);
  slots_.reserve(springs_.size() * 36);
  for (const Spring& s : springs_) {
    const int idx[2] = {s.a, s.b};
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) slots_.push_back(slot(3 * idx[p] + i, 3 * idx[q] + j));
  }
}

template <class BlockFn>
void SpringModel::assemble(SparseMatrix& H, double diagonal, BlockFn block) const {
  H = pattern_;
  double* values = H.valuePtr();
  std::fill(values, values + H.nonZeros(), 0.0);
  for (int slot : diagonal_slots_) values[slot] = diagonal;
  const int* slot = slots_.data();
  for (const Spring& s : springs_) {
    const Mat6 B = block(s);
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) values[*slot++] += B(3 * p + i, 3 * q + j);
  }
}

void SpringModel::set_threads(int n) {
  if (n != kernel_.threads()) kernel_ = NodeSprings(springs_, num_nodes_, n, rest_nodes_);
}

void SpringModel::require_size(const VectorXd& x) const {
  if (x.size() != num_dofs()) {
    throw std::invalid_argument("SpringModel: state of " + std::to_string(x.size()) +
                                " values, expected 3 × " + std::to_string(num_nodes_));
  }
}

double SpringModel::energy(const VectorXd& x) const {
  require_size(x);
  return kernel_.energy(x.data());
}

void SpringModel::gradient(const VectorXd& x, VectorXd& g) const {
  require_size(x);
  g.resize(num_dofs());
  kernel_.gradient(x.data(), g.data());
}

double SpringModel::energy_gradient(const VectorXd& x, VectorXd& g) const {
  require_size(x);
  g.resize(num_dofs());
  return kernel_.energy_gradient(x.data(), g.data());
}

double SpringModel::reference_energy(const VectorXd& x) const {
  double e = 0.0;
  for (const Spring& s : springs_)
    e += spring_energy(node(x, s.a), node(x, s.b), s.rest_length, s.law);
  return e;
}

void SpringModel::reference_gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs());
  for (const Spring& s : springs_) {
    const Vec6 gs = spring_gradient(node(x, s.a), node(x, s.b), s.rest_length, s.law);
    g.segment<3>(3 * s.a) += gs.head<3>();
    g.segment<3>(3 * s.b) += gs.tail<3>();
  }
}

void SpringModel::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  require_size(x);
  H = pattern_;
  double* values = H.valuePtr();
  std::fill(values, values + H.nonZeros(), 0.0);
  const int* slot = slots_.data();
  for (const Spring& s : springs_) {
    const Vec3 xa = node(x, s.a), xb = node(x, s.b);
    const Vec3 e = xa - xb;
    const double L = e.norm();
    if (!(L > 0.0)) {  // coincident ends: the reference kernel's special case
      const Mat6 B = spring_hessian(xa, xb, s.rest_length, s.law, project_psd);
      for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) values[*slot++] += B(3 * p + i, 3 * q + j);
      continue;
    }
    // spring_hessian's block K = ψ''·d dᵀ + ψ'/L·(I − d dᵀ) (kernels/spring_kernels.hpp), built
    // here as one 3×3 block and added as [[K, −K], [−K, K]]: no 6×6 matrix per spring.
    const Vec3 d = e / L;
    const LengthProfile prof = spring_profile(L, s.rest_length, s.law);
    double axial = prof.ddpsi;
    double transverse = prof.dpsi / L;
    if (project_psd) {
      axial = std::max(axial, 0.0);
      transverse = std::max(transverse, 0.0);
    }
    double K[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double D = d[i] * d[j];
        K[i][j] = axial * D + transverse * ((i == j ? 1.0 : 0.0) - D);
      }
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q) {
        const double sign = p == q ? 1.0 : -1.0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) values[*slot++] += sign * K[i][j];
      }
  }
}

void SpringModel::reference_hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  assemble(H, 0.0, [&](const Spring& s) {
    return spring_hessian(node(x, s.a), node(x, s.b), s.rest_length, s.law, project_psd);
  });
}

void SpringModel::damping_force(const VectorXd& x, const VectorXd& v, VectorXd& f) const {
  f = -point_damping_ * v;  // seed 000 eq. (3.3), every node
  for (int index : damped_) {  // only the springs with k_d ≠ 0: none walked when all are zero
    const Spring& s = springs_[static_cast<std::size_t>(index)];
    const Vec6 fs = axial_damping_force(node(x, s.a), node(x, s.b), node(v, s.a), node(v, s.b),
                                        s.damping);  // seed 000 eq. (3.4)
    f.segment<3>(3 * s.a) += fs.head<3>();
    f.segment<3>(3 * s.b) += fs.tail<3>();
  }
}

void SpringModel::damping_jacobian(const VectorXd& x, SparseMatrix& D) const {
  if (damped_.empty()) {  // no axial damping: k_v on the diagonal, in the Hessian's pattern
    D = pattern_;
    double* values = D.valuePtr();
    std::fill(values, values + D.nonZeros(), 0.0);
    for (int slot : diagonal_slots_) values[slot] = point_damping_;
    return;
  }
  assemble(D, point_damping_, [&](const Spring& s) {
    return axial_damping_jacobian(node(x, s.a), node(x, s.b), s.damping);
  });
}

double SpringModel::max_strain(const VectorXd& x) const {
  double m = 0.0;
  for (const Spring& s : springs_) {
    m = std::max(m, std::abs((node(x, s.a) - node(x, s.b)).norm() - s.rest_length) / s.rest_length);
  }
  return m;
}

VectorXd flatten(const std::vector<Vec3>& nodes) {
  VectorXd x(3 * static_cast<Eigen::Index>(nodes.size()));
  for (std::size_t i = 0; i < nodes.size(); ++i)
    x.segment<3>(3 * static_cast<Eigen::Index>(i)) = nodes[i];
  return x;
}

Problem make_problem(const Form& form, const SpringNetwork& net, const std::vector<double>& masses,
                     const TetMesh& mesh, const std::vector<Vec3>& mesh_loads,
                     const std::vector<std::string>& fixed_groups) {
  Problem p;
  p.form = &form;
  p.rest = flatten(net.nodes);
  const int n = static_cast<int>(net.nodes.size());
  if (static_cast<int>(masses.size()) != n) throw InputError("make_problem: one mass per node");
  p.mass.resize(3 * n);
  for (int i = 0; i < n; ++i) p.mass.segment<3>(3 * i).setConstant(masses[i]);
  std::vector<int> to_net(mesh.nodes.size(), -1);
  for (int i = 0; i < n; ++i) {
    const int s = net.source_node[i];
    if (s >= 0 && s < static_cast<int>(to_net.size())) to_net[s] = i;
  }
  p.external_force = VectorXd::Zero(3 * n);
  for (std::size_t m = 0; m < mesh_loads.size(); ++m) {
    if (mesh_loads[m].squaredNorm() == 0.0) continue;
    int target = to_net[m];
    if (target < 0) {  // load on a mesh node the network does not have: nearest network node
      double best = std::numeric_limits<double>::infinity();
      for (int i = 0; i < n; ++i) {
        const double d = (net.nodes[i] - mesh.nodes[m]).squaredNorm();
        if (d < best) {
          best = d;
          target = i;
        }
      }
    }
    p.external_force.segment<3>(3 * target) += mesh_loads[m];
  }
  p.fixed.assign(3 * n, 0);
  std::set<int> fixed_mesh_nodes;
  for (const auto& name : fixed_groups) {
    const PhysicalGroup& g = mesh.require_group(name, 2, "mesh");
    for (int v : mesh.group_nodes(g)) fixed_mesh_nodes.insert(v);
  }
  for (int i = 0; i < n; ++i) {
    const int s = net.source_node[i];
    if (s >= 0 && fixed_mesh_nodes.count(s)) {
      p.fixed[3 * i] = p.fixed[3 * i + 1] = p.fixed[3 * i + 2] = 1;
    }
  }
  return p;
}

}  // namespace vessel::msm
