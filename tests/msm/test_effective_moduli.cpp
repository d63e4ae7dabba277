// The volume model of a cube under uniform uniaxial stretch: effective Young's modulus and
// Poisson's ratio per stiffness rule, against the Cauchy relation (ν = 1/4 for central-force
// spring networks) and against linearity (seed001 = van_gelder / 3 exactly).
#include <gmsh.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "msm/model/spring_model.hpp"
#include "msm/solvers/static_solver.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kSide = 10e-3;

/// Unstructured Delaunay tets of a cube of side 10 mm, element size h (gmsh).
TetMesh cube_mesh(double h) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::model::add("cube");
  gmsh::model::occ::addBox(0, 0, 0, kSide, kSide, kSide);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMin", h);
  gmsh::option::setNumber("Mesh.MeshSizeMax", h);
  gmsh::model::mesh::generate(3);
  std::vector<std::size_t> tags;
  std::vector<double> coords, param;
  gmsh::model::mesh::getNodes(tags, coords, param);
  std::map<std::size_t, int> index;
  TetMesh m;
  for (std::size_t i = 0; i < tags.size(); ++i) {
    index[tags[i]] = static_cast<int>(i);
    m.nodes.emplace_back(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
  }
  std::vector<std::size_t> etags, enodes;
  gmsh::model::mesh::getElementsByType(4, etags, enodes);
  for (std::size_t e = 0; e < etags.size(); ++e) {
    m.tets.push_back({index[enodes[4 * e]], index[enodes[4 * e + 1]], index[enodes[4 * e + 2]],
                      index[enodes[4 * e + 3]]});
  }
  gmsh::finalize();
  remove_unused_nodes(m);
  orient_tets(m);
  return m;
}

struct Moduli {
  double E = 0.0;
  double nu = 0.0;
};

/// Uniaxial stretch ε along x: u_x = 0 on x = 0, u_x = εL on x = L, symmetry planes y = 0 and
/// z = 0 (u_y = 0, u_z = 0), lateral faces free. E = (reaction / L²)/ε, ν = −(mean u_y on
/// y = L / L)/ε.
Moduli measure(const SpringNetwork& net, double strain) {
  const SpringModel model(net);
  Problem p;
  p.form = &model;
  p.rest = flatten(net.nodes);
  const int n = static_cast<int>(net.nodes.size());
  p.mass = Eigen::VectorXd::Ones(3 * n);
  p.external_force = Eigen::VectorXd::Zero(3 * n);
  p.fixed.assign(3 * n, 0);
  const double tol = 1e-9;
  std::vector<int> pulled, side;
  for (int i = 0; i < n; ++i) {
    const Vec3& x = net.nodes[i];
    if (x.x() < tol) p.fixed[3 * i] = 1;
    if (x.x() > kSide - tol) {
      p.fixed[3 * i] = 1;
      p.rest[3 * i] += strain * kSide;
      pulled.push_back(i);
    }
    if (x.y() < tol) p.fixed[3 * i + 1] = 1;
    if (x.z() < tol) p.fixed[3 * i + 2] = 1;
    if (x.y() > kSide - tol) side.push_back(i);
  }
  StaticOptions o;
  o.force_scale = 1e-4;  // N, the order of the reaction (E·ε·L²)
  const StaticResult r = solve_static(p, o);
  Eigen::VectorXd g;
  model.gradient(r.x, g);
  double reaction = 0.0;
  for (int i : pulled) reaction += g[3 * i];
  double uy = 0.0;
  for (int i : side) uy += r.x[3 * i + 1] - net.nodes[i].y();
  uy /= static_cast<double>(side.size());
  return {reaction / (kSide * kSide) / strain, -(uy / kSide) / strain};
}

}  // namespace

TEST(EffectiveModuli, VolumeModelOfACubeObeysTheCauchyRelation) {
  const TetMesh mesh = cube_mesh(0.8e-3);
  ASSERT_GT(mesh.tets.size(), 1000u);
  const double E = 14.24e3;
  std::map<std::string, Moduli> m;
  for (StiffnessRule rule :
       {StiffnessRule::seed000, StiffnessRule::seed001, StiffnessRule::van_gelder,
        StiffnessRule::lloyd, StiffnessRule::uniform}) {
    for (double nu : {0.0, 0.25, 0.45}) {
      if (rule != StiffnessRule::lloyd && nu != 0.25) continue;  // only lloyd reads ν
      SpringNetwork net = build_volume_network(mesh);
      StiffnessParams sp;
      sp.youngs_modulus = E;
      sp.poisson_ratio = nu;
      assign_stiffness(net, rule, sp);
      char suffix[16] = "";
      if (rule == StiffnessRule::lloyd) std::snprintf(suffix, sizeof suffix, "(nu=%.2f)", nu);
      const std::string key = to_string(rule) + suffix;
      m[key] = measure(net, 1e-4);
      std::printf(
          "cube %zu nodes %zu tets, rule %-16s E_eff = %8.1f Pa (E_eff/E = %.3f), nu_eff = %.3f\n",
          mesh.nodes.size(), mesh.tets.size(), key.c_str(), m[key].E, m[key].E / E, m[key].nu);
    }
  }
  // Linearity: seed001's k is exactly a third of van_gelder's, so is its modulus; ν unchanged.
  EXPECT_NEAR(m["seed001"].E, m["van-gelder"].E / 3, 1e-6 * m["van-gelder"].E);
  EXPECT_NEAR(m["seed001"].nu, m["van-gelder"].nu, 1e-6);
  // Cauchy relation: networks whose k depends on geometry only (not on ν) sit near ν = 1/4,
  // whatever ν is asked for (the unstructured cube is nearly, not exactly, isotropic and has
  // free faces, hence the tolerance).
  for (const auto& key :
       {"seed001", "van-gelder", "lloyd(nu=0.25)", "lloyd(nu=0.45)", "lloyd(nu=0.00)"}) {
    ASSERT_TRUE(m.count(key)) << key;
    EXPECT_NEAR(m[key].nu, 0.25, 0.06) << key;
  }
  // The rules meant to reproduce E at the Cauchy point do so within the free-face error.
  EXPECT_NEAR(m["lloyd(nu=0.25)"].E / E, 1.0, 0.15);
  EXPECT_NEAR(m["van-gelder"].E / E, 1.0, 0.15);
}
