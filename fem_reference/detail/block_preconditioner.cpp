#include "fem_reference/detail/block_preconditioner.hpp"

#include <deal.II/lac/dynamic_sparsity_pattern.h>

namespace vessel::fem::detail {

/// The rows and columns `rows` of `a` (renumbered 0..rows.size()−1 by `local`, −1 elsewhere).
void extract_block(const dl::SparseMatrix<double>& a, const std::vector<Index>& rows,
                   const std::vector<int>& local, dl::SparsityPattern& pattern,
                   dl::SparseMatrix<double>& out) {
  const auto m = static_cast<Index>(rows.size());
  dl::DynamicSparsityPattern dsp(m, m);
  for (Index i = 0; i < m; ++i) {
    for (auto it = a.begin(rows[i]); it != a.end(rows[i]); ++it) {
      const int j = local[it->column()];
      if (j >= 0) dsp.add(i, static_cast<Index>(j));
    }
  }
  pattern.copy_from(dsp);
  out.reinit(pattern);
  for (Index i = 0; i < m; ++i) {
    for (auto it = a.begin(rows[i]); it != a.end(rows[i]); ++it) {
      const int j = local[it->column()];
      if (j >= 0) out.set(i, static_cast<Index>(j), it->value());
    }
  }
}

}  // namespace vessel::fem::detail
