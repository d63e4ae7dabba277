// The linearised stiffness fit (msm/calibration/stiffness_fit): its stiffness matrix against the
// model's own Hessian at rest, the adjoint gradient against central finite differences of the
// objective, and the recovery of stiffness factors planted in synthetic data that the nonlinear
// model generated with them (the planted factors are the independent truth).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <algorithm>
#include <numbers>
#include <limits>
#include <random>

#include "meshes/foundation/errors.hpp"
#include "msm/calibration/lbfgs.hpp"
#include "msm/calibration/stiffness_fit.hpp"
#include "msm/model/build_network.hpp"
#include "msm/model/mass_spring_model.hpp"
#include "msm/solvers/solve.hpp"
#include "tests/fixtures/kuhn_block.hpp"

using namespace vessel;
using namespace vessel::msm;

namespace {

constexpr double kE = 14.24e3;

/// An n×n×n block of cubes of side h (Kuhn's six tets each), shifted to x ≥ 3 mm so that the
/// straight vessel's centreline frame (radial from the z axis) is defined everywhere.
TetMesh block_mesh(int n, double h) {
  return vessel::test::kuhn_block(n, n, n, h, Vec3(3e-3, 0.0, 0.0));
}

BuiltNetwork hybrid(const TetMesh& mesh, double nu) {
  NetworkOptions o;
  o.model = ModelType::volume;
  o.stiffness = StiffnessRule::van_gelder;
  o.stiffness_params.youngs_modulus = kE;
  o.stiffness_params.poisson_ratio = nu;
  o.volume_term = true;
  return build_network(mesh, VesselParams{}, o);
}

/// The bottom face (z = 0) held.
std::vector<char> bottom_fixed(const SpringNetwork& net) {
  std::vector<char> fixed(3 * net.nodes.size(), 0);
  for (std::size_t i = 0; i < net.nodes.size(); ++i) {
    if (net.nodes[i].z() < 1e-9) fixed[3 * i] = fixed[3 * i + 1] = fixed[3 * i + 2] = 1;
  }
  return fixed;
}

/// Random forces (N) on the free nodes of the upper half.
Eigen::VectorXd random_load(const SpringNetwork& net, std::mt19937& rng, double scale) {
  std::normal_distribution<double> g;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(net.nodes.size()));
  for (std::size_t i = 0; i < net.nodes.size(); ++i) {
    if (net.nodes[i].z() < 1.5e-3) continue;
    for (int c = 0; c < 3; ++c) f[3 * static_cast<Eigen::Index>(i) + c] = scale * g(rng);
  }
  return f;
}

/// The nonlinear model's static answer u = x − x0 (m, per dof) under f.
Eigen::VectorXd static_displacement(const BuiltNetwork& built, const std::vector<char>& fixed,
                                    const Eigen::VectorXd& f) {
  const auto model = make_model(built);
  Problem p;
  p.form = model.get();
  p.rest = flatten(built.network.nodes);
  p.external_force = f;
  p.mass = Eigen::VectorXd::Ones(p.rest.size());
  p.fixed = fixed;
  const SolveResult r = solve(p, parse_solver("static"));
  return r.x - p.rest;
}

/// An arch of bend radius 2 mm about the z axis whose wall (ρ = 1.2–3.2 mm) covers block_mesh's
/// nodes (x ≥ 3 mm, y, z ≥ 0): 1–3.9 mm from its centreline circle.
VesselParams bend_around_block() {
  VesselParams v;
  v.kind = VesselKind::arch;
  v.bend_radius = 2e-3;
  v.inner_radius = 1.2e-3;
  v.wall_thickness = 2.0e-3;
  return v;
}

/// The arch the hand-placed spring tests use: R = 15 mm, inner radius 3 mm, wall 1 mm.
VesselParams hand_placed_arch() {
  VesselParams arch;
  arch.kind = VesselKind::arch;
  arch.bend_radius = 15e-3;
  arch.inner_radius = 3e-3;
  arch.wall_thickness = 1e-3;
  return arch;
}

}  // namespace

TEST(StiffnessFit, LinearisedStiffnessIsTheModelsHessianAtRest) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  const StiffnessParameters params = group_parameters(built.network, VesselParams{}, true);
  std::mt19937 rng(1);
  const Eigen::VectorXd f = random_load(built.network, rng, 1e-6);
  const LinearisedFit fit(built.network, built.terms.volume_kappa, fixed, params,
                          {{"c", f, Eigen::VectorXd::Ones(f.size())}});
  const SparseMatrix K = fit.stiffness(Eigen::VectorXd::Zero(params.size()));
  const auto model = make_model(built);
  SparseMatrix H;
  model->hessian(flatten(built.network.nodes), H, false);
  const Eigen::MatrixXd Hd(H);
  std::vector<int> free;
  for (std::size_t i = 0; i < fixed.size(); ++i) {
    if (!fixed[i]) free.push_back(static_cast<int>(i));
  }
  const Eigen::MatrixXd Kd(K);
  ASSERT_EQ(Kd.rows(), static_cast<Eigen::Index>(free.size()));
  double worst = 0.0;
  for (std::size_t i = 0; i < free.size(); ++i) {
    for (std::size_t j = 0; j < free.size(); ++j) {
      worst = std::max(worst, std::abs(Kd(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) -
                                       Hd(free[i], free[j])));
    }
  }
  EXPECT_LT(worst, 1e-9 * Hd.cwiseAbs().maxCoeff());
}

TEST(StiffnessFit, AdjointGradientMatchesFiniteDifferences) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  std::mt19937 rng(5);
  std::vector<FitCase> cases;
  for (int c = 0; c < 2; ++c) {
    const Eigen::VectorXd f = random_load(built.network, rng, 1e-6);
    Eigen::VectorXd r = static_displacement(built, fixed, 1.3 * f);  // a different stiffness
    for (Eigen::Index i = 0; i < r.size(); ++i) {
      if (!fixed[static_cast<std::size_t>(i)]) r[i] += 1e-8 * std::sin(1.0 + i);
    }
    cases.push_back({"case" + std::to_string(c), f, r, c == 0 ? 1.0 : 2.5});  // unequal weights
  }
  // The block sits at ρ = 3–5 mm from the straight tube's axis: with a 1 mm wall from ρ = 3.5 mm
  // every layer (inner, middle, outer; κ inner and outer half) is populated.
  VesselParams wall;
  wall.inner_radius = 3.5e-3;
  wall.wall_thickness = 1.0e-3;
  // Per section spring (granularity 6) on an arch of bend radius 2 mm round the block.
  const VesselParams bend = bend_around_block();
  // Granularity 5: per spring with κ per half of the wall and a regulariser centred on random
  // log factors (a per-spring fit on top of a class calibration).
  // Granularity 6: a factor per spring of a cross-section of the arch (bend), κ per half.
  for (const int granularity : {0, 1, 2, 3, 5, 6}) {
    const bool per_spring = granularity == 1 || granularity == 5 || granularity == 6;
    const StiffnessParameters params =
        granularity == 0   ? group_parameters(built.network, VesselParams{}, true)
        : granularity == 6 ? per_section_spring_parameters(built.network, bend, true, true)
        : granularity == 1 ? per_spring_parameters(built.network, true)
        : granularity == 5 ? per_spring_parameters(built.network, true, &wall)
                           : wall_layer_parameters(built.network, wall, true, granularity == 3);
    if (granularity >= 2) {
      ASSERT_FALSE(params.of_tet.empty());
      EXPECT_EQ(std::count(params.names.begin(), params.names.end(), "kappa/inner"), 1);
      EXPECT_EQ(std::count(params.names.begin(), params.names.end(), "kappa/outer"), 1);
    }
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    Regulariser reg = per_spring ? Regulariser{0.3, 1e-3, {}} : Regulariser{};
    if (granularity == 5) {
      ASSERT_EQ(params.of_tet.size(), built.network.tets.size());
      reg.centre.resize(params.size());
      for (Eigen::Index i = 0; i < reg.centre.size(); ++i) reg.centre[i] = u(rng);
    }
    const LinearisedFit fit(built.network, built.terms.volume_kappa, fixed, params, cases, reg);
    Eigen::VectorXd theta(params.size());
    for (Eigen::Index i = 0; i < theta.size(); ++i) theta[i] = u(rng);
    Eigen::VectorXd g;
    fit.objective(theta, g);
    const double h = 1e-6;
    int checked = 0;
    for (Eigen::Index p = 0; p < theta.size(); p += per_spring ? 7 : 1) {
      Eigen::VectorXd tp = theta, tm = theta, dummy;
      tp[p] += h;
      tm[p] -= h;
      const double fd = (fit.objective(tp, dummy) - fit.objective(tm, dummy)) / (2 * h);
      EXPECT_NEAR(g[p], fd, 1e-6 * std::abs(fd) + 1e-7 * g.lpNorm<Eigen::Infinity>())
          << (granularity == 0   ? "groups, "
              : granularity == 1 ? "per spring, "
              : granularity == 2 ? "wall layers, "
              : granularity == 3 ? "edge types, "
              : granularity == 5 ? "per spring from a centre, "
                                 : "per section spring, ")
          << params.names[static_cast<std::size_t>(p)];
      ++checked;
    }
    EXPECT_GT(checked, 5);
  }
}

namespace {

/// Data the nonlinear model generates with the `planted` factors (four random loads at strain
/// ~1e-5, i.e. linear), then the L-BFGS fit of those factors from zero: the fitted θ and the fit's
/// relative errors per case.
std::pair<Eigen::VectorXd, std::vector<double>> fit_planted_factors(
    const BuiltNetwork& built, const std::vector<char>& fixed, const StiffnessParameters& params,
    const Eigen::VectorXd& planted, unsigned seed, int max_iterations) {
  BuiltNetwork truth = built;
  apply_stiffness_factors(truth.network, truth.terms.volume_kappa, params, planted);
  std::mt19937 rng(seed);
  std::vector<FitCase> cases;
  for (int c = 0; c < 4; ++c) {
    const Eigen::VectorXd f = random_load(built.network, rng, 1e-7);
    cases.push_back({"case" + std::to_string(c), f, static_displacement(truth, fixed, f)});
  }
  const LinearisedFit fit(built.network, built.terms.volume_kappa, fixed, params, cases);
  const Objective f = [&](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    return fit.objective(x, g);
  };
  LbfgsOptions o;
  o.max_iterations = max_iterations;
  o.gradient_tolerance = 1e-12;
  const LbfgsResult r = minimize_lbfgs(f, Eigen::VectorXd::Zero(params.size()), o);
  return {r.x, fit.relative_errors(r.x)};
}

}  // namespace

TEST(StiffnessFit, RecoversPlantedGroupFactorsFromTheModelsOwnData) {
  const TetMesh mesh = block_mesh(3, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  const StiffnessParameters params = group_parameters(built.network, VesselParams{}, true);
  ASSERT_GE(params.size(), 5);  // several direction/boundary classes plus kappa
  // Planted factors: exp(θ*) from 0.5 to 2 across the classes.
  Eigen::VectorXd planted(params.size());
  for (Eigen::Index p = 0; p < planted.size(); ++p) {
    planted[p] = std::log(0.5) + std::log(4.0) * static_cast<double>(p) / (planted.size() - 1);
  }
  const auto [x, errors] = fit_planted_factors(built, fixed, params, planted, 11, 500);
  for (Eigen::Index p = 0; p < planted.size(); ++p) {
    EXPECT_NEAR(std::exp(x[p]), std::exp(planted[p]), 2e-3 * std::exp(planted[p]))
        << params.names[static_cast<std::size_t>(p)];
  }
  for (const double e : errors) EXPECT_LT(e, 1e-4);
}

// The wall-layer granularity, with its two κ halves, recovers factors planted in data the
// nonlinear model generated with them.
TEST(StiffnessFit, RecoversPlantedWallLayerFactorsFromTheModelsOwnData) {
  const TetMesh mesh = block_mesh(3, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  VesselParams wall;  // the block spans ρ = 3–6.7 mm: all three layers and both halves
  wall.inner_radius = 3.5e-3;
  wall.wall_thickness = 1.5e-3;
  const StiffnessParameters params = wall_layer_parameters(built.network, wall, true);
  ASSERT_GE(params.size(), 8);
  Eigen::VectorXd planted(params.size());
  for (Eigen::Index p = 0; p < planted.size(); ++p) {
    planted[p] = std::log(0.5) + std::log(4.0) * static_cast<double>((3 * p) % planted.size()) /
                                     (planted.size() - 1);
  }
  const auto [x, errors] = fit_planted_factors(built, fixed, params, planted, 13, 1000);
  for (Eigen::Index p = 0; p < planted.size(); ++p) {
    EXPECT_NEAR(std::exp(x[p]), std::exp(planted[p]), 5e-3 * std::exp(planted[p]))
        << params.names[static_cast<std::size_t>(p)];
  }
}

// The regulariser with a centre θ_c acts on δ = θ − θ_c: zero at the centre; for every spring
// shifted by the same c from it the smoothness term vanishes (each node's springs depart alike)
// and the ridge is β/(2P)·P·c² = β·c²/2 (hand-derived); and a per-spring fit on top of planted
// group factors, started at them, has nothing left to fit.
TEST(StiffnessFit, ARegulariserCentreMovesBothTermsToTheDepartureFromIt) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  const StiffnessParameters params = per_spring_parameters(built.network, true);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Regulariser reg{0.7, 0.3, Eigen::VectorXd(params.size())};
  for (Eigen::Index i = 0; i < reg.centre.size(); ++i) reg.centre[i] = u(rng);
  const Eigen::VectorXd f = random_load(built.network, rng, 1e-7);
  const LinearisedFit fit(built.network, built.terms.volume_kappa, fixed, params,
                          {{"c", f, static_displacement(built, fixed, f)}}, reg);
  EXPECT_NEAR(fit.regularisation(reg.centre), 0.0, 1e-15);
  const double c = 0.4;
  const Eigen::VectorXd shifted = reg.centre.array() + c;
  EXPECT_NEAR(fit.regularisation(shifted), 0.5 * 0.3 * c * c, 1e-12);
  Regulariser bad = reg;
  bad.centre.resize(3);
  EXPECT_THROW(LinearisedFit(built.network, built.terms.volume_kappa, fixed, params,
                             {{"c", f, static_displacement(built, fixed, f)}}, bad),
               InputError);

  // Data from planted group factors; the per-spring parameters at those factors fit it exactly.
  const StiffnessParameters groups = group_parameters(built.network, VesselParams{}, true);
  Eigen::VectorXd planted(groups.size());
  for (Eigen::Index p = 0; p < planted.size(); ++p) planted[p] = 0.3 * std::sin(1.0 + p);
  BuiltNetwork truth = built;
  apply_stiffness_factors(truth.network, truth.terms.volume_kappa, groups, planted);
  Eigen::VectorXd start(params.size());
  for (std::size_t s = 0; s < built.network.springs.size(); ++s) {
    start[params.of_spring[s]] = groups.spring_log_factor(planted, s);
  }
  start[params.kappa] = planted[groups.kappa];
  const LinearisedFit on_top(built.network, built.terms.volume_kappa, fixed, params,
                             {{"c", f, static_displacement(truth, fixed, f)}},
                             Regulariser{0.7, 0.3, start});
  EXPECT_LT(on_top.relative_errors(start)[0], 1e-3);  // linearised against nonlinear data (1e-4)
  EXPECT_GT(on_top.relative_errors(Eigen::VectorXd::Zero(params.size()))[0], 1e-2);
}

// Springs that are images of each other along the centreline share a factor, others do not:
// hand-placed springs on the arch (R = 15 mm) at two arch angles φ, on the outer bend and at the
// top of the section, along the tangent and radially, one with its ends swapped; and axial
// springs at two heights of the straight tube.
TEST(StiffnessFit, PerSectionSpringClassesAreImagesAlongTheCentreline) {
  const VesselParams arch = hand_placed_arch();
  const double h = 0.2e-3;
  SpringNetwork net;
  const auto add = [&](const Vec3& a, const Vec3& b) {
    net.nodes.push_back(a);
    net.nodes.push_back(b);
    Spring sp;
    sp.a = static_cast<int>(net.nodes.size()) - 2;
    sp.b = sp.a + 1;
    sp.family = SpringFamily::volume;
    net.springs.push_back(sp);
  };
  for (const double phi : {0.3, 1.1}) {
    const Vec3 outward(std::cos(phi), std::sin(phi), 0.0);
    const Vec3 tangent(-std::sin(phi), std::cos(phi), 0.0);
    const Vec3 centre = arch.bend_radius * outward;
    const Vec3 outer = centre + 3.5e-3 * outward, top = centre + 3.5e-3 * Vec3::UnitZ();
    add(outer - 0.5 * h * tangent, outer + 0.5 * h * tangent);   // 0, 4: tangent, outer bend
    add(top - 0.5 * h * tangent, top + 0.5 * h * tangent);       // 1, 5: tangent, top
    add(outer - 0.5 * h * outward, outer + 0.5 * h * outward);   // 2, 6: radial, outer bend
    if (phi < 1.0) {
      add(outer - 0.5 * h * outward, outer + 0.5 * h * outward);  // 3: as 2
    } else {
      add(outer + 0.5 * h * outward, outer - 0.5 * h * outward);  // 7: as 2, ends swapped
    }
  }
  const StiffnessParameters p = per_section_spring_parameters(net, arch, false, false);
  EXPECT_EQ(p.size(), 3);
  EXPECT_EQ(p.of_spring[0], p.of_spring[4]);
  EXPECT_EQ(p.of_spring[1], p.of_spring[5]);
  EXPECT_EQ(p.of_spring[2], p.of_spring[6]);
  EXPECT_EQ(p.of_spring[2], p.of_spring[3]);
  EXPECT_EQ(p.of_spring[2], p.of_spring[7]);
  EXPECT_NE(p.of_spring[0], p.of_spring[1]);
  EXPECT_NE(p.of_spring[0], p.of_spring[2]);
  // The straight tube: axial springs at z = 1 and 5 mm at the same (ρ, θ) share a factor; one
  // at another θ does not.
  SpringNetwork tube_net;
  net = tube_net;
  add(Vec3(3.5e-3, 0, 1e-3), Vec3(3.5e-3, 0, 1.2e-3));
  add(Vec3(3.5e-3, 0, 5e-3), Vec3(3.5e-3, 0, 5.2e-3));
  add(Vec3(0, 3.5e-3, 5e-3), Vec3(0, 3.5e-3, 5.2e-3));
  VesselParams tube = arch;
  tube.kind = VesselKind::straight;
  const StiffnessParameters q = per_section_spring_parameters(net, tube, false, false);
  EXPECT_EQ(q.of_spring[0], q.of_spring[1]);
  EXPECT_NE(q.of_spring[0], q.of_spring[2]);
}

// Factors planted per cross-section spring of the block (repeated along z on the straight tube:
// each height's springs are images of the others) are recovered from data the nonlinear model
// generated with them.
TEST(StiffnessFit, RecoversPlantedPerSectionSpringFactorsFromTheModelsOwnData) {
  const TetMesh mesh = block_mesh(3, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  VesselParams tube;
  tube.inner_radius = 3.5e-3;
  tube.wall_thickness = 1.5e-3;
  const StiffnessParameters params = per_section_spring_parameters(built.network, tube, true, false);
  ASSERT_LT(params.size(), static_cast<int>(built.network.springs.size()) / 2);  // shared along z
  Eigen::VectorXd planted(params.size());
  for (int p = 0; p < params.size(); ++p) planted[p] = 0.5 * std::sin(0.7 + 1.3 * p);  // 0.6–1.65
  const auto [x, errors] = fit_planted_factors(built, fixed, params, planted, 19, 3000);
  int checked = 0;
  for (int p = 0; p < params.size(); ++p) {
    EXPECT_NEAR(std::exp(x[p]), std::exp(planted[p]), 1e-2 * std::exp(planted[p]))
        << params.names[static_cast<std::size_t>(p)];
    ++checked;
  }
  EXPECT_GT(checked, 20);
  for (const double e : errors) EXPECT_LT(e, 1e-4);
}

TEST(StiffnessFit, PerSpringFitReducesTheMisfitOfPlantedData) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  const StiffnessParameters groups = group_parameters(built.network, VesselParams{}, true);
  Eigen::VectorXd planted = Eigen::VectorXd::Zero(groups.size());
  planted[0] = std::log(1.8);
  BuiltNetwork truth = built;
  apply_stiffness_factors(truth.network, truth.terms.volume_kappa, groups, planted);
  std::mt19937 rng(2);
  const Eigen::VectorXd f = random_load(built.network, rng, 1e-7);
  const LinearisedFit fit(built.network, built.terms.volume_kappa, fixed,
                          per_spring_parameters(built.network, true),
                          {{"c", f, static_displacement(truth, fixed, f)}}, Regulariser{1e-4, 1e-6, {}});
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(fit.parameters().size());
  const double before = fit.misfit(zero);
  const Objective obj = [&](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    return fit.objective(x, g);
  };
  LbfgsOptions o;
  o.max_iterations = 300;
  const LbfgsResult r = minimize_lbfgs(obj, zero, o);
  EXPECT_LT(fit.misfit(r.x), 1e-2 * before);
}

// A negative κ (the homogenised rule below ν = 1/4) scaled up makes K indefinite: the objective
// is then +∞, for the line search to step back, not an exception that ends the fit.
TEST(StiffnessFit, AnIndefiniteStiffnessGivesAnInfiniteObjective) {
  const TetMesh mesh = block_mesh(2, 1e-3);
  const BuiltNetwork built = hybrid(mesh, 0.45);
  const std::vector<char> fixed = bottom_fixed(built.network);
  std::mt19937 rng(3);
  const Eigen::VectorXd f = random_load(built.network, rng, 1e-7);
  const StiffnessParameters params = group_parameters(built.network, VesselParams{}, true);
  const double kappa = -0.5 * *built.terms.volume_kappa;  // negative, small enough to start stable
  const LinearisedFit fit(built.network, kappa, fixed, params,
                          {{"c", f, Eigen::VectorXd::Ones(f.size())}});
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(params.size()), g;
  theta[params.kappa] = std::log(1e4);  // κ → −5000·κ0: the volume term overwhelms the springs
  EXPECT_EQ(fit.objective(theta, g), std::numeric_limits<double>::infinity());
  EXPECT_EQ(g.size(), params.size());
}

TEST(StiffnessFit, RefusesMismatchedSizesAndKappaWithoutVolumeTerm) {
  const TetMesh mesh = block_mesh(1, 1e-3);
  BuiltNetwork built = hybrid(mesh, 0.45);
  const StiffnessParameters params = group_parameters(built.network, VesselParams{}, true);
  std::optional<double> none;
  EXPECT_THROW(apply_stiffness_factors(built.network, none, params,
                                       Eigen::VectorXd::Zero(params.size())),
               InputError);
  EXPECT_THROW(apply_stiffness_factors(built.network, built.terms.volume_kappa, params,
                                       Eigen::VectorXd::Zero(params.size() + 1)),
               InputError);
}

namespace {

/// A network of springs from node 0 to each of `ends`, no tets.
SpringNetwork star_network(const Vec3& centre, const std::vector<Vec3>& ends) {
  SpringNetwork net;
  net.nodes.push_back(centre);
  for (const Vec3& e : ends) {
    net.nodes.push_back(e);
    Spring s;
    s.a = 0;
    s.b = static_cast<int>(net.nodes.size()) - 1;
    s.family = SpringFamily::volume;
    s.rest_length = (e - centre).norm();
    net.springs.push_back(s);
  }
  return net;
}

}  // namespace

// The direction classes on the arch use its local centreline frame: at a point at angle φ round
// the arch axis the axial direction is the tangent (−sin φ, cos φ, 0), radial points away from the
// centreline circle of radius R, circumferential is the rest. Hand-built springs along those
// directions (worked out here, not by the classifier's own frame) at two arch angles and two
// section angles; a fixed z axis (the straight tube's frame) would call the tangential springs
// "circumferential" or "radial".
TEST(StiffnessFit, ArchEdgeClassesUseTheLocalCentrelineFrame) {
  const VesselParams arch = hand_placed_arch();
  const double h = 0.2e-3;  // spring length
  for (const double phi : {std::numbers::pi / 6, std::numbers::pi / 2, 0.8 * std::numbers::pi}) {
    const Vec3 outward(std::cos(phi), std::sin(phi), 0.0);
    const Vec3 tangent(-std::sin(phi), std::cos(phi), 0.0);
    const Vec3 up = Vec3::UnitZ();
    const Vec3 centre = arch.bend_radius * outward;
    // Section angle 0 (outer bend): radial = outward, circumferential = z.
    // Section angle 90° (top): radial = z, circumferential = outward.
    for (const bool top : {false, true}) {
      const Vec3 radial = top ? up : outward;
      const Vec3 circ = top ? outward : up;
      const Vec3 p = centre + 3.5e-3 * radial;
      // Tilted slightly towards another direction, so the largest component decides.
      const SpringNetwork net = star_network(
          p, {p + h * (tangent + 0.3 * radial).normalized(), p + h * (radial + 0.2 * circ).normalized(),
              p + h * (circ + 0.4 * tangent).normalized()});
      const std::vector<char> boundary(net.springs.size(), 0);
      const std::string where = "phi " + std::to_string(phi) + (top ? ", top" : ", outer bend");
      EXPECT_EQ(spring_class(net, arch, boundary, 0), "volume/axial/interior") << where;
      EXPECT_EQ(spring_class(net, arch, boundary, 1), "volume/radial/interior") << where;
      EXPECT_EQ(spring_class(net, arch, boundary, 2), "volume/circumferential/interior") << where;
      // The wall-layer classes: same directions; ξ̄ = (3.5 mm + ~0.1 mm·(radial share) − a)/t
      // lies in the middle third.
      EXPECT_EQ(spring_wall_layer_class(net, arch, 0), "volume/axial/middle") << where;
      EXPECT_EQ(spring_wall_layer_class(net, arch, 1), "volume/radial/middle") << where;
      EXPECT_EQ(spring_wall_layer_class(net, arch, 2), "volume/circumferential/middle") << where;
      if (!top && std::abs(phi - std::numbers::pi / 2) < 1e-12) {
        // The discriminating case: a straight tube's fixed frame (axis z) at the same point
        // calls the arch's tangential spring circumferential.
        VesselParams straight = arch;
        straight.kind = VesselKind::straight;
        EXPECT_EQ(spring_class(net, straight, boundary, 0), "volume/circumferential/interior");
      }
    }
  }
}

// Wall layers by the mean through-wall position of a spring's ends (hand-placed nodes on a
// straight tube, a = 3 mm, t = 1 mm) and κ halves by the tet centroid.
TEST(StiffnessFit, WallLayerClassesFollowThePositionThroughTheWall) {
  VesselParams tube;
  tube.kind = VesselKind::straight;
  tube.inner_radius = 3e-3;
  tube.wall_thickness = 1e-3;
  const auto at = [](double rho, double z) { return Vec3(rho, 0.0, z); };
  SpringNetwork net;
  // Axial springs on the inner wall, at mid-wall and on the outer wall; radial springs through
  // the inner and the outer half.
  net.nodes = {at(3e-3, 0), at(3e-3, 1e-3), at(3.5e-3, 0), at(3.5e-3, 1e-3),
               at(4e-3, 0), at(4e-3, 1e-3)};
  const std::pair<int, int> pairs[] = {{0, 1}, {2, 3}, {4, 5}, {0, 2}, {2, 4}};
  for (const auto& [a, b] : pairs) {
    Spring s;
    s.a = a;
    s.b = b;
    s.family = SpringFamily::volume;
    net.springs.push_back(s);
  }
  // Two tets: one with three nodes on the inner wall (centroid ξ = 0.125... < 1/2), one with
  // three on the outer wall.
  net.nodes.push_back(Vec3(3e-3 * std::cos(0.3), 3e-3 * std::sin(0.3), 0));    // 6, inner wall
  net.nodes.push_back(Vec3(4e-3 * std::cos(0.3), 4e-3 * std::sin(0.3), 0));    // 7, outer wall
  net.tets = {Tet{0, 1, 6, 2}, Tet{4, 5, 7, 2}};
  EXPECT_EQ(spring_wall_layer_class(net, tube, 0), "volume/axial/inner");
  EXPECT_EQ(spring_wall_layer_class(net, tube, 1), "volume/axial/middle");
  EXPECT_EQ(spring_wall_layer_class(net, tube, 2), "volume/axial/outer");
  EXPECT_EQ(spring_wall_layer_class(net, tube, 3), "volume/radial/inner");   // ξ̄ = 1/4
  EXPECT_EQ(spring_wall_layer_class(net, tube, 4), "volume/radial/outer");   // ξ̄ = 3/4
  // Edge types: the axis-aligned springs keep their direction; a radial–axial diagonal at 30°
  // from the axis spans both (components 0.87 and 0.5 > 0.35) where the largest component says
  // axial; one at 80° from the axis is radial alone (cos 80° = 0.17 < 0.35).
  EXPECT_EQ(spring_wall_layer_class(net, tube, 0, true), "volume/axial/inner");
  EXPECT_EQ(spring_wall_layer_class(net, tube, 3, true), "volume/radial/inner");
  {
    SpringNetwork diag;
    const double r0 = 3.0e-3, l = 0.4e-3;
    const double a30 = std::numbers::pi / 6.0, a80 = 80.0 * std::numbers::pi / 180.0;
    diag.nodes = {at(r0, 0), at(r0 + l * std::sin(a30), l * std::cos(a30)),
                  at(r0 + l * std::sin(a80), l * std::cos(a80))};
    for (const int b : {1, 2}) {
      Spring sp;
      sp.a = 0;
      sp.b = b;
      sp.family = SpringFamily::volume;
      diag.springs.push_back(sp);
    }
    EXPECT_EQ(spring_wall_layer_class(diag, tube, 0, true), "volume/radial+axial/inner");
    EXPECT_EQ(spring_wall_layer_class(diag, tube, 0, false), "volume/axial/inner");
    EXPECT_EQ(spring_wall_layer_class(diag, tube, 1, true), "volume/radial/inner");
  }
  const StiffnessParameters p = wall_layer_parameters(net, tube, true);
  ASSERT_EQ(p.of_tet.size(), 2u);
  EXPECT_EQ(p.names[static_cast<std::size_t>(p.of_tet[0])], "kappa/inner");
  EXPECT_EQ(p.names[static_cast<std::size_t>(p.of_tet[1])], "kappa/outer");
  EXPECT_EQ(p.kappa, -1);
  EXPECT_EQ(p.size(), 5 + 2);
  // Applying the factors scales each tet's κ through the per-tet factors.
  std::optional<double> kappa = 2.0;
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(p.size());
  theta[p.of_tet[0]] = std::log(3.0);
  theta[p.of_tet[1]] = std::log(0.5);
  apply_stiffness_factors(net, kappa, p, theta);
  EXPECT_DOUBLE_EQ(*kappa, 2.0);
  ASSERT_EQ(net.tet_kappa_factors.size(), 2u);
  EXPECT_DOUBLE_EQ(net.tet_kappa_factors[0], 3.0);
  EXPECT_DOUBLE_EQ(net.tet_kappa_factors[1], 0.5);
}
