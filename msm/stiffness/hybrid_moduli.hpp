#pragma once
/// The moduli rule of the hybrid volume model ("volume_term = true" on a volume_msm model,
/// `--volume-term`): springs with Van Gelder weights k = E_s·Σ V_e/L² carry the shear modulus μ, and each tet's
/// volume energy W = ½κV₀(V/V₀ − 1)² adds κ = λ − μ to the network's λ. Derivation (small uniform
/// strain ε, edge directions d of each tet distributed isotropically over the mesh): a spring's
/// energy is ½kL²(dᵀεd)² = ½E_s·V_e·(dᵀεd)² per element sharing it, so a tet's six springs store
/// ½E_s·V·Σ_6 (dᵀεd)², whose isotropic average is ½E_s·V·6·((tr ε)² + 2 ε:ε)/15
/// = V·(½·0.4E_s·(tr ε)² + 0.4E_s·ε:ε): the network alone has λ_s = μ_s = 0.4·E_s (the Cauchy
/// relation, ν = 1/4). Choosing E_s = μ/0.4 = 2.5μ = 1.25·E/(1 + ν) gives μ_s = μ and λ_s = μ; the
/// volume term adds ½κV(tr ε)², so λ = μ + κ, i.e. κ = λ − μ = E(4ν − 1)/(2(1 + ν)(1 − 2ν)).
/// At ν = 1/4, κ = 0 and E_s = E: plain van-gelder. κ is infinite at ν = 1/2: refused (no
/// incompressibility constraint is offered). κ is negative for ν < 1/4 (−μ at ν = 0), and refused
/// too: a sliver tet changes its volume at first order under a motion that barely changes its edge
/// lengths, so a negative volume energy outweighs its springs there (volume term ∝ κ·A·δ²/h against
/// springs ∝ E_s·A·h³·δ²/L⁴ for a sliver of height h ≪ L): measured, the static solver diverged on
/// the gmsh cube at ν = 0 and 0.1. So the model covers ν ∈ [1/4, 1/2).
/// Measured (tests/msm/test_effective_moduli.cpp, docs/physics/accuracy.md): the formula is the
/// affine, isotropic-average one; the real network relaxes non-affinely (van-gelder alone gives
/// ν = 0.235, not 0.25, on the cube) and the volume term stiffens it towards ν = 1/2, so effective
/// E and ν deviate from the target by a few per cent (not within the 2 %). The homogenised
/// rule (volume_term_homogenised.hpp, volume_moduli = "homogenised") fits (E_s, κ) to the mesh's
/// own network instead, and reaches ν < 1/4 with a per-tet stability clip.
#include <string>

namespace vessel::msm {

/// Moduli of the hybrid volume model for E (Pa) and ν.
struct HybridModuli {
  double lambda = 0.0;                 ///< target Lamé λ = Eν/((1 + ν)(1 − 2ν)), Pa
  double mu = 0.0;                     ///< target shear modulus μ = E/(2(1 + ν)), Pa
  double spring_youngs_modulus = 0.0;  ///< E_s = 2.5μ: van-gelder springs with λ_s = μ_s = μ, Pa
  double kappa = 0.0;                  ///< κ = λ − μ, Pa
};
/// Why the hybrid model cannot take E (Pa) and ν, or "" if it can: ν in [0.25, 0.5) (κ negative
/// below, infinite at 0.5), E > 0.
std::string hybrid_refusal(double E, double nu);
/// Throws InputError with hybrid_refusal's reason where it has one.
HybridModuli hybrid_moduli(double E, double nu);

}  // namespace vessel::msm
