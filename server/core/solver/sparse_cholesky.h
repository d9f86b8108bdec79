// A factor-once, solve-many sparse Cholesky for the symmetric positive definite normal equations.
//
// SymbolicCholesky::Analyze() depends only on the sparsity pattern: fill-reducing ordering,
// elimination tree and the pattern of the factor. CholeskyFactor::Factorize() computes the numeric
// factor L (P A P^T = L L^T) for any matrix with that same pattern, reusing the analysis; it is
// called once per mesh and again after each stiffness change.
//
// The solve is written for the deformation's three right-hand sides (x, y, z): they are stored
// interleaved and solved together, so each triangular pass reads the factor exactly once. The
// factor is stored by supernodes (runs of columns sharing one row pattern, kept as dense row-major
// blocks with one row index per block row), so a pass reads 8 bytes per stored value plus little
// else, and its inner loops are dense. This makes the per-frame solve memory-bound.
#pragma once

#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/solver/supernodal_solve.h"

namespace deform {

enum class Ordering {
  kNatural,  // no reordering (for tests)
  kAmd,      // approximate minimum degree (Eigen's)
  kMetis,    // nested dissection (METIS_NodeND); least fill on large surface meshes
  kAuto,     // both of the above, keeping the one whose factor has fewer non-zeros (AMD tends to
             // win below a few thousand vertices, METIS above)
};

const char* OrderingName(Ordering ordering);

class SymbolicCholesky {
 public:
  // `a` is square and structurally symmetric (both triangles stored), column-major.
  // INVALID_ARGUMENT for a non-square matrix or a missing diagonal entry.
  static StatusOr<std::shared_ptr<const SymbolicCholesky>> Analyze(
      const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, Ordering ordering);

  int size() const { return n_; }
  // The ordering used (kAmd or kMetis when kAuto was asked for).
  Ordering ordering() const { return ordering_; }
  // Non-zeros of the factor L, diagonal included.
  std::int64_t factor_nonzeros() const { return column_pointers_.back(); }

 private:
  friend class CholeskyFactor;
  int n_ = 0;
  Ordering ordering_ = Ordering::kMetis;
  std::vector<int> permutation_;  // permutation_[new] = old
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

class CholeskyFactor {
 public:
  // An empty factor (size 0): Solve3 refuses it. Factorize() makes usable ones.
  CholeskyFactor() = default;

  // `a` must have exactly the pattern that `symbolic` was analysed with. INTERNAL if `a` is not
  // positive definite (names the pivot); INVALID_ARGUMENT for another pattern or a null `symbolic`.
  static StatusOr<CholeskyFactor> Factorize(
      std::shared_ptr<const SymbolicCholesky> symbolic,
      const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a);

  int size() const { return symbolic_ ? symbolic_->size() : 0; }
  // Solves A X = B for three right-hand sides stored interleaved: b[3 i + c] is row i, column c.
  // `x` may equal `b`. `work` holds WorkSize() doubles. Allocation-free; const and thread-safe.
  // Runs the fastest kernel this CPU supports (see supernodal_solve.h). FAILED_PRECONDITION, with
  // nothing written, for an empty (default-constructed) factor.
  Status Solve3(const double* b, double* x, double* work) const;
  // The same with a chosen kernel, which must be available (for tests and benchmarks).
  Status Solve3(const double* b, double* x, double* work, SolveKernel kernel) const;
  // Doubles of scratch Solve3 needs (SolveWorkSize: a four-double row per unknown plus room for
  // the widest supernode). The same for every factor of one symbolic analysis.
  std::size_t WorkSize() const;
  // Bytes one triangular pass reads: the supernodes' values, row indices and pointers.
  std::size_t bytes() const;
  // Non-zeros of L (the explicit zeros of the supernodes' diagonal blocks not counted).
  std::int64_t nonzeros() const { return symbolic_ ? symbolic_->factor_nonzeros() : 0; }

 private:
  SupernodalFactorView View() const;

  std::shared_ptr<const SymbolicCholesky> symbolic_;
  // Supernode s: its rows are row_indices_[row_pointers_[s] .. row_pointers_[s + 1]) (its own
  // columns first, then the rows below, ascending); its values are a dense row-major block of
  // (#rows) by (width) starting at values_[value_pointers_[s]], zero above the diagonal.
  std::vector<std::int64_t> row_pointers_;
  std::vector<std::int64_t> value_pointers_;
  std::vector<int> row_indices_;
  std::vector<double> values_;
};

}  // namespace deform
