#include "verification/contact_models/model_walls.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "meshes/foundation/errors.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "verification/model_capabilities.hpp"
#include "verification/scene_problems.hpp"

namespace vessel::contact {

fem::FreeDisplacementSystem form_wall_system(const msm::Form& form, const Eigen::VectorXd& rest,
                                             const std::vector<char>& fixed,
                                             const std::vector<int>& mesh_node,
                                             std::size_t mesh_nodes) {
  const auto n = static_cast<std::size_t>(form.num_dofs());
  if (static_cast<std::size_t>(rest.size()) != n || fixed.size() != n ||
      3 * mesh_node.size() != n) {
    throw std::invalid_argument("form_wall_system: " + std::to_string(n) + " dofs but " +
                                std::to_string(rest.size()) + " rest values, " +
                                std::to_string(fixed.size()) + " fixed flags, " +
                                std::to_string(mesh_node.size()) + " mapped nodes");
  }
  fem::FreeDisplacementSystem sys;
  sys.free_index.assign(n, -1);
  int free = 0;
  for (std::size_t d = 0; d < n; ++d) {
    if (!fixed[d]) sys.free_index[d] = free++;
  }
  sys.node_rows.assign(mesh_nodes, {-1, -1, -1});
  std::vector<char> mapped(mesh_nodes, 0);
  for (std::size_t i = 0; i < mesh_node.size(); ++i) {
    const int m = mesh_node[i];
    if (m < 0) continue;
    if (static_cast<std::size_t>(m) >= mesh_nodes || mapped[static_cast<std::size_t>(m)]) {
      throw std::invalid_argument("form_wall_system: model node " + std::to_string(i) +
                                  " maps to mesh node " + std::to_string(m) +
                                  (static_cast<std::size_t>(m) >= mesh_nodes
                                       ? ", outside the mesh"
                                       : ", which another model node maps to"));
    }
    mapped[static_cast<std::size_t>(m)] = 1;
    for (int c = 0; c < 3; ++c)
      sys.node_rows[static_cast<std::size_t>(m)][c] = sys.free_index[3 * i + c];
  }
  msm::SparseMatrix H;
  form.hessian(rest, H, false);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(H.nonZeros()));
  for (Eigen::Index col = 0; col < H.outerSize(); ++col) {
    const int fc = sys.free_index[static_cast<std::size_t>(col)];
    if (fc < 0) continue;
    for (msm::SparseMatrix::InnerIterator it(H, col); it; ++it) {
      const int fr = sys.free_index[static_cast<std::size_t>(it.row())];
      if (fr >= 0 && it.value() != 0.0) t.emplace_back(fr, fc, it.value());
    }
  }
  sys.K.resize(free, free);
  sys.K.setFromTriplets(t.begin(), t.end());
  sys.f = Eigen::VectorXd::Zero(free);
  return sys;
}

std::string to_string(WallLinearisation l) {
  return l == WallLinearisation::exact ? "own (linear)" : "small-dent";
}

ModelWall model_wall(const Scene& scene, const ModelSpec& spec, const TetMesh& mesh,
                     const VesselParams& vessel, double nu) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string source = scene.source.string() + ": model " + spec.name;
  if (std::string why = model_refusal(spec, scene.youngs_modulus, nu); !why.empty()) {
    throw InputError(source + ": " + why);
  }
  ModelWall out;
  out.name = spec.name;
  std::chrono::steady_clock::duration untimed{};
  switch (spec.kind) {
    case ModelKind::fem: {
      fem::ElasticityProblem p = fem_problem(scene, mesh, nu, spec.degree, 0.0);
      p.options.formulation = fem::Formulation::displacement;
      const fem::ElasticitySolver solver(mesh, p);
      out.system = solver.free_displacement_system();
      if (spec.degree > 1) {
        // Where a P2 wall's mid-edge contact candidates are (LinearWall::edge_nodes): the
        // contact's, not the model's set-up a simulator pays, so not timed.
        const auto t1 = std::chrono::steady_clock::now();
        solver.set_row_points(out.system);
        untimed = std::chrono::steady_clock::now() - t1;
      }
      out.detail = "FEM P" + std::to_string(spec.degree) + " (deal.II)";
      out.linearisation = WallLinearisation::exact;
      break;
    }
    case ModelKind::corotational_fem:
    case ModelKind::xpbd_fem: {
      std::shared_ptr<const msm::TetTerm> term = tet_fem_term(spec, mesh, scene.youngs_modulus, nu);
      const msm::Problem p = tet_mesh_problem(scene, *term, mesh, 0.0);
      std::vector<int> identity(mesh.nodes.size());
      for (std::size_t i = 0; i < identity.size(); ++i) identity[i] = static_cast<int>(i);
      out.system = form_wall_system(*term, p.rest, p.fixed, identity, mesh.nodes.size());
      out.energy = {term, term.get(), p.rest, p.fixed, identity};
      out.detail = spec.kind == ModelKind::corotational_fem
                       ? "corotational P1 (Müller & Gross 2004), its tangent at rest"
                       : "XPBD FEM's stable neo-Hookean P1 energy (Macklin & Müller 2021), its "
                         "Hessian at rest";
      // Corotational P1's consistent tangent at rest is linear P1's stiffness, but its
      // equilibrium under a dent is not linear P1's (the rotations it extracts): both linearised.
      out.linearisation = WallLinearisation::small_dent;
      break;
    }
    case ModelKind::volume_msm:
    case ModelKind::surface_msm: {
      if (spec.kind == ModelKind::surface_msm && spec.surface == msm::WallSurface::outer) {
        throw InputError(source +
                         ": surface = \"outer\" has no node on the inner wall the wire "
                         "touches; expected surface \"inner\" or \"mid\" for the contact");
      }
      struct Owned {
        msm::BuiltNetwork built;
        std::unique_ptr<msm::MassSpringModel> model;
      };
      auto owned = std::make_shared<Owned>();
      owned->built = scene_network(scene, spec, mesh, vessel, nu);
      owned->model = msm::make_model(owned->built, 0.0);
      const msm::BuiltNetwork& built = owned->built;
      const msm::Problem p = msm_problem(scene, *owned->model, built, mesh, 0.0);
      out.system = form_wall_system(*owned->model, p.rest, p.fixed, built.network.source_node,
                                    mesh.nodes.size());
      out.energy = {owned, owned->model.get(), p.rest, p.fixed, built.network.source_node};
      out.detail = built.topology;
      // Springs are nonlinear in x through their lengths, the edge pairs (StVK) quartic in x.
      out.linearisation = WallLinearisation::small_dent;
      break;
    }
    default:
      throw InputError(source + ": kind " + to_string(spec.kind) +
                       " has no wall in the contact (expected fem, volume_msm, surface_msm, "
                       "corotational_fem or xpbd_fem)");
  }
  out.setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0 - untimed).count();
  return out;
}

double own_imbalance(const ModelWall& wall, const std::vector<Vec3>& u,
                     const std::vector<Vec3>& loads) {
  const WallEnergy& e = wall.energy;
  if (e.form == nullptr) return 0.0;
  Eigen::VectorXd x = e.rest, f = Eigen::VectorXd::Zero(e.rest.size());
  for (std::size_t i = 0; i < e.mesh_node.size(); ++i) {
    const int m = e.mesh_node[i];
    if (m < 0) continue;
    x.segment<3>(3 * static_cast<Eigen::Index>(i)) += u[static_cast<std::size_t>(m)];
    f.segment<3>(3 * static_cast<Eigen::Index>(i)) = loads[static_cast<std::size_t>(m)];
  }
  Eigen::VectorXd g;
  e.form->gradient(x, g);
  double r2 = 0.0, f2 = 0.0;
  for (Eigen::Index d = 0; d < g.size(); ++d) {
    if (e.fixed[static_cast<std::size_t>(d)]) continue;
    r2 += (g[d] - f[d]) * (g[d] - f[d]);
    f2 += f[d] * f[d];
  }
  return f2 > 0.0 ? std::sqrt(r2 / f2) : 0.0;
}

}  // namespace vessel::contact
