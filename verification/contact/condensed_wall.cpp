#include "verification/contact/condensed_wall.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

namespace vessel::contact {

CondensedWall::CondensedWall(fem::FreeDisplacementSystem system, std::vector<int> nodes,
                             std::vector<Vec3> directions)
    : system_(std::move(system)), nodes_(std::move(nodes)), directions_(std::move(directions)) {
  if (nodes_.size() != directions_.size()) {
    throw std::invalid_argument("CondensedWall: " + std::to_string(nodes_.size()) +
                                " candidates but " + std::to_string(directions_.size()) +
                                " directions");
  }
  for (const int n : nodes_) {
    if (n < 0 || static_cast<std::size_t>(n) >= system_.node_rows.size()) {
      throw std::invalid_argument("CondensedWall: candidate node " + std::to_string(n) +
                                  " is not a node of the wall's mesh");
    }
    const auto& rows = system_.node_rows[static_cast<std::size_t>(n)];
    if (rows[0] < 0 && rows[1] < 0 && rows[2] < 0) {
      throw std::invalid_argument("CondensedWall: candidate node " + std::to_string(n) +
                                  " is held by a support");
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  factor_ = std::make_unique<fem::CholmodFactor>(system_.K);
  const auto m = static_cast<Eigen::Index>(nodes_.size());
  compliance_.resize(m, m);
  constexpr Eigen::Index kBlock = 32;  // columns per blocked solve: n × 32 doubles at a time
  for (Eigen::Index first = 0; first < m; first += kBlock) {
    const Eigen::Index cols = std::min(kBlock, m - first);
    Eigen::MatrixXd B(system_.K.rows(), cols);
    for (Eigen::Index j = 0; j < cols; ++j) {
      Eigen::VectorXd unit = Eigen::VectorXd::Zero(m);
      unit[first + j] = 1.0;
      B.col(j) = load_vector(unit);
    }
    const Eigen::MatrixXd U = factor_->solve_block(B);
    for (Eigen::Index i = 0; i < m; ++i) {
      const auto& rows = system_.node_rows[static_cast<std::size_t>(nodes_[i])];
      for (Eigen::Index j = 0; j < cols; ++j) {
        double along = 0.0;
        for (int c = 0; c < 3; ++c) {
          if (rows[c] >= 0) along += directions_[i][c] * U(rows[c], j);
        }
        compliance_(i, first + j) = along;
      }
    }
  }
  compliance_ = 0.5 * (compliance_ + compliance_.transpose()).eval();  // symmetric to round-off
  setup_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

CondensedWall::~CondensedWall() = default;

Eigen::VectorXd CondensedWall::load_vector(const Eigen::VectorXd& forces) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(system_.K.rows());
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const auto& rows = system_.node_rows[nodes_[i]];
    for (int c = 0; c < 3; ++c) {
      if (rows[c] >= 0) f[rows[c]] += forces[static_cast<Eigen::Index>(i)] * directions_[i][c];
    }
  }
  return f;
}

std::vector<Vec3> CondensedWall::displacement(const Eigen::VectorXd& forces) const {
  return per_node(system_.node_rows, factor_->solve(load_vector(forces)));
}

std::vector<Vec3> per_node(const std::vector<std::array<int, 3>>& node_rows,
                           const Eigen::VectorXd& x) {
  std::vector<Vec3> out(node_rows.size(), Vec3::Zero());
  for (std::size_t n = 0; n < out.size(); ++n) {
    for (int c = 0; c < 3; ++c) {
      if (node_rows[n][c] >= 0) out[n][c] = x[node_rows[n][c]];
    }
  }
  return out;
}

ComponentCandidates every_component(const std::vector<int>& nodes) {
  ComponentCandidates out;
  for (const int node : nodes) {
    for (int c = 0; c < 3; ++c) {
      out.nodes.push_back(node);
      out.directions.push_back(Vec3::Unit(c));
    }
  }
  return out;
}

WallStrain largest_strain(const TetMesh& mesh, const std::vector<Vec3>& u) {
  const auto largest_magnitude = [](const Eigen::Matrix3d& m) {
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues().cwiseAbs().maxCoeff();
  };
  WallStrain out;
  for (const Tet& t : mesh.tets) {
    Eigen::Matrix3d dX, dU;
    for (int k = 0; k < 3; ++k) {
      dX.col(k) = mesh.nodes[t[k + 1]] - mesh.nodes[t[0]];
      dU.col(k) = u[t[k + 1]] - u[t[0]];
    }
    const Eigen::Matrix3d H = dU * dX.inverse();
    const Eigen::Matrix3d e = 0.5 * (H + H.transpose());
    out.small = std::max(out.small, largest_magnitude(e));
    out.green = std::max(out.green, largest_magnitude(e + 0.5 * H.transpose() * H));
  }
  return out;
}

}  // namespace vessel::contact
