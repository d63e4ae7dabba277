#pragma once
/// The one place that turns a built network into the Form the solvers run on: the spring model,
/// plus, for the hybrid volume model, the volume term of every tet (Golec et al. 2020). The
/// harness, the `msm` command, regions of interest and the studies build their models here.
///
/// The hybrid volume model ("volume_term = true" on a volume_msm model, `--volume-term`):
/// springs with Van Gelder weights k = E_s·Σ V_e/L² carry the shear modulus μ, and each tet's
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
/// Measured (tests/msm/test_effective_moduli.cpp, docs/msm_accuracy.md): the formula is the
/// affine, isotropic-average one; the real network relaxes non-affinely (van-gelder alone gives
/// ν = 0.235, not 0.25, on the cube) and the volume term stiffens it towards ν = 1/2, so effective
/// E and ν deviate from the target by a few per cent (not within the 2 %). The homogenised
/// rule (volume_term_homogenised.hpp, volume_moduli = "homogenised") fits (E_s, κ) to the mesh's
/// own network instead, and reaches ν < 1/4 with a per-tet stability clip.
#include <string>
#include <memory>
#include <optional>

#include "msm/terms/bending_term.hpp"
#include "msm/model/build_network.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/terms/volume_term.hpp"

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

/// A mass-spring model as the solvers see it: the spring model, plus the volume term when the
/// network carries one, plus the Discrete Shells bending term (bending_term.hpp) on a surface
/// network's triangles when asked. Energy, gradient and Hessian are the sums; damping is the
/// springs'.
class MassSpringModel : public Form {
 public:
  /// volume_kappa: κ (Pa) of the volume term on network.tets; bending_rigidity: D (N·m) of the
  /// bending term on network.triangles; edge_pairs: the StVK material of the edge-pair term
  /// (edge_pair_term.hpp) on network.tets; none: without that term. InputError if the network
  /// lacks the tets or triangles a term needs.
  MassSpringModel(const SpringNetwork& network, double point_damping,
                  std::optional<double> volume_kappa,
                  std::optional<double> bending_rigidity = std::nullopt,
                  std::optional<LameParameters> edge_pairs = std::nullopt);

  [[nodiscard]] int num_dofs() const override { return springs_.num_dofs(); }
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  /// One pass of the fast spring kernel for both (the explicit integrators call this), plus the
  /// volume term's.
  double energy_gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;
  void damping_force(const VectorXd& x, const VectorXd& v, VectorXd& f) const override;
  void damping_jacobian(const VectorXd& x, SparseMatrix& D) const override;

  [[nodiscard]] const SpringModel& springs() const { return springs_; }
  /// The volume term, or nullptr.
  [[nodiscard]] const VolumeTerm* volume_term() const { return volume_.get(); }
  /// The bending term, or nullptr.
  [[nodiscard]] const BendingTerm* bending_term() const { return bending_.get(); }
  /// The edge-pair term, or nullptr.
  [[nodiscard]] const EdgePairTerm* edge_pair_term() const { return edge_pairs_.get(); }
  /// Largest spring (or, with the edge-pair term, tet edge) strain |L − l|/l at x.
  [[nodiscard]] double max_strain(const VectorXd& x) const;

 private:
  SpringModel springs_;
  std::unique_ptr<VolumeTerm> volume_;
  std::unique_ptr<BendingTerm> bending_;
  std::unique_ptr<EdgePairTerm> edge_pairs_;
  std::vector<const FourNodeTerm*> terms_;  ///< the above that exist, summed with the springs
  /// Hessian pattern when the springs' lacks some tet or hinge entries (a region of interest drops
  /// the springs between two held nodes; no spring joins a hinge's opposite vertices): the union,
  /// and where each spring value goes in it.
  SparseMatrix union_pattern_;
  std::vector<int> spring_to_union_;
  /// Per term, where its blocks go: in the springs' pattern, or in union_pattern_.
  std::vector<std::vector<int>> term_slots_;
};

/// The springs alone of a Form that is nothing but springs: a SpringModel, or a MassSpringModel
/// without a volume, bending or edge-pair term; nullptr for any other Form (solvers that need a plain spring
/// network, such as the local-global method, refuse those).
const SpringModel* plain_spring_model(const Form& form);

/// The model of a network (volume_kappa, bending_rigidity and edge_pairs as in BuiltNetwork),
/// point damping k_v in N·s/m per node.
std::unique_ptr<MassSpringModel> make_model(
    const SpringNetwork& network, std::optional<double> volume_kappa, double point_damping = 0.0,
    std::optional<double> bending_rigidity = std::nullopt,
    std::optional<LameParameters> edge_pairs = std::nullopt);
/// The model of a built network (its volume, bending and edge-pair terms if it has them).
std::unique_ptr<MassSpringModel> make_model(const BuiltNetwork& built, double point_damping = 0.0);

}  // namespace vessel::msm
