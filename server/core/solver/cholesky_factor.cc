#include "core/solver/cholesky_factor.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "internal/supernodal_numeric.h"
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
                                                   const CancelToken* cancel,
                                                   ParallelRunner* runner) {
  if (!symbolic) return Status::InvalidArgument("no symbolic analysis to factorize with");
  DEFORM_RETURN_IF_ERROR(CheckAnalysedPattern(*symbolic, a));
  CholeskyFactor f;
  f.symbolic_ = std::move(symbolic);
  DEFORM_RETURN_IF_ERROR(f.FactorizeSupernodal(a, cancel, runner));
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

// C's lower triangle by columns: the transpose of its upper triangle's pattern, with its values.
CholeskyFactor::LowerTriangle CholeskyFactor::PermutedLowerTriangle(const SymbolicCholesky& s,
                                                                    const ColMajorMatrix& a) {
  const std::vector<double> upper = PermutedUpperValues(s, a);
  const int n = s.n_;
  LowerTriangle lower;
  lower.pointers.assign(n + 1, 0);
  for (const int row : s.c_row_indices_) ++lower.pointers[row + 1];
  for (int j = 0; j < n; ++j) lower.pointers[j + 1] += lower.pointers[j];
  lower.rows.resize(upper.size());
  lower.values.resize(upper.size());
  std::vector<std::int64_t> next(lower.pointers.begin(), lower.pointers.end() - 1);
  for (int column = 0; column < n; ++column) {  // ascending: each lower column's rows ascend
    for (int p = s.c_column_pointers_[column]; p < s.c_column_pointers_[column + 1]; ++p) {
      const std::int64_t q = next[s.c_row_indices_[p]]++;
      lower.rows[q] = column;
      lower.values[q] = upper[p];
    }
  }
  return lower;
}

// The supernodal layout (the class comment), every block zero and every row index in place.
void CholeskyFactor::LayOutSupernodes(const LowerTriangle& lower) {
  const SymbolicCholesky& s = *symbolic_;
  const int num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  // Supernode sn's rows: its own columns, then its last column's pattern below that column (every
  // member column's pattern lies in them: symbolic_cholesky.cc, SupernodeColumns).
  row_pointers_.assign(num_supernodes + 1, 0);
  value_pointers_.assign(num_supernodes + 1, 0);
  for (int sn = 0; sn < num_supernodes; ++sn) {
    const int first = s.supernode_columns_[sn], last = s.supernode_columns_[sn + 1] - 1;
    const int width = last - first + 1;
    const std::int64_t rows = static_cast<std::int64_t>(last - first) +
                              s.column_pointers_[last + 1] - s.column_pointers_[last];
    row_pointers_[sn + 1] = row_pointers_[sn] + rows;
    value_pointers_[sn + 1] = value_pointers_[sn] + rows * width;
  }
  row_indices_.resize(row_pointers_.back());
  values_.assign(value_pointers_.back() + kSolveValuePadding, 0.0);
  solver_internal::SupernodeRows(s.n_, s.supernode_columns_, row_pointers_, lower.pointers,
                                 lower.rows, row_indices_.data());
}

Status CholeskyFactor::FactorizeSupernodal(const ColMajorMatrix& a, const CancelToken* cancel,
                                           ParallelRunner* runner) {
  const SymbolicCholesky& s = *symbolic_;
  const LowerTriangle lower = PermutedLowerTriangle(s, a);
  LayOutSupernodes(lower);
  const solver_internal::SupernodalUpdates updates = solver_internal::PlanSupernodalUpdates(
      s.n_, s.supernode_columns_, row_pointers_, row_indices_);
  solver_internal::SupernodalNumericInput input;
  input.size = s.n_;
  input.num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  input.supernode_columns = s.supernode_columns_.data();
  input.row_pointers = row_pointers_.data();
  input.value_pointers = value_pointers_.data();
  input.row_indices = row_indices_.data();
  input.lower_pointers = lower.pointers.data();
  input.lower_rows = lower.rows.data();
  input.lower_values = lower.values.data();
  input.updates = &updates;
  input.values = values_.data();
  const int helpers = runner != nullptr ? runner->IdleHelpers() : 0;
  const ParallelSolvePlan plan =
      helpers > 0 ? PlanParallelSolve(View(), 1 + helpers) : ParallelSolvePlan();
  if (plan.parts < 2) {
    std::vector<int> all(input.num_supernodes);
    for (int sn = 0; sn < input.num_supernodes; ++sn) all[sn] = sn;
    solver_internal::SupernodalWorkspace work;
    return solver_internal::FactorizeSupernodes(input, all.data(), input.num_supernodes, &work,
                                                cancel)
        .status;
  }
  // The parts' subtrees side by side (each reads only its own supernodes), then the top.
  struct Job {
    const solver_internal::SupernodalNumericInput* input;
    const ParallelSolvePlan* plan;
    const CancelToken* cancel;
    std::vector<solver_internal::SupernodalResult> results;
  } job{&input, &plan, cancel, std::vector<solver_internal::SupernodalResult>(plan.parts)};
  runner->Run(
      plan.parts,
      [](void* context, int part) {
        Job& j = *static_cast<Job*>(context);
        const int begin = j.plan->part_offsets[part], end = j.plan->part_offsets[part + 1];
        solver_internal::SupernodalWorkspace work;
        j.results[part] = solver_internal::FactorizeSupernodes(
            *j.input, j.plan->part_supernodes.data() + begin, end - begin, &work, j.cancel);
      },
      &job);
  // A failed part: the smallest column that failed (cancellation first), as one thread would.
  const solver_internal::SupernodalResult* failed = nullptr;
  for (const solver_internal::SupernodalResult& r : job.results) {
    if (r.status.ok()) continue;
    if (failed == nullptr || r.failed_column < 0 ||
        (failed->failed_column >= 0 && r.failed_column < failed->failed_column)) {
      failed = &r;
    }
  }
  if (failed != nullptr) return failed->status;
  solver_internal::SupernodalWorkspace work;
  return solver_internal::FactorizeSupernodes(input, plan.top.data(),
                                              static_cast<int>(plan.top.size()), &work, cancel)
      .status;
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

Status CholeskyFactor::SolveBackward3(const double* z, double* x, double* work) const {
  if (!symbolic_) return Status::FailedPrecondition("the Cholesky factor is empty");
  SolveKernelFunctionsFor(BestSolveKernel()).solve_backward3(View(), z, x, work);
  return Status::Ok();
}

Status CholeskyFactor::SolveBackwardMany(const double* z, double* x, int columns,
                                         double* work) const {
  if (!symbolic_) return Status::FailedPrecondition("the Cholesky factor is empty");
  if (columns < 1 || columns > kMaxSolveColumns) {
    return Status::InvalidArgument("a backward pass takes 1 to " +
                                   std::to_string(kMaxSolveColumns) + " columns, not " +
                                   std::to_string(columns));
  }
  SolveKernelFunctionsFor(BestSolveKernel()).solve_backward_many(View(), z, x, columns, work);
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

void CholeskyFactor::ForwardUnitSolves(const int* vertices, int count, int* paths, int path_stride,
                                       int* lengths, double* values, std::int64_t value_stride,
                                       double* work) const {
  deform::ForwardUnitSolves(View(), vertices, count, paths, path_stride, lengths, values,
                            value_stride, work);
}

std::size_t CholeskyFactor::UnitSolvesWorkSize() const {
  return static_cast<std::size_t>(size()) * kUnitSolveBlock;
}

void CholeskyFactor::LongestUnitSolvePath(std::int64_t* columns, int* supernodes) const {
  deform::LongestUnitSolvePath(View(), columns, supernodes);
}

int CholeskyFactor::SupernodeFirstColumn(int s) const { return symbolic_->supernode_columns_[s]; }

int CholeskyFactor::SupernodeWidth(int s) const {
  return symbolic_->supernode_columns_[s + 1] - symbolic_->supernode_columns_[s];
}

Eigen::SparseMatrix<double, Eigen::ColMajor, int> CholeskyFactor::FactorMatrix() const {
  if (!symbolic_) return {};
  const SymbolicCholesky& s = *symbolic_;
  std::vector<Eigen::Triplet<double, int>> entries;
  entries.reserve(static_cast<std::size_t>(value_pointers_.back()));
  for (std::size_t sn = 0; sn + 1 < row_pointers_.size(); ++sn) {
    const int first = s.supernode_columns_[sn];
    const int width = s.supernode_columns_[sn + 1] - first;
    for (std::int64_t k = 0; k < row_pointers_[sn + 1] - row_pointers_[sn]; ++k) {
      const int row = row_indices_[row_pointers_[sn] + k];
      for (int c = 0; c < width && first + c <= row; ++c) {
        const std::int64_t at = value_pointers_[sn] + k * width + c;
        entries.emplace_back(
            row, first + c,
            stores_float32() ? static_cast<double>(float_values_[at]) : values_[at]);
      }
    }
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> l(s.n_, s.n_);
  l.setFromTriplets(entries.begin(), entries.end());
  return l;
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
