#pragma once
/// Stiffness calibration of a mass-spring network against reference displacements (issue 14
/// item 4): the network's spring stiffnesses and its volume term's κ, scaled by factors
/// exp(θ) (log-parameters keep every stiffness positive), are fitted by least squares on nodal
/// displacements over a set of load cases.
///
/// The fit uses the model linearised at rest: K(θ)·u_c = f_c on the free dofs, with
///   K(θ) = Σ_s k_s(θ)·B_s + κ(θ)·Σ_t g_t g_tᵀ/|V₀,t|,
/// B_s = d dᵀ ⊗ [1 −1; −1 1] the rest Hessian of spring s (direction d; the transverse term ψ'/L
/// vanishes at rest) and g_t = ∂V/∂x of tet t at rest (the volume term's rest Hessian,
/// volume_term.hpp; its ∇²V term carries V − V₀ = 0). K is linear in the stiffnesses, so
///   J(θ) = Σ_c ½·w_c·|u_c(θ) − r_c|²  (+ regulariser),   w_c = ω_c/(C·|r_c|²)
/// (C cases, ω_c = 1: J is half the mean squared relative L2 error of the harness's metric;
/// FitCase::weight ω_c weighs the cases otherwise) has the
/// adjoint gradient (one extra solve per case with the same factorisation):
///   K λ_c = w_c (u_c − r_c),   ∂J/∂θ_p = −Σ_c λ_cᵀ (∂K/∂θ_p) u_c
///   = −Σ_c [Σ_{s∈p} k_s (d·Δλ_s)(d·Δu_s) + (p = κ) Σ_t κ/|V₀| (g_t·λ_t)(g_t·u_t)],
/// Δ the difference of the spring's two end nodes. The loads of the scenes are in the linear
/// regime, so the linearised fit is what the calibrated model does to first order; the
/// calibrated model is then evaluated as the scene solves it (nonlinear), by the caller.
#include <optional>
#include <string>
#include <vector>

#include "meshes/vessel_geometry.hpp"
#include "msm/form/form.hpp"
#include "msm/topology/springs.hpp"

namespace vessel::msm {

/// Which parameter scales each spring and the volume term: k_s = k_s0·exp(θ[of_spring[s]]),
/// κ = κ0·exp(θ[kappa]). of_spring[s] = −1: spring s keeps its stiffness.
struct StiffnessParameters {
  std::vector<std::string> names;  ///< one per parameter
  std::vector<int> of_spring;      ///< per spring of the network
  int kappa = -1;                  ///< κ's parameter, −1: none (or no volume term)
  /// Per tet of the network: the parameter scaling that tet's κ (κ_e = κ0·f_e·exp(θ[of_tet[e]])),
  /// for a κ that differs through the wall (wall_layer_parameters). Empty: `kappa` scales every
  /// tet alike. When non-empty, `kappa` is −1.
  std::vector<int> of_tet;
  [[nodiscard]] int size() const { return static_cast<int>(names.size()); }
  /// Whether any parameter scales κ.
  [[nodiscard]] bool scales_kappa() const {
    return kappa >= 0 || !of_tet.empty();
  }
  /// The parameter of tet e's κ, −1: none.
  [[nodiscard]] int kappa_of_tet(std::size_t e) const {
    return of_tet.empty() ? kappa : of_tet[e];
  }
  /// log(k_s/k_s0) and log(κ_e/(κ0·f_e)) at θ.
  [[nodiscard]] double spring_log_factor(const VectorXd& theta, std::size_t s) const {
    return of_spring[s] >= 0 ? theta[of_spring[s]] : 0.0;
  }
  [[nodiscard]] double tet_log_factor(const VectorXd& theta, std::size_t e) const {
    const int p = kappa_of_tet(e);
    return p >= 0 ? theta[p] : 0.0;
  }
};

/// A few parameters ("groups"): on a surface network one factor per spring family present
/// (structural, shear, bend, two_ring); on a volume network one per (direction, boundary) class
/// of the tet-edge springs: direction = the largest component of the spring's unit vector in the
/// vessel's centreline frame at its midpoint (radial e_ρ, circumferential e_θ, axial e_s), and
/// boundary = whether the edge lies on a boundary face of the tet mesh (boundary edges get less
/// tet volume under Van Gelder's Σ V_e weights, so they are the class most likely to be off).
/// Plus "kappa" when with_kappa. The classes are defined by the vessel's geometry, not by spring
/// indices, so a group calibration applies to any mesh of any vessel kind.
StiffnessParameters group_parameters(const SpringNetwork& network, const VesselParams& vessel,
                                     bool with_kappa);
/// The class name group_parameters gives spring s ("volume/axial/boundary", "bend", ...).
std::string spring_class(const SpringNetwork& network, const VesselParams& vessel,
                         const std::vector<char>& boundary_edge, std::size_t s);
/// Per spring of a volume network: whether it is an edge of a boundary face (one tet only).
std::vector<char> boundary_edges(const SpringNetwork& network);

/// Position through the wall of a parametric vessel: ξ = (ρ − a)/t, ρ the distance from the
/// centreline, a the inner radius, t the wall thickness (0 on the inner wall, 1 on the outer).
double through_wall_position(const VesselParams& vessel, const Vec3& p);

/// A few parameters by position through the wall ("wall_layers"; our own extension of the
/// groups, for the wall's bending response, which depends on where a spring sits between the
/// inner and outer surfaces): on a volume network one factor per (direction, layer) class of the
/// tet-edge springs, direction as in group_parameters and layer from ξ̄, the mean of the two end
/// nodes' through_wall_position: "inner" ξ̄ < 1/3, "middle", "outer" ξ̄ > 2/3 (the band edges fall
/// between node layers of the structured meshes, whose nodes sit at ξ = j/(2·2^level)); and, with
/// with_kappa, a κ factor per half of the wall by the tet's centroid ξ ("kappa/inner" ξ < 1/2,
/// "kappa/outer"). With `edge_types` ("edge_types"), the direction is instead the set of frame
/// directions the edge spans, |d·e_i| > kEdgeTypeComponent ("radial", "circumferential+axial",
/// ...): a diagonal of a structured cell gets its own class apart from the cell's axis-aligned
/// edges. Surface networks: the spring families, as group_parameters. The classes are defined by
/// the vessel's geometry, so such a calibration applies to any mesh of a parametric vessel
/// (InputError for a mesh-file vessel, which has no centreline).
StiffnessParameters wall_layer_parameters(const SpringNetwork& network, const VesselParams& vessel,
                                          bool with_kappa, bool edge_types = false);
/// The class name wall_layer_parameters gives spring s ("volume/axial/outer",
/// "volume/circumferential+axial/inner", "bend", ...).
std::string spring_wall_layer_class(const SpringNetwork& network, const VesselParams& vessel,
                                    std::size_t s, bool edge_types = false);
/// Edge types: a unit vector's component along a frame direction above this counts (cos 69.5°).
/// On the structured meshes (cells about 0.5 mm radial × 0.9 mm circumferential × 1.8 mm axial
/// at level 0, the same proportions at every level) the circumferential–axial and radial–
/// circumferential diagonals get their own types, while the radial–axial diagonals (radial
/// component ≈ 0.27) count as axial.
inline constexpr double kEdgeTypeComponent = 0.35;

/// One parameter per spring of a cross-section ("per_section_spring"; our own, for a vessel whose
/// geometry repeats along its centreline — the straight tube along z, the arch round its axis):
/// springs that are images of each other along the centreline (the same midpoint ρ and θ in
/// centreline coordinates, the same direction in the local centreline frame; compared to 1 nm,
/// 1 µrad and 1e-6) share a factor ("section/<k>", k in the order of those keys). A fit then
/// moves the stiffness alike at every position along the vessel, so what it learns at the
/// training loads' positions holds at another position along it. κ as per_spring_parameters
/// (kappa_halves: per half of the wall). Its classes are indexed by one mesh's cross-section:
/// such a calibration belongs to this mesh only. InputError for a mesh-file vessel.
StiffnessParameters per_section_spring_parameters(const SpringNetwork& network,
                                                  const VesselParams& vessel, bool with_kappa,
                                                  bool kappa_halves);

/// One parameter per spring ("spring/<index>"), plus "kappa" when with_kappa. Such a
/// calibration belongs to this network only. With `kappa_halves` (a parametric vessel), κ per
/// half of the wall instead ("kappa/inner", "kappa/outer", as wall_layer_parameters): a
/// per-spring fit on top of a wall-layer or edge-types one keeps its two κ factors apart.
StiffnessParameters per_spring_parameters(const SpringNetwork& network, bool with_kappa,
                                          const VesselParams* kappa_halves = nullptr);

/// Scales network's spring laws (k1 and k2) and *kappa by the factors exp(θ). InputError if the
/// sizes do not match the network, or θ names κ while kappa is empty.
void apply_stiffness_factors(SpringNetwork& network, std::optional<double>& kappa,
                             const StiffnessParameters& params, const VectorXd& theta);

/// One load case of a fit: nodal forces f (N, per dof, full network) and the reference
/// displacement r at the network's nodes (m, per dof), in the same dof order.
struct FitCase {
  std::string name;
  VectorXd force;
  VectorXd reference;
  /// The case's weight ω_c in J: w_c = ω_c/(C·|r_c|²) (1: every case's relative error counts
  /// alike).
  double weight = 1.0;
};

/// The smoothness regulariser of a per-spring fit:
///   R(θ) = α/(2·N_s) · Σ_nodes Σ_{s∋n} (δ_{p(s)} − δ̄_n)²  +  β/(2·P) · Σ_p δ_p²,   δ = θ − θ_c,
/// δ̄_n the mean of δ over the springs meeting at node n, θ_c the centre (0: the base rule). The
/// first term is, per node, 1/m_n times the sum over all pairs of its m_n springs of
/// (δ_s − δ_t)²/2: springs sharing a node are pushed towards the same correction of the centre's
/// stiffness. The ridge β keeps the fit well posed where the data see nothing. A centre from a
/// class calibration (a per-spring fit on top of it) makes both terms act on the per-spring
/// departures from that calibration's factors, which differ a lot between neighbouring classes.
struct Regulariser {
  double smoothness = 0.0;  ///< α
  double ridge = 0.0;       ///< β
  VectorXd centre;          ///< θ_c (empty: 0)
};

/// The linearised least-squares fit and its adjoint gradient (header comment).
class LinearisedFit {
 public:
  /// `fixed` per dof (the problem's supports). InputError if a case's sizes differ from the
  /// network's dofs, its reference is zero, or params do not match the network.
  LinearisedFit(const SpringNetwork& network, std::optional<double> kappa,
                const std::vector<char>& fixed, StiffnessParameters params,
                std::vector<FitCase> cases, Regulariser regulariser = {});

  /// J(θ) and ∂J/∂θ (adjoint: one factorisation, one forward and one adjoint solve per case);
  /// +∞ (gradient 0) where K(θ) is not positive definite, so that a line search steps back.
  double objective(const VectorXd& theta, VectorXd& gradient) const;
  /// The data term alone and the regulariser alone at θ.
  [[nodiscard]] double misfit(const VectorXd& theta) const;
  [[nodiscard]] double regularisation(const VectorXd& theta) const;
  /// Displacements u_c(θ) of the linearised model (per dof, full network, fixed dofs 0), m.
  [[nodiscard]] std::vector<VectorXd> displacements(const VectorXd& theta) const;
  /// Per case, the relative L2 error |u_c − r_c|/|r_c| of the linearised model at θ.
  [[nodiscard]] std::vector<double> relative_errors(const VectorXd& theta) const;
  /// K(θ) on the free dofs (N/m).
  [[nodiscard]] SparseMatrix stiffness(const VectorXd& theta) const;

  [[nodiscard]] const StiffnessParameters& parameters() const { return params_; }
  [[nodiscard]] int num_cases() const { return static_cast<int>(cases_.size()); }

 private:
  struct Evaluation;
  [[nodiscard]] Evaluation evaluate(const VectorXd& theta, bool adjoint) const;
  [[nodiscard]] double regulariser_value(const VectorXd& theta, VectorXd* gradient) const;

  struct RestSpring {
    int a, b, param;
    Vec3 d;
    double k;
  };
  struct RestTet {
    std::array<int, 4> nodes;
    Eigen::Matrix<double, 12, 1> g;  ///< ∂V/∂x at rest
    double inv_volume;               ///< κ factor f_e/|V₀|
    int param;                       ///< κ's parameter for this tet, −1: none
  };
  std::vector<RestSpring> springs_;
  std::vector<RestTet> tets_;
  double kappa0_ = 0.0;
  StiffnessParameters params_;
  std::vector<FitCase> cases_;
  std::vector<double> weights_;
  Regulariser regulariser_;
  int num_dofs_ = 0;
  std::vector<int> free_index_;  ///< per dof: its index among the free dofs, −1 if fixed
  int num_free_ = 0;
  std::vector<std::vector<int>> node_springs_;  ///< springs meeting at each node
};

}  // namespace vessel::msm
