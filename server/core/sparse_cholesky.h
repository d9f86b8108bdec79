// A factor-once, solve-many sparse Cholesky for the symmetric positive definite normal equations.
//
// SymbolicCholesky::Analyze() depends only on the sparsity pattern: fill-reducing ordering,
// elimination tree and the pattern of the factor. CholeskyFactor::Factorize() computes the numeric
// factor L (P A P^T = L L^T) for any matrix with that same pattern, reusing the analysis; it is
// called once per mesh and again after each stiffness change.
//
// The solve is written for the deformation's three right-hand sides (x, y, z): they are stored
// interleaved and solved together, so each triangular pass reads the factor exactly once. This is
// what makes the per-frame solve memory-bound rather than three times that.
#pragma once

#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/status.h"

namespace deform {

enum class Ordering {
  kNatural,  // no reordering (for tests)
  kAmd,      // approximate minimum degree (Eigen's)
  kMetis,    // nested dissection (METIS_NodeND); the default, least fill on surface meshes
};

const char* OrderingName(Ordering ordering);

class SymbolicCholesky {
 public:
  // `a` is square and structurally symmetric (both triangles stored), column-major.
  // INVALID_ARGUMENT for a non-square matrix or a missing diagonal entry.
  static StatusOr<std::shared_ptr<const SymbolicCholesky>> Analyze(
      const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, Ordering ordering);

  int size() const { return n_; }
  Ordering ordering() const { return ordering_; }
  // Non-zeros of the factor L, diagonal included.
  std::int64_t factor_nonzeros() const { return column_pointers_.back(); }

 private:
  friend class CholeskyFactor;
  int n_ = 0;
  Ordering ordering_ = Ordering::kMetis;
  std::vector<int> permutation_;          // permutation_[new] = old
  // Upper triangle of C = P A P^T, column-major, rows ascending in each column.
  std::vector<int> c_column_pointers_;
  std::vector<int> c_row_indices_;
  std::vector<int> a_to_c_;               // A's value index -> C's value index, or -1 (lower part)
  std::int64_t a_nonzeros_ = 0;
  std::vector<int> elimination_tree_;     // parent of each column of L, -1 for a root
  std::vector<std::int64_t> column_pointers_;  // of L, n + 1
};

class CholeskyFactor {
 public:
  CholeskyFactor() = default;

  // `a` must have exactly the pattern that `symbolic` was analysed with. INTERNAL if `a` is not
  // positive definite (names the pivot).
  static StatusOr<CholeskyFactor> Factorize(std::shared_ptr<const SymbolicCholesky> symbolic,
                                            const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a);

  int size() const { return symbolic_ ? symbolic_->size() : 0; }
  // Solves A X = B for three right-hand sides stored interleaved: b[3 i + c] is row i, column c.
  // `x` may equal `b`. `work` holds 3 * size() doubles. Allocation-free; const and thread-safe.
  void Solve3(const double* b, double* x, double* work) const;
  // Bytes one triangular pass reads: values, row indices and column pointers of L.
  std::size_t bytes() const;
  std::int64_t nonzeros() const { return static_cast<std::int64_t>(values_.size()); }

 private:
  std::shared_ptr<const SymbolicCholesky> symbolic_;
  std::vector<int> row_indices_;  // per column: the diagonal first, then rows ascending
  std::vector<double> values_;
};

}  // namespace deform
