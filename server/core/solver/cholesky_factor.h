// The numeric half of the sparse Cholesky (sparse_cholesky.h): the factor L of one matrix with an
// analysed pattern, stored by supernodes, and the three-column triangular solve.
#pragma once

#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/base/cancel_token.h"
#include "core/base/status.h"
#include "core/solver/parallel_solve.h"
#include "core/solver/supernodal_solve.h"
#include "core/solver/symbolic_cholesky.h"

namespace deform {

class CholeskyFactor {
 public:
  // An empty factor (size 0): Solve3 refuses it. Factorize() makes usable ones.
  CholeskyFactor() = default;

  // `a` must have exactly the pattern that `symbolic` was analysed with. INTERNAL if `a` is not
  // positive definite (names the pivot: a column of the factor's order); INVALID_ARGUMENT for
  // another pattern or a null `symbolic`. Supernodal and left-looking
  // (internal/supernodal_numeric.h): each supernode's block updated by its descendants' blocks and
  // factorized in dense kernels, in place in the factor's storage; beside the factor it holds C's
  // lower triangle, the list of updates and, per thread, one update's dense product. `runner`
  // (optional): when it has idle helpers, disjoint subtrees of the supernodal elimination tree
  // (PlanParallelSolve's parts) are factorized on its threads, then the supernodes above them on
  // the calling thread; the factor is the same as on one thread, bit for bit (every supernode's
  // sums run in the same order). `cancel` (optional) is checked before every supernode (at most 128
  // columns, fewer than kCancelCheckRows: symbolic_cholesky.cc, SupernodeColumns) on every thread:
  // once it is cancelled the factorization stops there with FAILED_PRECONDITION "cancelled during
  // the numeric factorization" and frees what it built: a cancel waits for at most one supernode on
  // each thread, not for the whole factorization of a large mesh (docs/performance.md, "Time to
  // first frame").
  static StatusOr<CholeskyFactor> Factorize(
      std::shared_ptr<const SymbolicCholesky> symbolic,
      const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a,
      const CancelToken* cancel = nullptr, ParallelRunner* runner = nullptr);
  static constexpr int kCancelCheckRows = 256;

  int size() const { return symbolic_ ? symbolic_->size() : 0; }
  // Solves A X = B for three right-hand sides stored interleaved: b[3 i + c] is row i, column c.
  // `x` may equal `b`. `work` holds WorkSize() doubles. Allocation-free; const and thread-safe.
  // Runs the fastest kernel this CPU supports (see supernodal_solve.h). FAILED_PRECONDITION, with
  // nothing written, for an empty (default-constructed) factor.
  Status Solve3(const double* b, double* x, double* work) const;
  // The same with a chosen kernel, which must be available (for tests and benchmarks).
  Status Solve3(const double* b, double* x, double* work, SolveKernel kernel) const;
  // Solves A X = B for `columns` (1 to kMaxSolveColumns) right-hand sides stored by rows:
  // b[columns * i + c]; several frames' three coordinates side by side, solved in one pass over
  // the factor. `x` may equal `b`; `work` holds WorkSizeMany(columns) doubles. Allocation-free;
  // const and thread-safe. Each column matches Solve3's to round-off. FAILED_PRECONDITION for an
  // empty factor, INVALID_ARGUMENT for a column count out of range, nothing written either way.
  Status SolveMany(const double* b, double* x, int columns, double* work) const;
  Status SolveMany(const double* b, double* x, int columns, double* work, SolveKernel kernel) const;
  std::size_t WorkSizeMany(int columns) const;
  // SolveMany for `frames` frames (1 to kMaxSolveColumns / 3) of three columns each, every frame
  // in an array of its own stored as Solve3's (b[f][3 i + c]): no packed copy of the batch.
  // x[f] may equal b[f]; `work` holds WorkSizeMany(3 * frames) doubles. Each frame matches its
  // Solve3 to round-off. Allocation-free; const and thread-safe. FAILED_PRECONDITION for an empty
  // factor, INVALID_ARGUMENT for a frame count out of range, nothing written either way.
  Status SolveFrames(const double* const* b, double* const* x, int frames, double* work) const;
  Status SolveFrames(const double* const* b, double* const* x, int frames, double* work,
                     SolveKernel kernel) const;
  // Solve3 on several threads (parallel_solve.h): `plan` from PlanParallel (of this factor or one
  // of the same analysis), its parts run through `runner`; `work` holds WorkSizeParallel(plan)
  // doubles. Matches Solve3 to round-off. Allocation-free; const and thread-safe.
  // FAILED_PRECONDITION for an empty factor, INVALID_ARGUMENT for a plan without parts.
  ParallelSolvePlan PlanParallel(int parts) const;
  std::size_t WorkSizeParallel(const ParallelSolvePlan& plan) const;
  Status Solve3Parallel(const ParallelSolvePlan& plan, const double* b, double* x, double* work,
                        ParallelRunner* runner) const;
  Status Solve3Parallel(const ParallelSolvePlan& plan, const double* b, double* x, double* work,
                        ParallelRunner* runner, SolveKernel kernel) const;
  // SolveFrames on several threads (ParallelSolveFrames) as Solve3Parallel splits Solve3: `work`
  // holds WorkSizeFramesParallel(plan, frames) doubles. Each frame matches its Solve3 to
  // round-off. Allocation-free; const and thread-safe. FAILED_PRECONDITION for an empty factor,
  // INVALID_ARGUMENT for a plan without parts or a frame count out of range.
  std::size_t WorkSizeFramesParallel(const ParallelSolvePlan& plan, int frames) const;
  Status SolveFramesParallel(const ParallelSolvePlan& plan, const double* const* b,
                             double* const* x, int frames, double* work,
                             ParallelRunner* runner) const;
  Status SolveFramesParallel(const ParallelSolvePlan& plan, const double* const* b,
                             double* const* x, int frames, double* work, ParallelRunner* runner,
                             SolveKernel kernel) const;
  // Doubles of scratch Solve3 needs (SolveWorkSize: a four-double row per unknown plus room for
  // the widest supernode). The same for every factor of one symbolic analysis.
  std::size_t WorkSize() const;
  // Bytes one triangular pass reads: the supernodes' values, row indices and pointers.
  std::size_t bytes() const;
  // A copy of this factor whose values are rounded to float32: half the bytes of the values for
  // every pass to read (the solves still compute in double). Its solutions differ from this
  // factor's by the rounding of L, about cond(A) * 6e-8 at worst; the caller measures the
  // difference where it matters (DeformationModel's float32 probe). Empty for an empty factor.
  CholeskyFactor RoundedToFloat32() const;
  bool stores_float32() const { return !float_values_.empty(); }
  // bytes() of this factor in double: what it takes while it is built (a float32 factor is built
  // in double, then rounded).
  std::size_t bytes_as_built() const { return bytes() + float_values_.size() * sizeof(float); }
  // Non-zeros of L (the explicit zeros of the supernodes' diagonal blocks not counted).
  std::int64_t nonzeros() const { return symbolic_ ? symbolic_->factor_nonzeros() : 0; }

  // The forward pass for the unit right-hand side e_i: y = L^-1 P e_i, which is non-zero only on
  // the columns of the supernodes from the one holding i's column to the root (a path of the
  // elimination tree), so that (A^-1)_ij = y_i . y_j costs a path, not a solve. Writes the path's
  // supernodes, ascending, into `path` and y on their columns, concatenated in that order, into
  // `values`; returns the path's length, or -1 when y holds more than `max_values` values.
  // `work`: size() doubles, zero on entry and left zero. Allocation-free; const and thread-safe.
  int ForwardUnitSolve(int i, int* path, double* values, std::int64_t max_values,
                       double* work) const;
  // ForwardUnitSolve for e_{vertices[t]}, t < count, several at a time so that each supernode on
  // their paths is read once for the group rather than once a path: path t into
  // paths[t * path_stride ...] (path_stride at least the longest path's supernodes), its length
  // into lengths[t], its values into values[t * value_stride ...] (at least the longest path's
  // columns). The same values as ForwardUnitSolve. `work`: UnitSolvesWorkSize() doubles, zero on
  // entry and left zero. Allocation-free; const and thread-safe.
  void ForwardUnitSolves(const int* vertices, int count, int* paths, int path_stride, int* lengths,
                         double* values, std::int64_t value_stride, double* work) const;
  std::size_t UnitSolvesWorkSize() const;
  // The backward half of Solve3: x = P^T L^-T z for three columns z given in the factor's order
  // (z[3 c + k], c a column of L), so that M^-1 sum_j e_{i_j} w_j^T = P^T L^-T sum_j y_j w_j^T
  // costs one pass once the forward passes y_j are known (ForwardUnitSolve). `x` may equal `z`;
  // `work` holds WorkSize() doubles.
  Status SolveBackward3(const double* z, double* x, double* work) const;
  // SolveBackward3 for `columns` columns (1 to kMaxSolveColumns, z[columns * c + k]), all in one
  // pass over the factor: two combinations of the same forward passes cost one read of it. `x`
  // may equal `z`; `work` holds WorkSizeMany(columns) doubles. INVALID_ARGUMENT for a column
  // count out of range.
  Status SolveBackwardMany(const double* z, double* x, int columns, double* work) const;
  // Supernode s's first column (in the factor's order).
  int SupernodeFirstColumn(int s) const;
  // The most columns and the most supernodes on one path (what ForwardUnitSolve may write).
  void LongestUnitSolvePath(std::int64_t* columns, int* supernodes) const;
  // Supernode s's columns (in the factor's order): [first, first + width).
  int SupernodeWidth(int s) const;
  // L in the factor's order (P A P^T = L L^T, P the analysis' permutation()), column-major, with
  // the supernodes' explicit zeros: for tests and tools, not for solving. Empty (0 by 0) for an
  // empty factor; a float32 factor gives its rounded values.
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> FactorMatrix() const;

 private:
  using ColMajorMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  // C = P A P^T's lower triangle by columns (each column's rows ascending), with its values.
  struct LowerTriangle {
    std::vector<std::int64_t> pointers;
    std::vector<int> rows;
    std::vector<double> values;
  };
  // The steps of Factorize().
  static Status CheckAnalysedPattern(const SymbolicCholesky& s, const ColMajorMatrix& a);
  static std::vector<double> PermutedUpperValues(const SymbolicCholesky& s,
                                                 const ColMajorMatrix& a);
  static LowerTriangle PermutedLowerTriangle(const SymbolicCholesky& s, const ColMajorMatrix& a);
  void LayOutSupernodes(const LowerTriangle& lower);
  Status FactorizeSupernodal(const ColMajorMatrix& a, const CancelToken* cancel,
                             ParallelRunner* runner);

  SupernodalFactorView View() const;

  std::shared_ptr<const SymbolicCholesky> symbolic_;
  // Supernode s: its rows are row_indices_[row_pointers_[s] .. row_pointers_[s + 1]) (its own
  // columns first, then the rows below, ascending); its values are a dense row-major block of
  // (#rows) by (width) starting at values_[value_pointers_[s]], zero above the diagonal.
  std::vector<std::int64_t> row_pointers_;
  std::vector<std::int64_t> value_pointers_;
  std::vector<int> row_indices_;
  std::vector<double> values_;  // empty in a float32 factor, which holds float_values_ instead
  std::vector<float> float_values_;
};

}  // namespace deform
