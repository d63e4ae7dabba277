// The guidewire's scene as a whole is in equilibrium: the wire's clamp reaction plus the vessel's
// support reactions (a volume mass-spring model under the wire's patch load, solved statically)
// sum to zero. Both reactions are computed from the solved states' internal forces at the held
// dofs, independently of the loads that were applied.
#include <gtest/gtest.h>

#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/static_solver.hpp"
#include "test_paths.hpp"
#include "verification/guidewire/guidewire_load.hpp"
#include "verification/harness/harness.hpp"
#include "verification/scene.hpp"
#include "verification/scene_problems.hpp"

using namespace vessel;

namespace {

TEST(GuidewireReactions, WireClampAndVesselSupportsSumToZero) {
  for (const char* file : {"guidewire_straight.toml", "guidewire_arch.toml"}) {
    Scene s = read_scene(std::string(VESSEL_SCENES_DIR) + "/" + file);
    solve_guidewire_load(s);
    const TetMesh mesh = scene_mesh(s, 0, "");
    const ModelSpec* spec = nullptr;
    for (const ModelSpec& m : s.models) {
      if (m.name == "volume_mollemans") spec = &m;
    }
    ASSERT_NE(spec, nullptr);
    const msm::BuiltNetwork built = scene_network(s, *spec, mesh, s.vessel, 0.45);
    const auto model = msm::make_model(built);
    const msm::Problem p = msm_problem(s, *model, built, mesh, s.load.magnitudes.at(0));
    msm::StaticOptions options;
    options.tolerance = 1e-12;
    const msm::StaticResult r = msm::solve_static(p, options);
    ASSERT_TRUE(r.converged);
    // The supports' force on the vessel at each held dof: ∇E − f_ext there.
    Eigen::VectorXd g;
    model->gradient(r.x, g);
    Vec3 supports = Vec3::Zero();
    for (int i = 0; i < p.num_dofs(); ++i) {
      if (p.fixed[i]) supports[i % 3] += g[i] - p.external_force[i];
    }
    const Vec3 clamp = s.load.wire.value().clamp_force;
    const Vec3 sum = clamp + supports;
    std::printf(
        "GUIDEWIRE %s: clamp (%.3e, %.3e, %.3e) N, supports (%.3e, %.3e, %.3e) N, |sum| %.2e N\n",
        file, clamp.x(), clamp.y(), clamp.z(),
        supports.x(), supports.y(), supports.z(), sum.norm());
    // The patch pushes along the wire's normal (the exact lumen's), not the faceted wall's mean
    // normal, which at the arch's apex parts from it by ~5e-6 rad (a 1e-8 N imbalance).
    EXPECT_LT(sum.norm(), 1e-9) << file;
  }
}

// The harness's compliant coupling on a real wall: the model's compliance C_v comes from its own
// solve in the run (its indentation under the rigid wire's patch), the wire's C_r from the wire's
// solves; two springs in series give F = F_rigid·C_r/(C_r + C_v) within 1e-3 (the floppy wire,
// C_v/C_r ≈ 0.08, where both are near linear).
TEST(GuidewireCouplingRun, ModelForceIsTheSeriesSpringsOnTheModelsOwnCompliance) {
  Scene s = read_scene(std::string(VESSEL_SCENES_DIR) + "/guidewire_straight.toml");
  solve_guidewire_load(s);
  s.reference_level = 0;
  std::vector<ModelSpec> keep;
  for (const ModelSpec& m : s.models) {
    if (m.name == "volume_hybrid") keep.push_back(m);
  }
  s.models = keep;
  s.load.guidewire->stiffness_sweep.clear();
  s.load.guidewire->coupling = GuidewireCoupling::compliant;  // the series springs alone
  const SceneResult r = run_scene(s, HarnessOptions{});
  ASSERT_TRUE(r.guidewire.has_value());
  ASSERT_EQ(r.guidewire->rows.size(), 1u);
  const GuidewireCouplingRow& row = r.guidewire->rows[0];
  ASSERT_TRUE(row.ok) << row.failure;
  const GuidewireRigid& wire = r.guidewire->rigid.at(0);
  const double series =
      wire.solution.force * wire.wire_compliance / (wire.wire_compliance + row.wall_compliance);
  std::printf("GUIDEWIRE volume_hybrid: C_v %.4f m/N, C_r %.4f m/N, F %.6e N, series %.6e N\n",
              row.wall_compliance, wire.wire_compliance, row.force_mN * 1e-3, series);
  EXPECT_NEAR(row.force_mN * 1e-3 / series, 1.0, 1e-3);

  // C_v against a separate static solve of the same model under the same patch load: the
  // work-conjugate indentation per unit force, Σ f·u / F² (F = |Σ f|).
  ASSERT_EQ(s.load.magnitudes.size(), 1u);
  const TetMesh mesh = scene_mesh(s, row.level, "");
  const msm::BuiltNetwork built = scene_network(s, keep[0], mesh, s.vessel, row.poisson_ratio);
  const auto model = msm::make_model(built);
  const msm::Problem p = msm_problem(s, *model, built, mesh, s.load.magnitudes[0]);
  msm::StaticOptions options;
  options.tolerance = 1e-12;
  const msm::StaticResult solved = msm::solve_static(p, options);
  ASSERT_TRUE(solved.converged);
  Vec3 total = Vec3::Zero();
  double work = 0.0;
  for (int i = 0; i < p.num_dofs(); ++i) {
    total[i % 3] += p.external_force[i];
    work += p.external_force[i] * (solved.x[i] - p.rest[i]);
  }
  const double compliance = work / total.squaredNorm();
  std::printf("GUIDEWIRE volume_hybrid: C_v from a separate static solve %.6f m/N\n", compliance);
  EXPECT_NEAR(row.wall_compliance / compliance, 1.0, 1e-6);
}

}  // namespace
