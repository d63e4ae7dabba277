#include "msm/form/form_sum.hpp"

namespace vessel::msm {

double FormSum::energy(const VectorXd& x) const {
  double e = 0.0;
  for (const Form* f : terms_) e += f->energy(x);
  return e;
}

void FormSum::gradient(const VectorXd& x, VectorXd& g) const {
  g.setZero(num_dofs());
  VectorXd gi;
  for (const Form* f : terms_) {
    f->gradient(x, gi);
    g += gi;
  }
}

void FormSum::hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const {
  H.resize(num_dofs(), num_dofs());
  H.setZero();
  SparseMatrix Hi;
  for (const Form* f : terms_) {
    f->hessian(x, Hi, project_psd);
    H += Hi;
  }
}

}  // namespace vessel::msm
