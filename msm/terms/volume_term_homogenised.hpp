#pragma once
/// The mesh-homogenised hybrid volume model (our extension of Golec et al. 2020; rule name
/// "homogenised", scene key volume_moduli = "homogenised", `msm --volume-moduli homogenised`).
///
/// Same model as the hybrid (msm/stiffness/hybrid_moduli.hpp): van-gelder springs k = E_s·ΣV_e/L²
/// plus the volume energy W = ½κV₀(V/V₀ − 1)² per tet. Golec's rule picks E_s = 2.5μ, κ = λ − μ
/// from the affine, isotropic average of the springs' energy; on a real (irregular, bounded)
/// network the springs relax non-affinely and the cube measures E and ν a few per cent off
/// (docs/physics/accuracy.md). This rule instead measures the network's own linear response and solves
/// for (E_s, κ):
///
/// 1. Homogenisation under uniform boundary traction. The rest stiffness is
///    K(E_s, κ) = E_s·K₁ + κ·K_V (K₁: the springs at E_s = 1, K_V: the volume term at κ = 1; both
///    exact rest Hessians). For each of the six unit stresses σ (Mandel basis), the boundary faces
///    carry the consistent nodal loads of the traction σ·n (A/3 per corner; exact for the
///    piecewise-linear field), the body is held against rigid motion only (a statically
///    determinate 3-2-1 support: an equilibrated load leaves no reaction), and the mean strain is
///    the boundary integral ε̄ = (1/V)∫_∂Ω sym(u ⊗ n) dA (exact for the piecewise-linear
///    interpolation of the nodal displacements; rigid rotations drop out of sym). Under traction
///    boundary conditions the mean stress is exactly σ (Hill), so the six solves give the network's
///    compliance S (6×6, Mandel).
/// 2. Moduli of S: the fitted E and ν are those of uniaxial stress along the three coordinate
///    axes, averaged: E = 3/(S11 + S22 + S33), ν = −E·(S12 + S13 + S23)/3 (what a uniaxial test
///    along an axis measures). The isotropic projection of S (Frobenius, Mandel:
///    1/(3K) = (1/3)·Σ_{i,j≤3} S_ij, 1/(2μ) = (tr S − 1/(3K))/5) is reported beside them: a
///    Delaunay network is not exactly isotropic (on the gmsh cube, whose faces order the mesh,
///    its shear compliance at 45° is ~12 % above what its axial E and ν imply), and one scalar
///    pair cannot fix that.
/// 3. Fit. K is linear in (E_s, κ), so the compliance is homogeneous of degree −1 and ν_eff
///    depends on r = κ/E_s only. r is searched through the affine estimate's "nominal" ν_n,
///    r(ν_n) = (1.6ν_n − 0.4)/(1 − 2ν_n) (the inverse of Golec's ν = (0.4 + r)/(2(0.8 + r))), by
///    a safeguarded secant on ν_eff(ν_n) = ν (to 1e-5); then E_s = E/E_eff(1, r) scales E exactly.
///
/// For ν < 1/4, κ < 0. K(E_s, κ) is then checked to be positive definite on the non-rigid motions
/// (the CHOLMOD factorisation of the supported K succeeds) at every r tried; where it is not, the
/// network cannot represent that ν and the rule refuses with the lowest ν it reached. The static
/// solver uses the exact Hessian wherever it factorises (so Newton is exact near rest); only where
/// it does not does it fall back on the per-term PSD projection, which drops a negative κ's
/// volume blocks (a stiffer, still descent-direction Newton step, linear convergence). The energy
/// with κ < 0 is unbounded below at large volume change (−|κ|(V − V₀)²/V₀ outgrows the springs'
/// quadratic energy): the model is a small-strain model there. ν = 1/2 is refused (κ infinite).
/// The fit costs about a dozen factorisations of the model's rest stiffness (0.3–1 s on a
/// 7 000-dof mesh).
#include <string>
#include <array>
#include <optional>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"

namespace vessel::msm {

/// A network's effective isotropic moduli under uniform boundary traction.
struct TractionModuli {
  double youngs_modulus = 0.0;  ///< E_eff under uniaxial stress along x, y, z (averaged), Pa
  double poisson_ratio = 0.0;   ///< ν_eff likewise
  double bulk_modulus = 0.0;    ///< K_eff of the isotropic projection, Pa
  double shear_modulus = 0.0;   ///< μ_eff of the isotropic projection, Pa
  double isotropic_youngs_modulus = 0.0;  ///< 9Kμ/(3K + μ) of the projection, Pa
  double isotropic_poisson_ratio = 0.0;   ///< (3K − 2μ)/(2(3K + μ)) of the projection
  /// The full compliance (Mandel basis: ε11, ε22, ε33, √2ε23, √2ε13, √2ε12), 1/Pa.
  Eigen::Matrix<double, 6, 6> compliance = Eigen::Matrix<double, 6, 6>::Zero();
};

/// The homogenisation of one tet mesh's van-gelder springs plus volume term (steps 1–2 above).
class TractionHomogenisation {
 public:
  /// nodes (m) and positively oriented tets of the volume network. InputError for fewer than
  /// four nodes, degenerate tets, or all nodes collinear.
  TractionHomogenisation(const std::vector<Vec3>& nodes, const std::vector<Tet>& tets);

  /// The moduli at springs E_s (Pa, van-gelder k = E_s·ΣV/L²) and volume term κ (Pa) with the
  /// per-tet factors (empty: all 1); nullopt if K(E_s, κ) is not positive definite on the
  /// non-rigid motions.
  [[nodiscard]] std::optional<TractionModuli> moduli(
      double spring_youngs_modulus, double kappa,
      const std::vector<double>& tet_factors = {}) const;

  [[nodiscard]] double volume() const { return volume_; }

 private:
  int num_dofs_ = 0;
  double volume_ = 0.0;
  std::vector<Vec3> nodes_;
  std::vector<Tet> tets_;
  std::vector<int> free_index_;  ///< per dof: its index among the free dofs, −1 if supported
  int num_free_ = 0;
  SparseMatrix springs_;   ///< K₁ on the free dofs
  Eigen::MatrixXd loads_;  ///< 6 columns: nodal loads of the unit Mandel stresses, free dofs
  /// Mean strain (Mandel) from the free dofs' displacements: ε̄ = strain_ · u (6 × free dofs).
  Eigen::MatrixXd strain_;
};

/// Per unit E_s, the most negative κ/E_s at which one tet's own share of the van-gelder springs
/// (E_s·V/L² per edge) plus its volume term stays positive semi-definite at rest:
/// c = −1/(mᵀG⁻¹m), G = Σ_edges w wᵀ, w the Mandel vector of d dᵀ (d the unit edge), m =
/// (1,1,1,0,0,0). (A tet's nodal motion is rigid + uniform strain ε; its springs store ½E_s·V·εᵀGε,
/// its volume term ½κV(m·ε)²: a rank-one update, PSD iff κ ≥ −E_s/(mᵀG⁻¹m).) −2/3 for a regular tet
/// (the springs' bulk modulus, 2E_s/3); near 0 for a sliver, whose volume changes at first order
/// under motions that barely stretch its edges. InputError for a degenerate tet.
double volume_stability_limit(const std::array<Vec3, 4>& x);

/// The per-tet κ factors of the homogenised rule at κ/E_s = r: for r < 0 each tet's κ_e/E_s is
/// max(r, kStabilityMargin·c_e) (factor κ_e/κ ∈ (0, 1]), so that every tet's springs-plus-volume
/// block is positive definite at rest and so is the assembled stiffness; for r ≥ 0 none (empty).
constexpr double kStabilityMargin = 0.9;
std::vector<double> stability_clipped_factors(const std::vector<Vec3>& nodes,
                                              const std::vector<Tet>& tets, double r);

/// The homogenised rule's result for a target E, ν.
struct HomogenisedModuli {
  double spring_youngs_modulus = 0.0;  ///< E_s, Pa
  double kappa = 0.0;                  ///< κ, Pa
  std::vector<double> tet_factors;     ///< per tet κ_e/κ (stability clip, ν < 1/4); empty: all 1
  double clipped_fraction = 0.0;       ///< of the tets, the fraction whose κ was clipped
  TractionModuli achieved;             ///< the network's moduli at (E_s, κ)
  double golec_youngs_modulus = 0.0;   ///< E_eff at Golec's (E_s, κ), for comparison
  double golec_poisson_ratio = 0.0;    ///< ν_eff there (nan where Golec's κ is not PD)
  int evaluations = 0;                 ///< homogenisations (factorisations) used
};

/// Why the homogenised rule cannot take E (Pa) and ν whatever the mesh, or "" if it can: ν in
/// [0, 0.5), E > 0. The mesh's own floor below 1/4 is found by the fit (homogenised_moduli).
std::string homogenised_refusal(double E, double nu);

/// Steps 1–3: the (E_s, κ) of the network on (nodes, tets) whose traction-homogenised E and ν are
/// the targets. InputError for E ≤ 0, ν outside [0, 0.5) (ν = 0.5: κ infinite, refused), or a ν the
/// network cannot reach while positive definite (below 1/4, κ < 0), naming the lowest reached.
HomogenisedModuli homogenised_moduli(const std::vector<Vec3>& nodes, const std::vector<Tet>& tets,
                                     double E, double nu);

}  // namespace vessel::msm
