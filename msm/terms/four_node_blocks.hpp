#pragma once
/// What the model terms on four nodes (a tet's volume or edge-pair term, a hinge's bending term)
/// share: the 12×12 blocks of their Hessians, where those blocks go in a fixed sparse pattern
/// (compressed column storage, so each assembly writes values in place), the per-element
/// projection that keeps Newton's matrix positive semi-definite, and the loops over elements.
#include <array>
#include <vector>

#include "meshes/tet_mesh.hpp"
#include "msm/form/form.hpp"

namespace vessel::msm {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

/// The index into pattern.valuePtr() of entry (row, col), or −1 if the pattern lacks it.
int pattern_slot(const SparseMatrix& pattern, int row, int col);

/// The pattern of the diagonal of `dofs` unknowns and every element's 12×12 block (values 0).
SparseMatrix four_node_block_pattern(int dofs, const std::vector<std::array<int, 4>>& elements);

/// For each element, the 144 slots of its 12×12 block in the order node pairs (a, b), then
/// components (i, j): the block's entry (3a + i, 3b + j).
std::vector<int> four_node_block_slots(const SparseMatrix& pattern,
                                       const std::vector<std::array<int, 4>>& elements);

/// Adds block B at the next 144 slots (in four_node_block_slots' order) and advances `slot`.
void add_four_node_block(const Mat12& B, const int*& slot, double* values);

/// B with its negative eigenvalues set to zero (the nearest PSD matrix in the Frobenius norm).
Mat12 psd_projection(const Mat12& B);

/// A Form that sums an energy over elements of four nodes (no damping): the loops over the
/// elements, the Hessian's fixed pattern and where each element's block goes in it, written once
/// for every such term. A term supplies one element's energy, gradient and Hessian.
class FourNodeTerm : public Form {
 public:
  [[nodiscard]] int num_dofs() const override { return 3 * num_nodes_; }
  [[nodiscard]] double energy(const VectorXd& x) const override;
  void gradient(const VectorXd& x, VectorXd& g) const override;
  void hessian(const VectorXd& x, SparseMatrix& H, bool project_psd) const override;

  /// g += ∇W (g already sized).
  void add_gradient(const VectorXd& x, VectorXd& g) const;
  /// Per element, the 144 value indices of its 12×12 block in `pattern` (compressed,
  /// column-major); −1 where the pattern lacks an entry.
  [[nodiscard]] std::vector<int> slots_in(const SparseMatrix& pattern) const;
  /// Adds every element's Hessian block into `values` at `slots` (from slots_in, none −1).
  void add_hessian(const VectorXd& x, double* values, const std::vector<int>& slots,
                   bool project_psd) const;
  /// The sparsity pattern of the term's Hessian (element blocks plus the full diagonal), values 0.
  [[nodiscard]] const SparseMatrix& pattern() const { return pattern_; }
  /// The largest strain the term measures on its own elements at x (the edge-pair term's tet
  /// edges); 0 for a term that measures none.
  [[nodiscard]] virtual double max_strain(const VectorXd& /*x*/) const { return 0.0; }
  /// Each element's four node indices.
  [[nodiscard]] const std::vector<std::array<int, 4>>& elements() const { return elements_; }

 protected:
  explicit FourNodeTerm(int num_nodes) : num_nodes_(num_nodes) {}
  /// The elements (their indices already checked) and the pattern they make.
  void set_elements(std::vector<std::array<int, 4>> elements);
  /// Element k's four positions in x.
  [[nodiscard]] std::array<Vec3, 4> corners(const VectorXd& x, std::size_t k) const;

  [[nodiscard]] virtual double element_energy(std::size_t k, const std::array<Vec3, 4>& x) const = 0;
  [[nodiscard]] virtual Vec12 element_gradient(std::size_t k, const std::array<Vec3, 4>& x) const = 0;
  /// With project_psd, projected onto the positive semi-definite cone.
  [[nodiscard]] virtual Mat12 element_hessian(std::size_t k, const std::array<Vec3, 4>& x,
                                              bool project_psd) const = 0;

 private:
  int num_nodes_ = 0;
  std::vector<std::array<int, 4>> elements_;
  SparseMatrix pattern_;
  std::vector<int> slots_;
};

}  // namespace vessel::msm
