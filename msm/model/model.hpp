#pragma once
/// The one place that turns a built network into the Form the solvers run on: the spring model,
/// plus the volume term of every tet for the hybrid volume model (Golec et al. 2020; its moduli
/// rule in msm/stiffness/hybrid_moduli.hpp), the bending and edge-pair terms. The
/// harness, the `msm` command, regions of interest and the studies build their models here.
#include <memory>
#include <optional>

#include "msm/model/build_network.hpp"
#include "msm/terms/bending_term.hpp"
#include "msm/terms/edge_pair_term.hpp"
#include "msm/terms/spring_model.hpp"
#include "msm/terms/volume_term.hpp"

namespace vessel::msm {

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
