#include "core/solver/cholesky_factor.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "internal/row_pattern.h"
#include "internal/unit_solve.h"

namespace deform {
namespace {

// INVALID_ARGUMENT unless a batch of `frames` frames fits a batched solve's columns.
Status CheckFrameCount(int frames) {
  if (frames < 1 || 3 * frames > kMaxSolveColumns) {
    return Status::InvalidArgument("a batched solve takes 1 to " +
                                   std::to_string(kMaxSolveColumns / 3) + " frames, not " +
                                   std::to_string(frames));
  }
  return Status::Ok();
}

}  // namespace

StatusOr<CholeskyFactor> CholeskyFactor::Factorize(std::shared_ptr<const SymbolicCholesky> symbolic,
                                                   const ColMajorMatrix& a,
                                                   const CancelToken* cancel) {
  if (!symbolic) return Status::InvalidArgument("no symbolic analysis to factorize with");
  DEFORM_RETURN_IF_ERROR(CheckAnalysedPattern(*symbolic, a));
  DEFORM_ASSIGN_OR_RETURN(const ColumnFactor l,
                          UpLookingCholesky(*symbolic, PermutedUpperValues(*symbolic, a), cancel));
  CholeskyFactor f;
  f.PackSupernodes(*symbolic, l);
  f.symbolic_ = std::move(symbolic);
  return f;
}

Status CholeskyFactor::CheckAnalysedPattern(const SymbolicCholesky& s, const ColMajorMatrix& a) {
  const int n = s.n_;
  if (a.rows() != n || a.cols() != n || a.nonZeros() != s.a_nonzeros_ || !a.isCompressed() ||
      !std::equal(s.a_column_pointers_.begin(), s.a_column_pointers_.end(), a.outerIndexPtr()) ||
      !std::equal(s.a_row_indices_.begin(), s.a_row_indices_.end(), a.innerIndexPtr())) {
    return Status::InvalidArgument("matrix pattern differs from the analysed one");
  }
  return Status::Ok();
}

// The values of C = P A P^T's upper triangle, in the analysed pattern.
std::vector<double> CholeskyFactor::PermutedUpperValues(const SymbolicCholesky& s,
                                                        const ColMajorMatrix& a) {
  std::vector<double> c_values(s.c_row_indices_.size(), 0.0);
  for (std::int64_t p = 0; p < s.a_nonzeros_; ++p) {
    if (s.a_to_c_[p] >= 0) c_values[s.a_to_c_[p]] = a.valuePtr()[p];
  }
  return c_values;
}

// Up-looking factorization (CSparse's cs_chol): row k of L from the rows above it.
StatusOr<CholeskyFactor::ColumnFactor> CholeskyFactor::UpLookingCholesky(
    const SymbolicCholesky& s, const std::vector<double>& c_values, const CancelToken* cancel) {
  const int n = s.n_;
  ColumnFactor l{std::vector<int>(s.column_pointers_[n], 0),
                 std::vector<double>(s.column_pointers_[n], 0.0)};
  std::vector<std::int64_t> next(s.column_pointers_.begin(), s.column_pointers_.end() - 1);
  std::vector<double> x(n, 0.0);
  std::vector<int> stack(n), mark(n, -1);
  for (int k = 0; k < n; ++k) {
    if (k % kCancelCheckRows == 0) {
      DEFORM_RETURN_IF_ERROR(CheckCancelled(cancel, "the numeric factorization"));
    }
    const int top = solver_internal::RowPattern(k, s.c_column_pointers_, s.c_row_indices_,
                                                s.elimination_tree_, &stack, &mark);
    x[k] = 0;
    for (int p = s.c_column_pointers_[k]; p < s.c_column_pointers_[k + 1]; ++p) {
      if (s.c_row_indices_[p] <= k) x[s.c_row_indices_[p]] = c_values[p];
    }
    double d = x[k];
    x[k] = 0;
    for (int t = top; t < n; ++t) {
      const int i = stack[t];
      const double lki = x[i] / l.values[s.column_pointers_[i]];
      x[i] = 0;
      for (std::int64_t p = s.column_pointers_[i] + 1; p < next[i]; ++p) {
        x[l.rows[p]] -= l.values[p] * lki;
      }
      d -= lki * lki;
      const std::int64_t q = next[i]++;
      l.rows[q] = k;
      l.values[q] = lki;
    }
    if (!(d > 0) || !std::isfinite(d)) {
      return Status::Internal("matrix is not positive definite (pivot " + std::to_string(k) +
                              " is " + std::to_string(d) + ")");
    }
    const std::int64_t q = next[k]++;
    l.rows[q] = k;
    l.values[q] = std::sqrt(d);
  }
  return l;
}

// Packs `l` into supernodal blocks (the layout in the class comment).
void CholeskyFactor::PackSupernodes(const SymbolicCholesky& s, const ColumnFactor& l) {
  const int num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  // Supernode sn's rows: its own columns, then its last column's pattern below that column (every
  // member column's pattern lies in them: symbolic_cholesky.cc, SupernodeColumns).
  const auto rows_of = [&](int sn) {
    const int first = s.supernode_columns_[sn], last = s.supernode_columns_[sn + 1] - 1;
    return static_cast<std::int64_t>(last - first) + s.column_pointers_[last + 1] -
           s.column_pointers_[last];
  };
  row_pointers_.assign(num_supernodes + 1, 0);
  value_pointers_.assign(num_supernodes + 1, 0);
  for (int sn = 0; sn < num_supernodes; ++sn) {
    const int width = s.supernode_columns_[sn + 1] - s.supernode_columns_[sn];
    const std::int64_t rows = rows_of(sn);
    row_pointers_[sn + 1] = row_pointers_[sn] + rows;
    value_pointers_[sn + 1] = value_pointers_[sn] + rows * width;
  }
  row_indices_.resize(row_pointers_.back());
  values_.assign(value_pointers_.back() + kSolveValuePadding, 0.0);
  std::vector<std::int64_t> position(static_cast<std::size_t>(s.n_), -1);  // row -> block row
  for (int sn = 0; sn < num_supernodes; ++sn) {
    const int first = s.supernode_columns_[sn];
    const int last = s.supernode_columns_[sn + 1] - 1;
    const int width = last - first + 1;
    int* rows = row_indices_.data() + row_pointers_[sn];
    for (int c = 0; c < width - 1; ++c) rows[c] = first + c;
    std::copy(l.rows.begin() + s.column_pointers_[last],
              l.rows.begin() + s.column_pointers_[last + 1], rows + (width - 1));
    const std::int64_t count = row_pointers_[sn + 1] - row_pointers_[sn];
    for (std::int64_t k = 0; k < count; ++k) position[rows[k]] = k;
    double* block = values_.data() + value_pointers_[sn];
    for (int c = 0; c < width; ++c) {
      for (std::int64_t p = s.column_pointers_[first + c]; p < s.column_pointers_[first + c + 1];
           ++p) {
        block[position[l.rows[p]] * width + c] = l.values[p];
      }
    }
  }
}

std::size_t CholeskyFactor::WorkSize() const {
  return symbolic_ ? static_cast<std::size_t>(
                         SolveWorkSize(symbolic_->n_, symbolic_->max_supernode_width_))
                   : 0;
}

Status CholeskyFactor::Solve3(const double* b, double* x, double* work) const {
  return Solve3(b, x, work, BestSolveKernel());
}

Status CholeskyFactor::Solve3(const double* b, double* x, double* work, SolveKernel kernel) const {
  if (!symbolic_) return Status::FailedPrecondition("the Cholesky factor is empty");
  SolveKernelFunctionsFor(kernel).solve3(View(), b, x, work);
  return Status::Ok();
}

std::size_t CholeskyFactor::WorkSizeMany(int columns) const {
  return symbolic_ ? static_cast<std::size_t>(SolveManyWorkSize(symbolic_->n_, columns)) : 0;
}

Status CholeskyFactor::SolveMany(const double* b, double* x, int columns, double* work) const {
  return SolveMany(b, x, columns, work, BestSolveKernel());
}

Status CholeskyFactor::SolveMany(const double* b, double* x, int columns, double* work,
                                 SolveKernel kernel) const {
  if (!symbolic_) return Status::FailedPrecondition("the Cholesky factor is empty");
  if (columns < 1 || columns > kMaxSolveColumns) {
    return Status::InvalidArgument("a batched solve takes 1 to " +
                                   std::to_string(kMaxSolveColumns) + " columns, not " +
                                   std::to_string(columns));
  }
  SolveKernelFunctionsFor(kernel).solve_many(View(), b, x, columns, work);
  return Status::Ok();
}

Status CholeskyFactor::SolveFrames(const double* const* b, double* const* x, int frames,
                                   double* work) const {
  return SolveFrames(b, x, frames, work, BestSolveKernel());
}

Status CholeskyFactor::SolveFrames(const double* const* b, double* const* x, int frames,
                                   double* work, SolveKernel kernel) const {
  if (!symbolic_) return Status::FailedPrecondition("the Cholesky factor is empty");
  DEFORM_RETURN_IF_ERROR(CheckFrameCount(frames));
  SolveKernelFunctionsFor(kernel).solve_frames(View(), b, x, frames, work);
  return Status::Ok();
}

ParallelSolvePlan CholeskyFactor::PlanParallel(int parts) const {
  return symbolic_ ? PlanParallelSolve(View(), parts) : ParallelSolvePlan();
}

std::size_t CholeskyFactor::WorkSizeParallel(const ParallelSolvePlan& plan) const {
  return symbolic_ ? static_cast<std::size_t>(ParallelSolveWorkSize(symbolic_->n_, plan)) : 0;
}

Status CholeskyFactor::Solve3Parallel(const ParallelSolvePlan& plan, const double* b, double* x,
                                      double* work, ParallelRunner* runner) const {
  return Solve3Parallel(plan, b, x, work, runner, BestSolveKernel());
}

Status CholeskyFactor::Solve3Parallel(const ParallelSolvePlan& plan, const double* b, double* x,
                                      double* work, ParallelRunner* runner,
                                      SolveKernel kernel) const {
  if (!symbolic_) return Status::FailedPrecondition("solve with an empty factor");
  if (plan.parts < 2) return Status::InvalidArgument("a parallel solve needs a plan with parts");
  ParallelSolve3(View(), plan, kernel, b, x, work, runner);
  return Status::Ok();
}

std::size_t CholeskyFactor::WorkSizeFramesParallel(const ParallelSolvePlan& plan,
                                                   int frames) const {
  return symbolic_ ? static_cast<std::size_t>(
                         ParallelSolveFramesWorkSize(symbolic_->n_, plan, std::max(frames, 1)))
                   : 0;
}

Status CholeskyFactor::SolveFramesParallel(const ParallelSolvePlan& plan, const double* const* b,
                                           double* const* x, int frames, double* work,
                                           ParallelRunner* runner) const {
  return SolveFramesParallel(plan, b, x, frames, work, runner, BestSolveKernel());
}

Status CholeskyFactor::SolveFramesParallel(const ParallelSolvePlan& plan, const double* const* b,
                                           double* const* x, int frames, double* work,
                                           ParallelRunner* runner, SolveKernel kernel) const {
  if (!symbolic_) return Status::FailedPrecondition("solve with an empty factor");
  if (plan.parts < 2) return Status::InvalidArgument("a parallel solve needs a plan with parts");
  DEFORM_RETURN_IF_ERROR(CheckFrameCount(frames));
  ParallelSolveFrames(View(), plan, kernel, b, x, frames, work, runner);
  return Status::Ok();
}

int CholeskyFactor::ForwardUnitSolve(int i, int* path, double* values, std::int64_t max_values,
                                     double* work) const {
  return deform::ForwardUnitSolve(View(), i, path, values, max_values, work);
}

void CholeskyFactor::LongestUnitSolvePath(std::int64_t* columns, int* supernodes) const {
  deform::LongestUnitSolvePath(View(), columns, supernodes);
}

int CholeskyFactor::SupernodeWidth(int s) const {
  return symbolic_->supernode_columns_[s + 1] - symbolic_->supernode_columns_[s];
}

SupernodalFactorView CholeskyFactor::View() const {
  const SymbolicCholesky& s = *symbolic_;
  SupernodalFactorView view;
  view.size = s.n_;
  view.num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  view.supernode_columns = s.supernode_columns_.data();
  view.permutation = s.permutation_.data();
  view.inverse_permutation = s.inverse_permutation_.data();
  view.row_pointers = row_pointers_.data();
  view.value_pointers = value_pointers_.data();
  view.row_indices = row_indices_.data();
  if (stores_float32()) {
    view.float_values = float_values_.data();
  } else {
    view.values = values_.data();
  }
  return view;
}

CholeskyFactor CholeskyFactor::RoundedToFloat32() const {
  CholeskyFactor rounded;
  if (!symbolic_) return rounded;
  rounded.symbolic_ = symbolic_;
  rounded.row_pointers_ = row_pointers_;
  rounded.value_pointers_ = value_pointers_;
  rounded.row_indices_ = row_indices_;
  if (stores_float32()) {
    rounded.float_values_ = float_values_;
  } else {
    rounded.float_values_.assign(values_.begin(), values_.end());  // the padding zeros too
  }
  return rounded;
}

std::size_t CholeskyFactor::bytes() const {
  if (!symbolic_) return 0;
  return values_.size() * sizeof(double) + float_values_.size() * sizeof(float) +
         row_indices_.size() * sizeof(int) +
         (row_pointers_.size() + value_pointers_.size()) * sizeof(std::int64_t) +
         symbolic_->supernode_columns_.size() * sizeof(int);
}

}  // namespace deform
