#include "msm/form/form.hpp"

namespace vessel::msm {

void apply_dirichlet(SparseMatrix& A, const std::vector<char>& fixed) {
  for (int k = 0; k < A.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(A, k); it; ++it) {
      if (fixed[it.row()] || fixed[it.col()]) it.valueRef() = it.row() == it.col() ? 1.0 : 0.0;
    }
  }
}

}  // namespace vessel::msm
