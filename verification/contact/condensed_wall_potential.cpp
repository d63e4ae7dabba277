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

CondensedLinearWall::CondensedLinearWall(const fem::FreeDisplacementSystem& system,
                                         std::vector<int> band)
    : band_(std::move(band)), node_rows_(system.node_rows.size(), {-1, -1, -1}) {
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < band_.size(); ++k) {
    const int n = band_[k];
    if (n < 0 || static_cast<std::size_t>(n) >= system.node_rows.size()) {
      throw InputError("the condensed wall's band node " + std::to_string(n) +
                       " is not a node of the wall's mesh");
    }
    for (int c = 0; c < 3; ++c) {
      if (system.node_rows[static_cast<std::size_t>(n)][c] < 0) {
        throw InputError("the condensed wall's band node " + std::to_string(n) +
                         " is held by a support: a band is the wall near the contact, away "
                         "from its supports");
      }
      node_rows_[static_cast<std::size_t>(n)][c] = static_cast<int>(3 * k) + c;
    }
  }
  const ComponentCandidates all = every_component(band_);
  wall_ = std::make_unique<CondensedWall>(system, all.nodes, all.directions);
  const Eigen::LLT<Eigen::MatrixXd> llt(wall_->compliance());
  if (llt.info() != Eigen::Success) {
    throw std::runtime_error("the wall's compliance on the band is not positive definite");
  }
  stiffness_ = llt.solve(Eigen::MatrixXd::Identity(num_dofs(), num_dofs()));
  stiffness_ = 0.5 * (stiffness_ + stiffness_.transpose()).eval();
  sparse_stiffness_ = stiffness_.sparseView();
  setup_seconds_ = seconds_since(t0);
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
  return wall_->displacement(stiffness_ * u);
}

VectorXd CondensedLinearWall::band_rows(const std::vector<Vec3>& field) const {
  VectorXd u(num_dofs());
  for (std::size_t k = 0; k < band_.size(); ++k) {
    u.segment<3>(static_cast<Eigen::Index>(3 * k)) = field[static_cast<std::size_t>(band_[k])];
  }
  return u;
}

namespace {

/// The surface nodes that join the band: the neighbours outside it of a pressed node on its edge,
/// and the nodes outside it the displaced wall brings within `margin` of the wire's surface.
std::vector<int> joining(const TetMesh& mesh, const std::vector<Triangle>& triangles,
                         const std::vector<int>& surface, const std::vector<int>& band,
                         const PotentialContactSolution& s, const std::vector<Vec3>& field,
                         const ContactWire& wire, double margin) {
  std::vector<char> in(mesh.nodes.size(), 0), pressed(mesh.nodes.size(), 0),
      grow(mesh.nodes.size(), 0);
  for (const int n : band) in[static_cast<std::size_t>(n)] = 1;
  for (const int n : s.pressed) pressed[static_cast<std::size_t>(n)] = 1;
  for (const Triangle& t : triangles) {
    bool any = false;
    for (int k = 0; k < 3; ++k) any = any || pressed[static_cast<std::size_t>(t[k])];
    if (!any) continue;
    for (int k = 0; k < 3; ++k) {
      if (!in[static_cast<std::size_t>(t[k])]) grow[static_cast<std::size_t>(t[k])] = 1;
    }
  }
  for (const int n : surface) {
    const auto i = static_cast<std::size_t>(n);
    if (!in[i] && capsule_gap(wire, s.x, mesh.nodes[i] + field[i]) < margin) grow[i] = 1;
  }
  std::vector<int> added;
  for (std::size_t n = 0; n < grow.size(); ++n) {
    if (grow[n]) added.push_back(static_cast<int>(n));
  }
  return added;
}

/// The surface nodes outside the band within `reach` of a centreline polyline.
std::vector<int> near_centreline(const TetMesh& mesh, const std::vector<int>& surface,
                                 const std::vector<int>& band, const std::vector<Vec3>& centreline,
                                 double reach) {
  std::vector<char> in(mesh.nodes.size(), 0);
  for (const int n : band) in[static_cast<std::size_t>(n)] = 1;
  std::vector<int> added;
  for (const int n : surface) {
    if (in[static_cast<std::size_t>(n)]) continue;
    const Vec3& p = mesh.nodes[static_cast<std::size_t>(n)];
    for (std::size_t i = 0; i + 1 < centreline.size(); ++i) {
      const Vec3 e = centreline[i + 1] - centreline[i];
      const double t = std::clamp((p - centreline[i]).dot(e) / e.squaredNorm(), 0.0, 1.0);
      if ((p - centreline[i] - t * e).norm() < reach) {
        added.push_back(n);
        break;
      }
    }
  }
  return added;
}

}  // namespace

GrownPotentialContact solve_wire_wall_potential_growing(msm::rods::Rod& rod, double radius,
                                                        const fem::FreeDisplacementSystem& system,
                                                        const TetMesh& mesh, std::vector<int> band,
                                                        const VectorXd& start,
                                                        const PotentialContactOptions& options,
                                                        const BandGrowth& growth) {
  const PhysicalGroup& group = mesh.require_group(growth.surface_group, 2, "wall mesh");
  const std::vector<Triangle> triangles = mesh.group_triangles(group);
  const std::vector<int> surface = mesh.group_nodes(group);
  const ContactWire wire = contact_wire(rod, radius);
  std::sort(band.begin(), band.end());
  GrownPotentialContact out;
  // The last equilibrium (the wire's start and the wall at rest before the first): every band's
  // solve starts from it.
  VectorXd x = start;
  std::vector<Vec3> field(mesh.nodes.size(), Vec3::Zero());
  int newton = 0, factorisations = 0;
  double seconds = 0.0;
  for (;; ++out.rounds) {
    out.wall = std::make_unique<CondensedLinearWall>(system, band);
    out.setup_seconds += out.wall->setup_seconds();
    std::vector<int> added;
    try {
      out.solution = solve_wire_wall_potential(rod, radius, *out.wall, mesh, band, x, options,
                                               out.wall->band_rows(field));
      newton += out.solution.newton_iterations;
      factorisations += out.solution.factorisations;
      seconds += out.solution.seconds;
      x = out.solution.x;
      field = out.wall->nodal(out.solution.u);
      added = joining(mesh, triangles, surface, band, out.solution, field, wire, growth.margin);
    } catch (const WireThroughWall& e) {
      // The wire left the band through the wall, between nodes that were not candidates.
      added = near_centreline(mesh, surface, band, e.centreline, growth.crossing_reach);
      if (added.empty() || out.rounds == growth.max_rounds) throw;
    }
    if (added.empty()) break;
    if (out.rounds == growth.max_rounds) {
      throw std::runtime_error(
          "the wire-wall potential's contact still reaches the band's edge "
          "after " +
          std::to_string(growth.max_rounds) + " growths (" + std::to_string(band.size()) +
          " band nodes)");
    }
    band.insert(band.end(), added.begin(), added.end());
    std::sort(band.begin(), band.end());  // the pressed nodes come out ascending
  }
  out.solution.newton_iterations = newton;
  out.solution.factorisations = factorisations;
  out.solution.seconds = seconds;
  return out;
}

}  // namespace vessel::contact
