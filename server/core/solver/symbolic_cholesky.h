// The symbolic half of the sparse Cholesky (sparse_cholesky.h): everything that depends only on
// the sparsity pattern, computed once per pattern and shared by every numeric factor of it.
#pragma once

#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/solver/ordering.h"

namespace deform {

class SymbolicCholesky {
 public:
  // The fill-reducing ordering, the pattern of C = P A P^T, its elimination tree, the pattern of
  // the factor L and its supernodes. `a` is square and structurally symmetric (both triangles
  // stored), column-major and compressed; with Ordering::kAuto both AMD and METIS are analysed
  // and the one whose factor has fewer non-zeros is kept. INVALID_ARGUMENT for a non-square or
  // uncompressed matrix or a missing diagonal entry; RESOURCE_EXHAUSTED when the factor would
  // have more non-zeros than an int can index.
  static StatusOr<std::shared_ptr<const SymbolicCholesky>> Analyze(
      const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, Ordering ordering);

  int size() const { return n_; }
  // The ordering used (kAmd or kMetis when kAuto was asked for).
  Ordering ordering() const { return ordering_; }
  // Non-zeros of the factor L, diagonal included.
  std::int64_t factor_nonzeros() const { return column_pointers_.back(); }
  // Non-zeros of column j of L, diagonal included.
  std::int64_t column_nonzeros(int j) const {
    return column_pointers_[j + 1] - column_pointers_[j];
  }
  // The parent of each column of L in its elimination tree, -1 for a root. Postordered (every
  // subtree's columns consecutive, ending at its root) unless the ordering is kNatural.
  const std::vector<int>& elimination_tree() const { return elimination_tree_; }
  // The columns' order: permutation()[new] = old (the fill-reducing ordering, postordered).
  const std::vector<int>& permutation() const { return permutation_; }

 private:
  friend class CholeskyFactor;
  // Sets inverse_permutation_, the pattern of C and the map from A's entries (after permutation_
  // is set).
  Status AnalyzePermutedPattern(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a);

  int n_ = 0;
  Ordering ordering_ = Ordering::kMetis;
  std::vector<int> permutation_;          // permutation_[new] = old
  std::vector<int> inverse_permutation_;  // inverse_permutation_[old] = new
  // Upper triangle of C = P A P^T, column-major, rows ascending in each column.
  std::vector<int> c_column_pointers_;
  std::vector<int> c_row_indices_;
  std::vector<int> a_to_c_;  // A's value index -> C's value index, or -1 (lower part)
  std::int64_t a_nonzeros_ = 0;
  std::vector<int> a_column_pointers_;  // A's pattern, to check later matrices against
  std::vector<int> a_row_indices_;
  std::vector<int> elimination_tree_;          // parent of each column of L, -1 for a root
  std::vector<std::int64_t> column_pointers_;  // of L, n + 1
  // Supernodes: supernode s holds columns [supernode_columns_[s], supernode_columns_[s + 1]).
  std::vector<int> supernode_columns_;
  int max_supernode_width_ = 1;
};

}  // namespace deform
