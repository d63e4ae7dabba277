#pragma once
/// A model as the sum of Forms on the same dofs: a rod and its loads, a wire and a wall.
#include <utility>
#include <vector>

#include "msm/form/form.hpp"

namespace vessel::msm {

/// The sum of Forms on the same dofs (each term's pattern is x-independent, so is the sum's).
class FormSum : public Form {
 public:
  explicit FormSum(std::vector<const Form*> terms) : terms_(std::move(terms)) {}
  [[nodiscard]] int num_dofs() const override { return terms_.front()->num_dofs(); }
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;

 private:
  std::vector<const Form*> terms_;
};

}  // namespace vessel::msm
