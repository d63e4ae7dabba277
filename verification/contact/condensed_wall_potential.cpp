#include "verification/contact/condensed_wall_potential.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::contact {

using Eigen::VectorXd;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

CondensedLinearWall::CondensedLinearWall(fem::FreeDisplacementSystem system,
                                         const std::vector<int>& band)
    : system_(std::move(system)), node_rows_(system_.node_rows.size(), {-1, -1, -1}) {
  const auto t0 = std::chrono::steady_clock::now();
  factor_ = std::make_unique<fem::CholmodFactor>(system_.K);
  setup_seconds_ = seconds_since(t0);
  grow(band);
}

CondensedLinearWall::~CondensedLinearWall() = default;

void CondensedLinearWall::grow(const std::vector<int>& added) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto old_dofs = static_cast<Eigen::Index>(3 * band_.size());
  for (const int n : added) {
    if (n < 0 || static_cast<std::size_t>(n) >= system_.node_rows.size()) {
      throw InputError("the condensed wall's band node " + std::to_string(n) +
                       " is not a node of the wall's mesh");
    }
    auto& rows = node_rows_[static_cast<std::size_t>(n)];
    if (rows[0] >= 0) {
      throw InputError("the condensed wall's band node " + std::to_string(n) + " is given twice");
    }
    for (int c = 0; c < 3; ++c) {
      if (system_.node_rows[static_cast<std::size_t>(n)][c] < 0) {
        throw InputError("the condensed wall's band node " + std::to_string(n) +
                         " is held by a support: a band is the wall near the contact, away "
                         "from its supports");
      }
      rows[c] = static_cast<int>(3 * band_.size()) + c;
    }
    band_.push_back(n);
  }
  // W's new columns (a unit force along each new component; by symmetry also its new rows).
  const Eigen::Index dofs = num_dofs();
  compliance_.conservativeResize(dofs, dofs);
  constexpr Eigen::Index kBlock = 32;  // columns per blocked solve: n × 32 doubles at a time
  for (Eigen::Index first = old_dofs; first < dofs; first += kBlock) {
    const Eigen::Index cols = std::min(kBlock, dofs - first);
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(system_.K.rows(), cols);
    for (Eigen::Index j = 0; j < cols; ++j) {
      const Eigen::Index d = first + j;
      B(system_.node_rows[static_cast<std::size_t>(band_[d / 3])][d % 3], j) = 1.0;
    }
    const Eigen::MatrixXd U = factor_->solve_block(B);
    for (Eigen::Index i = 0; i < dofs; ++i) {
      const int row = system_.node_rows[static_cast<std::size_t>(band_[i / 3])][i % 3];
      for (Eigen::Index j = 0; j < cols; ++j) compliance_(i, first + j) = U(row, j);
    }
  }
  compliance_.bottomLeftCorner(dofs - old_dofs, old_dofs) =
      compliance_.topRightCorner(old_dofs, dofs - old_dofs).transpose();
  compliance_ = 0.5 * (compliance_ + compliance_.transpose()).eval();  // symmetric to round-off
  const Eigen::LLT<Eigen::MatrixXd> llt(compliance_);
  if (llt.info() != Eigen::Success) {
    throw std::runtime_error("the wall's compliance on the band is not positive definite");
  }
  stiffness_ = llt.solve(Eigen::MatrixXd::Identity(dofs, dofs));
  stiffness_ = 0.5 * (stiffness_ + stiffness_.transpose()).eval();
  sparse_stiffness_ = stiffness_.sparseView();
  setup_seconds_ += seconds_since(t0);
}

double CondensedLinearWall::evaluate(const VectorXd& u, VectorXd* gradient,
                                     Eigen::SparseMatrix<double>* hessian,
                                     bool /*project_psd*/) const {
  const VectorXd f = stiffness_ * u;
  if (gradient) *gradient = f;
  if (hessian) *hessian = sparse_stiffness_;
  return 0.5 * u.dot(f);
}

double CondensedLinearWall::largest_strain(const TetMesh& mesh, const VectorXd& u) const {
  return contact::largest_strain(mesh, nodal(u)).small;
}

std::vector<Vec3> CondensedLinearWall::nodal(const VectorXd& u) const {
  const VectorXd forces = stiffness_ * u;
  VectorXd f = VectorXd::Zero(system_.K.rows());
  for (std::size_t k = 0; k < band_.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      f[system_.node_rows[static_cast<std::size_t>(band_[k])][c]] =
          forces[static_cast<Eigen::Index>(3 * k) + c];
    }
  }
  return per_node(system_.node_rows, factor_->solve(f));
}

VectorXd CondensedLinearWall::band_rows(const std::vector<Vec3>& field) const {
  VectorXd u(num_dofs());
  for (std::size_t k = 0; k < band_.size(); ++k) {
    u.segment<3>(static_cast<Eigen::Index>(3 * k)) = field[static_cast<std::size_t>(band_[k])];
  }
  return u;
}

namespace {

/// Where the wire went through the wall: the crossed triangle's nodes outside the band and every
/// surface node outside it within `reach` of the crossing; none if the triangle is the band's own
/// (the wire passed between candidates: no growth helps).
std::vector<int> near_crossing(const TetMesh& mesh, const std::vector<int>& surface,
                               const std::vector<int>& band, const WireThroughWall& crossing,
                               double reach) {
  std::vector<char> in(mesh.nodes.size(), 0);
  for (const int n : band) in[static_cast<std::size_t>(n)] = 1;
  const bool own = std::all_of(crossing.triangle.begin(), crossing.triangle.end(),
                               [&](int n) { return in[static_cast<std::size_t>(n)] != 0; });
  std::vector<int> added;
  if (own) return added;
  for (const int n : surface) {
    const auto i = static_cast<std::size_t>(n);
    const bool corner =
        std::find(crossing.triangle.begin(), crossing.triangle.end(), n) != crossing.triangle.end();
    if (!in[i] && (corner || (mesh.nodes[i] - crossing.point).norm() < reach)) added.push_back(n);
  }
  return added;
}

}  // namespace

PotentialContactSolution solve_on_growing_band(msm::rods::Rod& rod, double radius,
                                               CondensedLinearWall& wall, const TetMesh& mesh,
                                               const VectorXd& start, std::vector<Vec3> field,
                                               const PotentialContactOptions& options,
                                               const BandGrowth& growth, int& rounds) {
  const PhysicalGroup& group = mesh.require_group(growth.surface_group, 2, "wall mesh");
  const std::vector<Triangle> triangles = mesh.group_triangles(group);
  const std::vector<int> surface = mesh.group_nodes(group);
  const ContactWire wire = contact_wire(rod, radius);
  // The last equilibrium (the wire's start and the given field before the first): every band's
  // solve starts from it.
  VectorXd x = start;
  PotentialContactSolution solution;
  int newton = 0, factorisations = 0;
  double seconds = 0.0;
  for (rounds = 0;; ++rounds) {
    const std::vector<int>& band = wall.band();
    std::vector<int> added;
    try {
      std::vector<int> candidates = band;  // ascending: so are the pressed nodes
      std::sort(candidates.begin(), candidates.end());
      solution = solve_wire_wall_potential(rod, radius, wall, mesh, candidates, x, options,
                                           wall.band_rows(field));
      newton += solution.newton_iterations;
      factorisations += solution.factorisations;
      seconds += solution.seconds;
      x = solution.x;
      field = wall.nodal(solution.u);
      added = joining_the_band(mesh, triangles, surface, band, solution.pressed, wire, x, field,
                               growth.margin);
    } catch (const WireThroughWall& e) {
      // The wire left the band through the wall, between nodes that were not candidates.
      added = near_crossing(mesh, surface, band, e, growth.crossing_reach);
      if (added.empty() || rounds == growth.max_rounds) throw;
    }
    if (added.empty()) break;
    if (rounds == growth.max_rounds) {
      throw std::runtime_error(
          "the wire-wall potential's contact still reaches the band's edge "
          "after " +
          std::to_string(growth.max_rounds) + " growths (" + std::to_string(band.size()) +
          " band nodes)");
    }
    wall.grow(added);
  }
  solution.newton_iterations = newton;
  solution.factorisations = factorisations;
  solution.seconds = seconds;
  return solution;
}

GrownPotentialContact solve_wire_wall_potential_growing(
    msm::rods::Rod& rod, double radius, const fem::FreeDisplacementSystem& system,
    const TetMesh& mesh, const std::vector<int>& band, const VectorXd& start,
    const PotentialContactOptions& options, const BandGrowth& growth) {
  GrownPotentialContact out;
  out.wall = std::make_unique<CondensedLinearWall>(system, band);
  out.solution = solve_on_growing_band(rod, radius, *out.wall, mesh, start,
                                       std::vector<Vec3>(mesh.nodes.size(), Vec3::Zero()), options,
                                       growth, out.rounds);
  return out;
}

}  // namespace vessel::contact
