// The assembled SpringModel against finite differences of its energy, momentum conservation and
// rigid-motion invariance; problem assembly on a vessel mesh against the shared load totals.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "finite_differences.hpp"
#include "meshes/gmsh_vessel.hpp"
#include "meshes/surface_loads.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/stiffness/stiffness_rules.hpp"

using namespace vessel;
using namespace vessel::msm;
using vessel::msm::test::check_derivatives;

namespace {

/// A 2×2×2 block of 8 cube corners split into 6 tets plus a triangle surface: small networks
/// with every family and both laws.
TetMesh small_tet_mesh() {
  TetMesh m;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) m.nodes.push_back(1e-3 * Vec3(i, j, k));
  // Kuhn split of the unit cube along the 0-7 diagonal.
  m.tets = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  orient_tets(m);
  for (auto& t : m.tets) {
    if (signed_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]) < 0)
      std::swap(t[2], t[3]);
  }
  return m;
}

SpringNetwork surface_strip() {
  TriangleSurface s;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) s.nodes.push_back(1e-3 * Vec3(i, j, 0.1 * i * j));
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i;
      s.triangles.push_back({a, a + 1, a + 4});
      s.triangles.push_back({a, a + 4, a + 3});
    }
  return build_triangle_network(s, 1e-3, true);
}

Eigen::VectorXd perturbed(const SpringNetwork& net, std::mt19937& rng, double amplitude) {
  std::normal_distribution<double> n(0.0, amplitude);
  Eigen::VectorXd x = flatten(net.nodes);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += n(rng);
  return x;
}

void check_model(const SpringModel& model, const Eigen::VectorXd& x) {
  auto E = [&](const Eigen::VectorXd& y) { return model.energy(y); };
  auto G = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd {
    Eigen::VectorXd g;
    model.gradient(y, g);
    return g;
  };
  auto H = [&](const Eigen::VectorXd& y) -> Eigen::MatrixXd {
    SparseMatrix h;
    model.hessian(y, h, false);
    return Eigen::MatrixXd(h);
  };
  const auto c = check_derivatives(E, G, H, x, 1e-9);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-5);
  EXPECT_LT(c.hessian_asymmetry, 1e-14);
}

}  // namespace

TEST(SpringModel, VolumeAndSurfaceModelsMatchFiniteDifferencesAtRandomStates) {
  std::mt19937 rng(7);
  SpringNetwork vol = build_volume_network(small_tet_mesh());
  StiffnessParams p;
  assign_stiffness(vol, StiffnessRule::seed001, p);
  SpringNetwork surf = surface_strip();
  assign_stiffness(surf, StiffnessRule::van_gelder, p);
  // Bilinear laws too (seed 001 eq. 1), threshold 2 % strain, k2 = 3 k1.
  SpringNetwork bil = vol;
  p.bilinear_ratio = 3.0;
  p.bilinear_threshold_strain = 0.02;
  assign_stiffness(bil, StiffnessRule::seed001, p);
  for (int trial = 0; trial < 10; ++trial) {
    check_model(SpringModel(vol), perturbed(vol, rng, 0.1e-3));
    check_model(SpringModel(surf), perturbed(surf, rng, 0.1e-3));
    check_model(SpringModel(bil), perturbed(bil, rng, 0.1e-3));
  }
}

TEST(SpringModel, InternalForcesConserveMomentumAndAreInvariantUnderRigidMotion) {
  std::mt19937 rng(8);
  SpringNetwork net = build_volume_network(small_tet_mesh());
  assign_stiffness(net, StiffnessRule::van_gelder, StiffnessParams{});
  const SpringModel model(net);
  const Eigen::VectorXd x = perturbed(net, rng, 0.2e-3);
  Eigen::VectorXd g;
  model.gradient(x, g);
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) {
    force += g.segment<3>(3 * i);
    torque += Vec3(x.segment<3>(3 * i)).cross(Vec3(g.segment<3>(3 * i)));
  }
  EXPECT_LT(force.norm(), 1e-14 * g.norm());
  EXPECT_LT(torque.norm(), 1e-14 * g.norm() * 1e-3);
  // Rigid motion: energy unchanged, gradient rotated.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 t(0.01, -0.02, 0.03);
  Eigen::VectorXd y(x.size());
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) y.segment<3>(3 * i) = R * x.segment<3>(3 * i) + t;
  EXPECT_NEAR(model.energy(y), model.energy(x), 1e-12 * model.energy(x));
  Eigen::VectorXd gy;
  model.gradient(y, gy);
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) {
    EXPECT_LT((gy.segment<3>(3 * i) - R * g.segment<3>(3 * i)).norm(), 1e-10 * g.norm());
  }
}

TEST(SpringModel, DampingForcesAreDissipativeAndTheJacobianIsExact) {
  std::mt19937 rng(9);
  SpringNetwork net = surface_strip();
  assign_stiffness(net, StiffnessRule::seed000, StiffnessParams{});
  for (auto& s : net.springs) s.damping = 0.01;
  const SpringModel model(net, 0.002);
  const Eigen::VectorXd x = perturbed(net, rng, 0.1e-3);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::VectorXd v(x.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = n(rng);
  Eigen::VectorXd f;
  model.damping_force(x, v, f);
  EXPECT_LT(f.dot(v), 0.0);
  SparseMatrix D;
  model.damping_jacobian(x, D);
  EXPECT_LT((f + D * v).norm(), 1e-12 * f.norm());  // f is linear in v: f = −D v
}

TEST(SpringModel, ProblemOnTheVesselCarriesTheSharedContactLoadAndFixesTheEnds) {
  const VesselParams params;
  const TetMesh mesh = generate_vessel_mesh(params);
  ContactPatchSpec spec;
  spec.point = Vec3(3e-3, 0, 20e-3);
  spec.force = 0.05;
  const auto loads = traction_nodal_loads(mesh, contact_patch(mesh, spec));
  const Vec3 total = total_load(loads);
  for (WallSurface w : {WallSurface::inner, WallSurface::mid, WallSurface::outer}) {
    SpringNetwork net = build_triangle_network(wall_surface(mesh, params, w), 1e-3);
    assign_stiffness(net, StiffnessRule::seed000, StiffnessParams{});
    const SpringModel model(net);
    const auto m = nodal_masses(net, MassRule::consistent, kVesselDensity);
    const Problem p = make_problem(model, net, m, mesh, loads, {"inlet", "outlet"});
    Vec3 sum = Vec3::Zero();
    for (Eigen::Index i = 0; i < p.num_dofs() / 3; ++i) sum += p.external_force.segment<3>(3 * i);
    EXPECT_LT((sum - total).norm(), 1e-15);
    int fixed = 0;
    for (Eigen::Index i = 0; i < p.num_dofs() / 3; ++i) {
      if (p.fixed[3 * i]) {
        ++fixed;
        const double z = p.rest[3 * i + 2];
        EXPECT_TRUE(std::abs(z) < 1e-9 || std::abs(z - 40e-3) < 1e-9);
      }
    }
    EXPECT_GT(fixed, 20);
  }
  SpringNetwork vol = build_volume_network(mesh);
  assign_stiffness(vol, StiffnessRule::seed001, StiffnessParams{});
  const SpringModel model(vol);
  const Problem p = make_problem(model, vol, nodal_masses(vol, MassRule::consistent, 1060.0), mesh,
                                 loads, {"inlet", "outlet"});
  EXPECT_NEAR(p.external_force.sum(), total.sum(), 1e-15);
  EXPECT_NEAR(p.mass.sum() / 3, 1060.0 * mesh_volume(mesh), 1e-12);
}

TEST(SpringModel, ConsistentMassesTimesGravityEqualTheSharedBodyForceLoads) {
  // The CLI's --gravity applies m_i·g; for the volume model with consistent masses this must be
  // the shared body_force_nodal_loads (ρV/4 per tet vertex) node by node.
  const TetMesh mesh = generate_vessel_mesh(VesselParams{});
  const SpringNetwork net = build_volume_network(mesh);
  const double rho = kVesselDensity;
  const auto m = nodal_masses(net, MassRule::consistent, rho);
  const Vec3 g(0, -9.81, 0);
  const auto shared = body_force_nodal_loads(mesh, rho * g);
  double worst = 0.0;
  for (std::size_t i = 0; i < m.size(); ++i) worst = std::max(worst, (m[i] * g - shared[i]).norm());
  EXPECT_LT(worst, 1e-18);
}
