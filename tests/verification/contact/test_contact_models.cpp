// Vessel models' walls in the wire–wall contact (verification/contact/model_walls): each model's
// stiffness at rest, its supports held, condensed and pressed by the wire like the FEM
// reference's. Checked against independent truth: deal.II's P1 assembly (the same operator
// assembled twice), the spring model's own nonlinear static equilibrium (finite differences in the
// load) and its support reactions (action and reaction). Rows printed as "CONTACT-MODELS ...".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fem_reference/elasticity.hpp"
#include "meshes/foundation/errors.hpp"
#include "meshes/supports.hpp"
#include "msm/fem/linear_tet.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "verification/contact/wire_wall_contact.hpp"
#include "verification/contact_models/contact_models.hpp"
#include "verification/contact_models/model_walls.hpp"
#include "verification/scene_problems.hpp"
#include "wire_in_tube.hpp"

using namespace vessel;
using namespace vessel::wire_in_tube;

namespace {

/// The straight tube of wire_in_tube::tube_mesh as a scene: its vessel, the wall's material at
/// E (Pa) and ν = 0.45, both ends clamped.
Scene tube_scene(double young) {
  Scene s;
  s.name = "tube";
  s.source = "tube (test)";
  s.vessel.length = kTubeLength;
  s.vessel.style = MeshStyle::structured;
  s.vessel.level = 0;
  s.youngs_modulus = young;
  s.poisson_ratios = {0.45};
  s.boundary = {{"inlet", EndCondition::clamped}, {"outlet", EndCondition::clamped}};
  return s;
}

ModelSpec spec(const std::string& name, ModelKind kind) {
  ModelSpec m;
  m.name = name;
  m.kind = kind;
  return m;
}

/// The nitinol wire (d = 0.356 mm, N = 32) of the straight-tube set-up aimed at the aimed node,
/// pressed into the wall `system` on the candidates within 4 mm and 60° of it (the coupled_run
/// set-up of wire_in_tube.hpp, with the wall given).
struct Pressed {
  contact::WireWallSolution solution;
  Vec3 clamp = Vec3::Zero();
  std::vector<Vec3> u;  ///< the wall's displacement per mesh node
  std::unique_ptr<contact::CondensedWall> wall;
  std::vector<int> nodes;
};

Pressed press(const fem::FreeDisplacementSystem& system) {
  const TetMesh& mesh = tube_mesh();
  const Vec3 target = mesh.nodes[aim_node(mesh)];
  Pressed out;
  out.nodes = band(mesh, target.z(), 4e-3, 1.05);
  const double d = 0.356e-3;
  const double length = rod_theory::straight_tube_contact(kTheta, (kA - d / 2) / kZc).length * kZc;
  Wire w(d, length, 32, Vec3(0, 0, target.z() - kZc));
  const RigidRun rigid = rigid_run(w);
  const contact::ComponentCandidates all = contact::every_component(out.nodes);
  out.wall = std::make_unique<contact::CondensedWall>(system, all.nodes, all.directions);
  const Vec3 tip = rigid.x.segment<3>(3 * w.layout.tip_node);
  const int first =
      nearest_candidate(mesh, out.nodes, tip + w.radius * Vec3(tip.x(), tip.y(), 0).normalized());
  contact::WireWallOptions o;
  o.force_scale = w.EI / (kZc * kZc);
  out.solution = contact::solve_wire_wall_contact(
      w.contact(), *out.wall, contact::into_wall_directions(mesh, out.nodes, "inner_wall"), mesh,
      rigid.x, {first}, o);
  out.clamp = contact::clamp_reaction(w.contact(), *out.wall, mesh, out.solution);
  out.u = out.wall->displacement(out.solution.wall_loads());
  return out;
}

}  // namespace

// msm's linear P1 tetrahedron (LinearTetTerm) and corotational P1 at rest (model_wall) against
// deal.II's P1 on the same mesh, the same supports: the same operator assembled by two codes, so
// the condensed compliances and then the contact forces of the same wire agree to round-off
// (1e-8 relative), though the contact solve decides its contact set itself on each.
TEST(ContactModels, MsmP1EqualsDealIiP1InTheContact) {
  const TetMesh& mesh = tube_mesh();
  const double young = 100 * kWallE;
  const fem::ElasticitySolver solver(mesh, wall_problem(young));
  const fem::FreeDisplacementSystem deal = solver.free_displacement_system();
  const msm::LinearTetTerm linear(mesh.nodes, mesh.tets, msm::lame_parameters(young, 0.45));
  Eigen::VectorXd rest(3 * static_cast<Eigen::Index>(mesh.nodes.size()));
  std::vector<int> identity(mesh.nodes.size());
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    rest.segment<3>(3 * static_cast<Eigen::Index>(i)) = mesh.nodes[i];
    identity[i] = static_cast<int>(i);
  }
  const std::vector<char> held =
      held_dofs(mesh, mesh.nodes, identity, scene_supports(tube_scene(young)));
  const fem::FreeDisplacementSystem msm_p1 =
      contact::form_wall_system(linear, rest, held, identity, mesh.nodes.size());
  const contact::ModelWall corotational =
      contact::model_wall(tube_scene(young), spec("corotational", ModelKind::corotational_fem),
                          mesh, tube_scene(young).vessel, 0.45);
  EXPECT_EQ(corotational.linearisation, contact::WallLinearisation::small_dent);
  ASSERT_EQ(msm_p1.K.rows(), deal.K.rows());  // the same dofs held

  const Pressed ref = press(deal);
  // msm's linear P1 is its own linearisation: its energy balances the contact loads at the dent
  // (own_imbalance maps the wall's displacement and loads onto the Form's nodes).
  {
    const Pressed p = press(msm_p1);
    contact::ModelWall wall;
    wall.energy = {nullptr, &linear, rest, held, identity};
    std::vector<Vec3> loads(mesh.nodes.size(), Vec3::Zero());
    for (std::size_t j = 0; j < p.nodes.size(); ++j) {
      loads[static_cast<std::size_t>(p.nodes[j])] =
          p.solution.force[static_cast<Eigen::Index>(j)] * p.solution.direction[j];
    }
    const double imbalance = contact::own_imbalance(wall, p.u, loads);
    std::printf("CONTACT-MODELS msm linear P1's own imbalance at its dent: %.2e\n", imbalance);
    EXPECT_LT(imbalance, 1e-8);
  }
  for (const fem::FreeDisplacementSystem* sys : {&msm_p1, &corotational.system}) {
    const Pressed p = press(*sys);
    const double w_diff = (p.wall->compliance() - ref.wall->compliance()).cwiseAbs().maxCoeff();
    const double w_max = ref.wall->compliance().cwiseAbs().maxCoeff();
    const double F = p.solution.force.sum(), F_ref = ref.solution.force.sum();
    std::printf(
        "CONTACT-MODELS msm P1 vs deal.II P1: W differs by %.2e of its largest entry; F %.9e N "
        "vs %.9e N (%+.2e), %zu vs %zu pressed\n",
        w_diff / w_max, F, F_ref, F / F_ref - 1, p.solution.active.size(),
        ref.solution.active.size());
    EXPECT_LT(w_diff, 1e-10 * w_max);
    EXPECT_EQ(p.solution.active, ref.solution.active);
    EXPECT_LT(std::abs(F / F_ref - 1), 1e-8);
    EXPECT_LT((p.solution.force - ref.solution.force).cwiseAbs().maxCoeff(), 1e-8 * F_ref);
  }
}

// A spring model's condensed compliance is its own static response: W's columns against central
// differences of the model's nonlinear equilibrium (msm's static Newton on the full energy) under
// ±δ along each component of a candidate node, at every candidate. The differences are second
// order in δ (measured: at δ = 1e-8, 1e-7, 1e-6, 1e-5 N, 6.8e-11, 1.5e-9, 1.5e-7, 1.5e-5 of W's
// largest entry for the volume springs, 1.0e-8, 1.0e-6, 1.0e-4, 1.0e-2 for the surface model on
// the mid-surface, whose out-of-plane response stiffens with the dent: its linearisation holds for
// dents well below ~0.2 mm only); δ = 1e-8 N dents the 1 × wall by ~2e-8 m.
TEST(ContactModels, SpringComplianceIsTheModelsOwnStaticResponse) {
  const TetMesh& mesh = tube_mesh();
  const Scene scene = tube_scene(kWallE);
  ModelSpec mollemans = spec("volume_mollemans", ModelKind::volume_msm);
  mollemans.stiffness = msm::StiffnessRule::seed001;
  ModelSpec surface = spec("surface_seed000_mid", ModelKind::surface_msm);
  surface.surface = msm::WallSurface::mid;
  for (const ModelSpec& m : {mollemans, surface}) {
    const contact::ModelWall wall = contact::model_wall(scene, m, mesh, scene.vessel, 0.45);
    const Vec3 target = mesh.nodes[aim_node(mesh)];
    const std::vector<int> nodes = band(mesh, target.z(), 1.5e-3, 0.3);
    ASSERT_GE(nodes.size(), 3u);
    const contact::ComponentCandidates all = contact::every_component(nodes);
    const contact::CondensedWall condensed(wall.system, all.nodes, all.directions);
    const Eigen::MatrixXd& W = condensed.compliance();

    const msm::BuiltNetwork built = scene_network(scene, m, mesh, scene.vessel, 0.45);
    const auto model = msm::make_model(built, 0.0);
    msm::Problem p = msm_problem(scene, *model, built, mesh, 0.0);
    std::vector<int> model_node(mesh.nodes.size(), -1);  // the network node at each mesh node
    for (std::size_t i = 0; i < built.network.source_node.size(); ++i) {
      if (built.network.source_node[i] >= 0)
        model_node[built.network.source_node[i]] = static_cast<int>(i);
    }
    constexpr double kDelta = 1e-8;  // N
    msm::StaticOptions so;
    so.tolerance = 1e-12;
    double worst = 0.0;
    const Eigen::Index column = 3 * (static_cast<Eigen::Index>(nodes.size()) / 2);  // a middle node
    for (Eigen::Index col = column; col < column + 3; ++col) {
      Eigen::VectorXd response[2];
      for (int side = 0; side < 2; ++side) {
        p.external_force.setZero();
        const int n = model_node[static_cast<std::size_t>(all.nodes[col])];
        ASSERT_GE(n, 0);
        p.external_force.segment<3>(3 * n) = (side == 0 ? kDelta : -kDelta) * all.directions[col];
        response[side] = msm::solve_static(p, so).x - p.rest;
      }
      for (Eigen::Index row = 0; row < W.rows(); ++row) {
        const int n = model_node[static_cast<std::size_t>(all.nodes[row])];
        const double fd =
            (response[0] - response[1]).segment<3>(3 * n).dot(all.directions[row]) / (2 * kDelta);
        worst = std::max(worst, std::abs(fd - W(row, col)));
      }
    }
    const double largest = W.cwiseAbs().maxCoeff();
    std::printf(
        "CONTACT-MODELS %s: condensed compliance vs central differences of its static "
        "equilibrium: largest difference %.2e of W's largest entry (%.4e m/N), %zu candidates\n",
        m.name.c_str(), worst / largest, largest, nodes.size());
    EXPECT_LT(worst, 1e-7 * largest);
  }
}

// Action and reaction through a spring model's supports: the surface model on the mid-surface
// (its nodes mapped to the inner wall's) pressed by the wire; the wire's clamp reaction plus the
// supports' reactions, the model's own forces at its held dofs (its Hessian at rest on the whole
// network times the displacement the contact solve gives: on a held dof the support's force on
// the wall), sum to zero.
TEST(ContactModels, ActionEqualsReactionThroughASurfaceModelsSupports) {
  const TetMesh& mesh = tube_mesh();
  const Scene scene = tube_scene(100 * kWallE);
  ModelSpec surface = spec("surface_seed000_mid", ModelKind::surface_msm);
  surface.surface = msm::WallSurface::mid;
  const contact::ModelWall wall = contact::model_wall(scene, surface, mesh, scene.vessel, 0.45);
  const Pressed p = press(wall.system);
  const double F = p.solution.force.sum();
  ASSERT_GT(F, 0.0);

  const msm::BuiltNetwork built = scene_network(scene, surface, mesh, scene.vessel, 0.45);
  const auto model = msm::make_model(built, 0.0);
  const msm::Problem problem = msm_problem(scene, *model, built, mesh, 0.0);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(problem.num_dofs());
  for (std::size_t i = 0; i < built.network.source_node.size(); ++i) {
    u.segment<3>(3 * static_cast<Eigen::Index>(i)) = p.u[built.network.source_node[i]];
  }
  msm::SparseMatrix H;
  model->hessian(problem.rest, H, false);
  const Eigen::VectorXd internal = H * u;
  Vec3 supports = Vec3::Zero();
  for (Eigen::Index d = 0; d < internal.size(); ++d) {
    if (problem.fixed[static_cast<std::size_t>(d)]) supports[d % 3] += internal[d];
  }
  const Vec3 sum = p.clamp + supports;
  std::printf(
      "CONTACT-MODELS surface mid-surface model at 100x: F %.6e N, %zu pressed, clamp + supports "
      "|%.3e| N (%.2e of F)\n",
      F, p.solution.active.size(), sum.norm(), sum.norm() / F);
  EXPECT_GT(supports.norm(), 0.5 * F);
  EXPECT_LT(sum.norm(), 1e-9 * F);
}

// Kinds and surfaces with no wall the wire can touch are refused by name.
// Models that differ only in their solver or region of interest are solved once in the contact
// (same_contact_wall): their walls, built independently, are the same matrix to the last bit;
// a different stiffness rule is another wall.
TEST(ContactModels, ASolverOrARegionOfInterestLeavesTheWallAsItIs) {
  const TetMesh& mesh = tube_mesh();
  const Scene scene = tube_scene(kWallE);
  ModelSpec a = spec("volume/lloyd/static", ModelKind::volume_msm);
  a.stiffness = msm::StiffnessRule::lloyd;
  ModelSpec b = a;
  b.name = "volume/lloyd/linear/R=4mm";
  b.solver = msm::parse_solver("linear");
  b.roi_radius = 4e-3;
  ModelSpec c = a;
  c.stiffness = msm::StiffnessRule::van_gelder;
  EXPECT_TRUE(contact::same_contact_wall(a, b));
  EXPECT_FALSE(contact::same_contact_wall(a, c));
  const auto K = [&](const ModelSpec& m) {
    return contact::model_wall(scene, m, mesh, scene.vessel, 0.45).system.K;
  };
  const auto largest = [](const Eigen::SparseMatrix<double>& m) {
    return m.nonZeros() == 0 ? 0.0 : m.coeffs().cwiseAbs().maxCoeff();
  };
  const Eigen::SparseMatrix<double> Ka = K(a);
  EXPECT_EQ(largest(Ka - K(b)), 0.0);
  EXPECT_GT(largest(Ka - K(c)), 1e-3 * largest(Ka));
}

// The folded walls named under a run's table: a solved model with inverted tets at its own
// equilibrium, not one with none, a linearised wall (no count) or a failed solve.
TEST(ContactModels, TheFoldedWallsAreTheSolvedOnesWithInvertedTets) {
  contact::ContactModelsRun run;
  const auto model = [](const std::string& name, std::optional<std::size_t> inverted,
                        const std::string& failure) {
    contact::ModelContact m;
    m.name = name;
    m.inverted_tets = inverted;
    m.failure = failure;
    return m;
  };
  run.models = {model("volume_mollemans", 890, ""), model("volume_van_gelder", 0, ""),
                model("fem_p1", std::nullopt, ""), model("surface_seed000", 12, "crossed"),
                model("xpbd_fem", 3, "")};
  EXPECT_EQ(contact::folded_walls(run), "volume_mollemans (890), xpbd_fem (3)");
  run.models.erase(run.models.begin());
  run.models.pop_back();
  EXPECT_EQ(contact::folded_walls(run), "");
}

// The linear walls dented through a 1 mm wall, by hand: solved, linear (linearised at rest, or
// a linear FEM model at its own equilibrium), dent above the thickness (the reference's row
// included; a failed row and a nonlinear wall at its own equilibrium not).
TEST(ContactModels, TheLinearWallsDentedThroughAreTheSolvedLinearOnesDeeperThanTheWall) {
  const auto model = [](const std::string& name, double dent, bool linear,
                        const std::string& failure) {
    contact::ModelContact m;
    m.name = name;
    m.dent = dent;
    m.linear_wall = linear;
    m.failure = failure;
    return m;
  };
  contact::ContactModelsRun run;
  run.reference = model("reference_fem_p2", 1.2e-3, true, "");
  run.models = {
      model("fem_p1", 1.36e-3, true, ""),  // at own equilibrium too: FEM P1 is linear
      model("volume_hybrid", 0.9e-3, true, ""), model("surface_shells", 1.43e-3, true, ""),
      model("volume_mollemans", 2e-3, true, "crossed"), model("xpbd_fem", 2.35e-3, false, "")};
  EXPECT_EQ(contact::linear_walls_dented_through(run, 1e-3),
            "reference_fem_p2 (1.2 mm), fem_p1 (1.36 mm), surface_shells (1.43 mm)");
  EXPECT_EQ(contact::linear_walls_dented_through(run, 1.5e-3), "");
}

TEST(ContactModels, OuterSurfaceModelIsRefused) {
  const Scene scene = tube_scene(kWallE);
  ModelSpec outer = spec("outer", ModelKind::surface_msm);
  outer.surface = msm::WallSurface::outer;
  EXPECT_THROW((void)contact::model_wall(scene, outer, tube_mesh(), scene.vessel, 0.45),
               InputError);
  EXPECT_THROW((void)contact::model_wall(scene, spec("ext", ModelKind::external), tube_mesh(),
                                         scene.vessel, 0.45),
               InputError);
}
