#include "msm/model/pattern_slots.hpp"

#include <algorithm>

namespace vessel::msm {

int pattern_slot(const SparseMatrix& pattern, int row, int col) {
  const int* inner = pattern.innerIndexPtr();
  const int* begin = inner + pattern.outerIndexPtr()[col];
  const int* end = inner + pattern.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  return it != end && *it == row ? static_cast<int>(it - inner) : -1;
}

std::vector<int> four_node_block_slots(const SparseMatrix& pattern,
                                       const std::vector<std::array<int, 4>>& elements) {
  std::vector<int> slots;
  slots.reserve(elements.size() * 144);
  for (const auto& e : elements)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            slots.push_back(pattern_slot(pattern, 3 * e[a] + i, 3 * e[b] + j));
          }
  return slots;
}

}  // namespace vessel::msm
