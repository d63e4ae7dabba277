// The homogenised hybrid volume model (msm/terms/volume_term_homogenised.hpp): each tet's
// stability limit against hand-derived values, the traction homogenisation of a single tet against
// its strain-space stiffness (E_s·G + κ·m mᵀ, derived independently here), positive-definiteness
// detection at the analytic limit, the fit's refusals, and the per-tet κ factors in the energy
// (finite differences) and in a region of interest.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "finite_differences.hpp"
#include "meshes/foundation/errors.hpp"
#include "msm/kernels/spring_kernels.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/model/roi.hpp"
#include "msm/terms/volume_term.hpp"
#include "msm/terms/volume_term_homogenised.hpp"
#include "tests/fixtures/kuhn_block.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// The tet's springs' strain-space stiffness per unit E_s and volume: Σ_edges w wᵀ with
/// w = (d_x², d_y², d_z², √2 d_y d_z, √2 d_x d_z, √2 d_x d_y), so that wᵀε = dᵀεd (Mandel).
Mat6 spring_strain_matrix(const std::array<Vec3, 4>& x) {
  Mat6 G = Mat6::Zero();
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const Vec3 d = (x[j] - x[i]).normalized();
      Vec6 w;
      w << d.x() * d.x(), d.y() * d.y(), d.z() * d.z(), std::sqrt(2.0) * d.y() * d.z(),
          std::sqrt(2.0) * d.x() * d.z(), std::sqrt(2.0) * d.x() * d.y();
      G += w * w.transpose();
    }
  }
  return G;
}

std::array<Vec3, 4> regular_tet(double a) {
  // Alternate corners of a cube of side a/√2: edge a.
  const double s = a / std::sqrt(2.0);
  return {Vec3(0, 0, 0), Vec3(s, s, 0), Vec3(s, 0, s), Vec3(0, s, s)};
}

/// An n×n×n block of cubes of side h, each cut into six tets (Kuhn), positively oriented.
TetMesh block_mesh(int n, double h) { return vessel::test::kuhn_block(n, n, n, h); }

}  // namespace

TEST(VolumeTermHomogenised, StabilityLimitMatchesHandDerivedValues) {
  // Regular tet: its six edges are a cube's face diagonals; by symmetry the cheapest unit volume
  // strain is ε = I/3, every edge strain 1/3, energy Σ = 6/9 = 2/3 (the springs' bulk modulus
  // 2E_s/3): c = −2/3.
  EXPECT_NEAR(volume_stability_limit(regular_tet(1e-3)), -2.0 / 3.0, 1e-12);
  // Corner tet (0, e1, e2, e3): the axis edges see ε_ii, the face diagonals (ε_ii + ε_jj)/2 − ε_ij,
  // which the shear ε_ij zeroes; min Σ ε_ii² at Σ ε_ii = 1 is 1/3: c = −1/3.
  const std::array<Vec3, 4> corner{Vec3(0, 0, 0), Vec3(1e-3, 0, 0), Vec3(0, 1e-3, 0),
                                   Vec3(0, 0, 1e-3)};
  EXPECT_NEAR(volume_stability_limit(corner), -1.0 / 3.0, 1e-12);
  // Scale- and rotation-free; a sliver's limit goes to 0 (its volume changes at first order under
  // motions that barely stretch its edges).
  EXPECT_NEAR(volume_stability_limit(regular_tet(7.0)), -2.0 / 3.0, 1e-12);
  const std::array<Vec3, 4> sliver{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0.9, 0),
                                   Vec3(0.5, 0.3, 0.01)};
  EXPECT_GT(volume_stability_limit(sliver), -0.01);
  EXPECT_LT(volume_stability_limit(sliver), 0.0);
}

TEST(VolumeTermHomogenised, SingleTetComplianceIsTheInverseOfItsStrainSpaceStiffness) {
  // One tet is affine: its mean strain is its strain, its springs store ½E_s·V·εᵀGε and its volume
  // term ½κV(m·ε)², so the traction-homogenised compliance must be (E_s·G + κ·m mᵀ)⁻¹ exactly.
  const std::array<Vec3, 4> x{Vec3(0, 0, 0), Vec3(1e-3, 0.1e-3, 0), Vec3(0.2e-3, 0.9e-3, 0.1e-3),
                              Vec3(0.1e-3, 0.3e-3, 1.1e-3)};
  const std::vector<Vec3> nodes(x.begin(), x.end());
  const TractionHomogenisation h(nodes, {Tet{0, 1, 2, 3}});
  const Mat6 G = spring_strain_matrix(x);
  Vec6 m;
  m << 1, 1, 1, 0, 0, 0;
  const double Es = 2.0e4;
  const double c = volume_stability_limit(x);
  for (double kappa : {0.0, 3.0e4, 0.9 * c * Es}) {
    const auto got = h.moduli(Es, kappa);
    ASSERT_TRUE(got.has_value()) << kappa;
    const Mat6 expected = (Es * G + kappa * m * m.transpose()).inverse();
    EXPECT_LT((got->compliance - expected).norm(), 1e-9 * expected.norm()) << "κ = " << kappa;
  }
  // Positive definiteness is detected at the analytic limit κ = c·E_s.
  EXPECT_TRUE(h.moduli(Es, 0.99 * c * Es).has_value());
  EXPECT_FALSE(h.moduli(Es, 1.01 * c * Es).has_value());
  // A per-tet factor multiplies κ.
  const auto halved = h.moduli(Es, 3.0e4, {0.5});
  ASSERT_TRUE(halved.has_value());
  const Mat6 expected = (Es * G + 1.5e4 * m * m.transpose()).inverse();
  EXPECT_LT((halved->compliance - expected).norm(), 1e-9 * expected.norm());
}

TEST(VolumeTermHomogenised, FitHitsItsOwnTargetAndRefusesWhatItCannotReach) {
  const TetMesh mesh = block_mesh(3, 1e-3);
  const double E = 14.24e3;
  for (double nu : {0.3, 0.45}) {
    const HomogenisedModuli h = homogenised_moduli(mesh.nodes, mesh.tets, E, nu);
    EXPECT_NEAR(h.achieved.youngs_modulus / E, 1.0, 1e-9);
    EXPECT_NEAR(h.achieved.poisson_ratio, nu, 1e-5);
    EXPECT_GT(h.spring_youngs_modulus, 0.0);
    EXPECT_TRUE(h.tet_factors.empty());  // κ > 0: no clip
    // Re-measured at the fitted (E_s, κ): the fit's answer, not a scaled copy.
    const TractionHomogenisation t(mesh.nodes, mesh.tets);
    const auto again = t.moduli(h.spring_youngs_modulus, h.kappa);
    ASSERT_TRUE(again.has_value());
    EXPECT_NEAR(again->youngs_modulus / E, 1.0, 1e-9);
    EXPECT_NEAR(again->poisson_ratio, nu, 1e-5);
  }
  auto message = [&](double E_, double nu) {
    try {
      (void)homogenised_moduli(mesh.nodes, mesh.tets, E_, nu);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(E, 0.5).find("κ is infinite"), std::string::npos) << message(E, 0.5);
  // (ν below a mesh's floor: EffectiveModuli.HomogenisedVolumeModelHitsTheTargetModuli, on the
  // gmsh cube; this structured block's springs alone sit below ν = 0.)
  EXPECT_NE(message(-1.0, 0.3).find("E > 0"), std::string::npos);
  EXPECT_NE(message(E, -0.1).find("[0, 0.5)"), std::string::npos);
}

TEST(VolumeTermHomogenised, PerTetFactorsEnterTheEnergyAndSurviveARegionOfInterest) {
  // A 3×3×3 Kuhn block with its interior nodes moved by up to 0.3 h: irregular tets, some of them
  // too flat for the fitted negative κ (clipped).
  TetMesh mesh = block_mesh(3, 1e-3);
  std::mt19937 shake(11);
  std::uniform_real_distribution<double> jitter(-0.3e-3, 0.3e-3);
  for (Vec3& p : mesh.nodes) {
    const bool interior = p.minCoeff() > 1e-9 && p.maxCoeff() < 3e-3 - 1e-9;
    if (interior) p += Vec3(jitter(shake), jitter(shake), jitter(shake));
  }
  NetworkOptions o;
  o.model = ModelType::volume;
  o.stiffness = StiffnessRule::van_gelder;
  o.stiffness_params.youngs_modulus = 14.24e3;
  o.stiffness_params.poisson_ratio = 0.0;  // κ < 0: clipped per tet
  o.volume_term = true;
  o.volume_moduli = VolumeModuli::homogenised;
  const BuiltNetwork built = build_network(mesh, VesselParams{}, o);
  ASSERT_TRUE(built.terms.volume_kappa.has_value());
  EXPECT_LT(*built.terms.volume_kappa, 0.0);
  ASSERT_EQ(built.network.tet_kappa_factors.size(), built.network.tets.size());
  const HomogenisedModuli h = homogenised_moduli(mesh.nodes, mesh.tets, 14.24e3, 0.0);
  EXPECT_NEAR(*built.terms.volume_kappa, h.kappa, 1e-12 * std::abs(h.kappa));
  const auto model = make_model(built);
  const VolumeTerm& v = *model->term<VolumeTerm>();
  // Each tet's κ is κ·f_e = max(κ, kStabilityMargin·c_e·E_s): never below the clip.
  bool some_clipped = false;
  for (std::size_t e = 0; e < v.tets().size(); ++e) {
    const Tet& t = v.tets()[e];
    const double c = volume_stability_limit(
        {mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]});
    EXPECT_NEAR(v.tet_kappa(e), *built.terms.volume_kappa * built.network.tet_kappa_factors[e],
                1e-12 * std::abs(*built.terms.volume_kappa));
    some_clipped = some_clipped || built.network.tet_kappa_factors[e] < 1.0;
    EXPECT_NEAR(v.tet_kappa(e),
                std::max(*built.terms.volume_kappa, kStabilityMargin * c * h.spring_youngs_modulus),
                1e-9 * std::abs(*built.terms.volume_kappa));
  }
  EXPECT_TRUE(some_clipped);
  // The model's energy with the factors against finite differences.
  std::mt19937 rng(5);
  Eigen::VectorXd x = flatten(built.network.nodes);
  std::uniform_real_distribution<double> u(-0.03e-3, 0.03e-3);
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] += u(rng);
  const auto c = msm::test::check_form_derivatives(*model, x, 1e-9);
  EXPECT_LT(c.gradient_error, 1e-6);
  EXPECT_LT(c.hessian_error, 1e-6);
  // At rest the assembled Hessian (no projection) is positive definite on the non-rigid motions:
  // every tet's springs-plus-volume block is, by the clip.
  SparseMatrix H;
  model->hessian(flatten(built.network.nodes), H, false);
  const Eigen::VectorXd eig =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(H)).eigenvalues();
  EXPECT_NEAR(eig[5] / eig[eig.size() - 1], 0.0, 1e-10);  // six rigid motions
  EXPECT_GT(eig[6] / eig[eig.size() - 1], 1e-6);
  // A region of interest carries the factors of the tets it keeps.
  std::vector<char> held(built.network.nodes.size(), 0);
  for (std::size_t i = 0; i < held.size(); ++i) held[i] = built.network.nodes[i].z() < 1.5e-3;
  const RoiNetwork roi = restrict_network(built.network, held, false);
  ASSERT_EQ(roi.network.tet_kappa_factors.size(), roi.network.tets.size());
  ASSERT_LT(roi.network.tets.size(), built.network.tets.size());
  const auto roi_model = make_model(roi.network, {.volume_kappa = built.terms.volume_kappa});
  // The ROI's energy at a displacement of the moving nodes equals the full model's minus the
  // held tets' (zero: held nodes stay at rest) — so compare both at the same moved state.
  Eigen::VectorXd full = flatten(built.network.nodes);
  Eigen::VectorXd part = flatten(roi.network.nodes);
  for (std::size_t r = 0; r < roi.full_index.size(); ++r) {
    const int f = roi.full_index[r];
    if (held[f]) continue;
    full.segment<3>(3 * f) += Vec3(1e-5, -2e-5, 3e-5) * (1 + 0.1 * static_cast<double>(r % 7));
    part.segment<3>(3 * static_cast<int>(r)) = full.segment<3>(3 * f);
  }
  EXPECT_NEAR(roi_model->term<VolumeTerm>()->energy(part), model->term<VolumeTerm>()->energy(full),
              1e-9 * std::abs(model->term<VolumeTerm>()->energy(full)));
}
