#pragma once
/// The one place that turns a built network into the Form the solvers run on: the spring model plus
/// an open sum of energy terms (msm/model/model_terms.hpp lists them: the volume term of the hybrid
/// volume model, Golec et al. 2020; the Discrete Shells bending term; the edge-pair term). The
/// harness, the `msm` command, regions of interest and the studies build their models here.
#include <memory>
#include <vector>

#include "msm/model/build_network.hpp"
#include "msm/model/model_terms.hpp"
#include "msm/terms/spring_model.hpp"

namespace vessel::msm {

/// A mass-spring model as the solvers see it: the spring model plus every term the network
/// carries (make_terms). Energy, gradient and Hessian are the sums; damping is the springs'.
class MassSpringModel : public Form {
 public:
  /// InputError if the network lacks the tets or triangles a term needs.
  MassSpringModel(const SpringNetwork& network, double point_damping, const ModelTerms& terms);

  [[nodiscard]] int num_dofs() const override { return springs_.num_dofs(); }
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  /// One pass of the fast spring kernel (the explicit integrators call this), plus each term's.
  double energy_gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;
  void damping_force(const VectorXd& x, const VectorXd& v, VectorXd& f) const override;
  void damping_jacobian(const VectorXd& x, SparseMatrix& D) const override;

  [[nodiscard]] const SpringModel& springs() const { return springs_; }
  /// The model's term of type Term (VolumeTerm, BendingTerm, EdgePairTerm, …), or nullptr.
  template <class Term>
  [[nodiscard]] const Term* term() const {
    for (const auto& t : terms_) {
      if (const auto* found = dynamic_cast<const Term*>(t.get())) return found;
    }
    return nullptr;
  }
  /// True when the model is its springs alone.
  [[nodiscard]] bool springs_only() const { return terms_.empty(); }
  /// Largest spring strain |L − l|/l at x, or a term's own largest strain if larger (the
  /// edge-pair term's tet edges).
  [[nodiscard]] double max_strain(const VectorXd& x) const;

 private:
  SpringModel springs_;
  std::vector<std::unique_ptr<FourNodeTerm>> terms_;
  /// Hessian pattern when the springs' lacks some tet or hinge entries (a region of interest drops
  /// the springs between two held nodes; no spring joins a hinge's opposite vertices): the union,
  /// and where each spring value goes in it.
  SparseMatrix union_pattern_;
  std::vector<int> spring_to_union_;
  /// Per term, where its blocks go: in the springs' pattern, or in union_pattern_.
  std::vector<std::vector<int>> term_slots_;
};

/// The springs alone of a Form that is nothing but springs: a SpringModel, or a MassSpringModel
/// without terms; nullptr for any other Form (solvers that need a plain spring network, such as
/// the local-global method, refuse those).
const SpringModel* plain_spring_model(const Form& form);

/// The model of a network with the given terms, point damping k_v in N·s/m per node.
std::unique_ptr<MassSpringModel> make_model(const SpringNetwork& network,
                                            const ModelTerms& terms = {},
                                            double point_damping = 0.0);
/// The model of a built network (the terms it carries).
std::unique_ptr<MassSpringModel> make_model(const BuiltNetwork& built, double point_damping = 0.0);

}  // namespace vessel::msm
