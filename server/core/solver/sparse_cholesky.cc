#include "core/solver/sparse_cholesky.h"

#include <metis.h>

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace deform {
namespace {

using ColMajorMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Adjacency of A without its diagonal, in METIS's CSR form.
void BuildGraph(const ColMajorMatrix& a, std::vector<idx_t>* xadj, std::vector<idx_t>* adjncy) {
  const int n = static_cast<int>(a.cols());
  xadj->assign(n + 1, 0);
  adjncy->clear();
  adjncy->reserve(a.nonZeros());
  for (int j = 0; j < n; ++j) {
    for (ColMajorMatrix::InnerIterator it(a, j); it; ++it) {
      if (it.row() != j) adjncy->push_back(it.row());
    }
    (*xadj)[j + 1] = static_cast<idx_t>(adjncy->size());
  }
}

StatusOr<std::vector<int>> ComputeOrdering(const ColMajorMatrix& a, Ordering ordering) {
  const int n = static_cast<int>(a.cols());
  std::vector<int> permutation(n);
  std::iota(permutation.begin(), permutation.end(), 0);
  if (ordering == Ordering::kNatural || n <= 1) return permutation;
  if (ordering == Ordering::kAmd) {
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse;
    Eigen::AMDOrdering<int> amd;
    amd(a.selfadjointView<Eigen::Lower>(), inverse);  // Eigen returns new -> old as its inverse
    for (int i = 0; i < n; ++i) permutation[i] = inverse.indices()[i];
    return permutation;
  }
  std::vector<idx_t> xadj, adjncy;
  BuildGraph(a, &xadj, &adjncy);
  if (adjncy.empty()) return permutation;  // diagonal matrix: any order is fill-free
  idx_t nvtxs = n;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;  // deterministic ordering from run to run
  std::vector<idx_t> perm(n), iperm(n);
  const int rc =
      METIS_NodeND(&nvtxs, xadj.data(), adjncy.data(), nullptr, options, perm.data(), iperm.data());
  if (rc != METIS_OK)
    return Status::Internal("METIS_NodeND failed with code " + std::to_string(rc));
  for (int i = 0; i < n; ++i) permutation[i] = perm[i];  // METIS: row i of P A P^T is row perm[i]
  return permutation;
}

// Nonzero pattern of row k of L, from column k of C's upper triangle and the elimination tree
// (CSparse's ereach). Writes the pattern to stack[top..n-1] in topological order; returns top.
int RowPattern(int k, const std::vector<int>& cp, const std::vector<int>& ci,
               const std::vector<int>& parent, std::vector<int>* stack, std::vector<int>* mark) {
  const int n = static_cast<int>(parent.size());
  int top = n;
  (*mark)[k] = k;
  for (int p = cp[k]; p < cp[k + 1]; ++p) {
    int i = ci[p];
    if (i > k) continue;
    int len = 0;
    for (; (*mark)[i] != k; i = parent[i]) {
      (*stack)[len++] = i;
      (*mark)[i] = k;
    }
    while (len > 0) (*stack)[--top] = (*stack)[--len];
  }
  return top;
}

}  // namespace

const char* OrderingName(Ordering ordering) {
  switch (ordering) {
    case Ordering::kNatural:
      return "natural";
    case Ordering::kAmd:
      return "amd";
    case Ordering::kMetis:
      return "metis";
    case Ordering::kAuto:
      return "auto";
  }
  return "unknown";
}

StatusOr<std::shared_ptr<const SymbolicCholesky>> SymbolicCholesky::Analyze(const ColMajorMatrix& a,
                                                                            Ordering ordering) {
  if (a.rows() != a.cols()) return Status::InvalidArgument("Cholesky needs a square matrix");
  if (!a.isCompressed()) return Status::InvalidArgument("Cholesky needs a compressed matrix");
  if (ordering == Ordering::kAuto) {
    DEFORM_ASSIGN_OR_RETURN(auto amd, Analyze(a, Ordering::kAmd));
    DEFORM_ASSIGN_OR_RETURN(auto metis, Analyze(a, Ordering::kMetis));
    return amd->factor_nonzeros() < metis->factor_nonzeros() ? amd : metis;
  }
  const int n = static_cast<int>(a.cols());
  auto s = std::make_shared<SymbolicCholesky>();
  s->n_ = n;
  s->ordering_ = ordering;
  DEFORM_ASSIGN_OR_RETURN(s->permutation_, ComputeOrdering(a, ordering));
  std::vector<int> inverse(n);
  for (int i = 0; i < n; ++i) inverse[s->permutation_[i]] = i;

  // Pattern of C = P A P^T (upper part) and the map from A's entries to C's.
  s->a_nonzeros_ = a.nonZeros();
  s->a_column_pointers_.assign(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  s->a_row_indices_.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  std::vector<int> counts(n + 1, 0);
  std::vector<bool> has_diagonal(n, false);
  for (int j = 0; j < n; ++j) {
    for (ColMajorMatrix::InnerIterator it(a, j); it; ++it) {
      const int r = inverse[it.row()], c = inverse[j];
      if (r <= c) ++counts[c + 1];
      if (it.row() == j) has_diagonal[j] = true;
    }
  }
  for (int j = 0; j < n; ++j) {
    if (!has_diagonal[j]) {
      return Status::InvalidArgument("matrix has no diagonal entry in column " + std::to_string(j));
    }
  }
  s->c_column_pointers_.assign(n + 1, 0);
  std::partial_sum(counts.begin(), counts.end(), s->c_column_pointers_.begin());
  s->c_row_indices_.assign(s->c_column_pointers_[n], 0);
  s->a_to_c_.assign(a.nonZeros(), -1);
  std::vector<int> next(s->c_column_pointers_.begin(), s->c_column_pointers_.end() - 1);
  for (int j = 0; j < n; ++j) {
    for (int p = a.outerIndexPtr()[j]; p < a.outerIndexPtr()[j + 1]; ++p) {
      const int r = inverse[a.innerIndexPtr()[p]], c = inverse[j];
      if (r > c) continue;
      s->a_to_c_[p] = next[c];
      s->c_row_indices_[next[c]++] = r;
    }
  }
  // Sort rows within each column (keeping the map consistent).
  {
    std::vector<int> position_of(s->c_row_indices_.size());
    std::vector<std::pair<int, int>> column;
    for (int c = 0; c < n; ++c) {
      column.clear();
      for (int p = s->c_column_pointers_[c]; p < s->c_column_pointers_[c + 1]; ++p) {
        column.emplace_back(s->c_row_indices_[p], p);
      }
      std::sort(column.begin(), column.end());
      for (int q = 0; q < static_cast<int>(column.size()); ++q) {
        const int p = s->c_column_pointers_[c] + q;
        s->c_row_indices_[p] = column[q].first;
        position_of[column[q].second] = p;
      }
    }
    for (int& target : s->a_to_c_) {
      if (target >= 0) target = position_of[target];
    }
  }

  // Elimination tree of C (CSparse's cs_etree with path compression).
  s->elimination_tree_.assign(n, -1);
  std::vector<int> ancestor(n, -1);
  for (int k = 0; k < n; ++k) {
    for (int p = s->c_column_pointers_[k]; p < s->c_column_pointers_[k + 1]; ++p) {
      for (int i = s->c_row_indices_[p]; i != -1 && i < k;) {
        const int next_i = ancestor[i];
        ancestor[i] = k;
        if (next_i == -1) {
          s->elimination_tree_[i] = k;
          break;
        }
        i = next_i;
      }
    }
  }

  // Column counts of L from the row patterns.
  std::vector<std::int64_t> column_counts(n, 1);  // the diagonal
  std::vector<int> stack(n), mark(n, -1);
  for (int k = 0; k < n; ++k) {
    const int top = RowPattern(k, s->c_column_pointers_, s->c_row_indices_, s->elimination_tree_,
                               &stack, &mark);
    for (int t = top; t < n; ++t) ++column_counts[stack[t]];
  }
  s->column_pointers_.assign(n + 1, 0);
  std::partial_sum(column_counts.begin(), column_counts.end(), s->column_pointers_.begin() + 1);
  // Supernodes: column j joins j - 1's supernode when j is j - 1's parent and its pattern is
  // j - 1's minus j - 1 (equal counts minus one imply equal patterns below).
  constexpr int kMaxSupernodeWidth = 128;
  s->supernode_columns_.assign(1, 0);
  for (int j = 1; j < n; ++j) {
    const bool continues = s->elimination_tree_[j - 1] == j &&
                           column_counts[j] == column_counts[j - 1] - 1 &&
                           j - s->supernode_columns_.back() < kMaxSupernodeWidth;
    if (!continues) s->supernode_columns_.push_back(j);
  }
  s->supernode_columns_.push_back(n);
  s->max_supernode_width_ = 1;
  for (size_t k = 0; k + 1 < s->supernode_columns_.size(); ++k) {
    s->max_supernode_width_ =
        std::max(s->max_supernode_width_, s->supernode_columns_[k + 1] - s->supernode_columns_[k]);
  }
  if (s->column_pointers_[n] > std::numeric_limits<int>::max()) {
    return Status::ResourceExhausted("Cholesky factor would have " +
                                     std::to_string(s->column_pointers_[n]) + " non-zeros");
  }
  return std::shared_ptr<const SymbolicCholesky>(std::move(s));
}

StatusOr<CholeskyFactor> CholeskyFactor::Factorize(std::shared_ptr<const SymbolicCholesky> symbolic,
                                                   const ColMajorMatrix& a) {
  if (!symbolic) return Status::InvalidArgument("no symbolic analysis to factorise with");
  const SymbolicCholesky& s = *symbolic;
  const int n = s.n_;
  if (a.rows() != n || a.cols() != n || a.nonZeros() != s.a_nonzeros_ || !a.isCompressed() ||
      !std::equal(s.a_column_pointers_.begin(), s.a_column_pointers_.end(), a.outerIndexPtr()) ||
      !std::equal(s.a_row_indices_.begin(), s.a_row_indices_.end(), a.innerIndexPtr())) {
    return Status::InvalidArgument("matrix pattern differs from the analysed one");
  }
  // Values of C's upper triangle.
  std::vector<double> c_values(s.c_row_indices_.size(), 0.0);
  for (std::int64_t p = 0; p < s.a_nonzeros_; ++p) {
    if (s.a_to_c_[p] >= 0) c_values[s.a_to_c_[p]] = a.valuePtr()[p];
  }

  // Column-compressed L first (the diagonal first in each column, rows ascending).
  std::vector<int> l_rows(s.column_pointers_[n], 0);
  std::vector<double> l_values(s.column_pointers_[n], 0.0);
  std::vector<std::int64_t> next(s.column_pointers_.begin(), s.column_pointers_.end() - 1);
  std::vector<double> x(n, 0.0);
  std::vector<int> stack(n), mark(n, -1);

  // Up-looking factorisation (CSparse's cs_chol): row k of L from the rows above it.
  for (int k = 0; k < n; ++k) {
    const int top =
        RowPattern(k, s.c_column_pointers_, s.c_row_indices_, s.elimination_tree_, &stack, &mark);
    x[k] = 0;
    for (int p = s.c_column_pointers_[k]; p < s.c_column_pointers_[k + 1]; ++p) {
      if (s.c_row_indices_[p] <= k) x[s.c_row_indices_[p]] = c_values[p];
    }
    double d = x[k];
    x[k] = 0;
    for (int t = top; t < n; ++t) {
      const int i = stack[t];
      const double lki = x[i] / l_values[s.column_pointers_[i]];
      x[i] = 0;
      for (std::int64_t p = s.column_pointers_[i] + 1; p < next[i]; ++p) {
        x[l_rows[p]] -= l_values[p] * lki;
      }
      d -= lki * lki;
      const std::int64_t q = next[i]++;
      l_rows[q] = k;
      l_values[q] = lki;
    }
    if (!(d > 0) || !std::isfinite(d)) {
      return Status::Internal("matrix is not positive definite (pivot " + std::to_string(k) +
                              " is " + std::to_string(d) + ")");
    }
    const std::int64_t q = next[k]++;
    l_rows[q] = k;
    l_values[q] = std::sqrt(d);
  }

  // Pack into supernodal blocks.
  CholeskyFactor f;
  const int num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  f.row_pointers_.assign(num_supernodes + 1, 0);
  f.value_pointers_.assign(num_supernodes + 1, 0);
  for (int sn = 0; sn < num_supernodes; ++sn) {
    const int first = s.supernode_columns_[sn];
    const int width = s.supernode_columns_[sn + 1] - first;
    const std::int64_t rows = s.column_pointers_[first + 1] - s.column_pointers_[first];
    f.row_pointers_[sn + 1] = f.row_pointers_[sn] + rows;
    f.value_pointers_[sn + 1] = f.value_pointers_[sn] + rows * width;
  }
  f.row_indices_.resize(f.row_pointers_.back());
  f.values_.assign(f.value_pointers_.back() + kSolveValuePadding, 0.0);
  for (int sn = 0; sn < num_supernodes; ++sn) {
    const int first = s.supernode_columns_[sn];
    const int width = s.supernode_columns_[sn + 1] - first;
    const std::int64_t rows = f.row_pointers_[sn + 1] - f.row_pointers_[sn];
    std::copy(l_rows.begin() + s.column_pointers_[first],
              l_rows.begin() + s.column_pointers_[first + 1],
              f.row_indices_.begin() + f.row_pointers_[sn]);
    double* block = f.values_.data() + f.value_pointers_[sn];
    for (int c = 0; c < width; ++c) {
      // Column first + c holds the block's rows c.. (its pattern is the supernode's minus c rows).
      const std::int64_t begin = s.column_pointers_[first + c];
      for (std::int64_t k = c; k < rows; ++k) block[k * width + c] = l_values[begin + (k - c)];
    }
  }
  f.symbolic_ = std::move(symbolic);
  return f;
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
  Solve3For(kernel)(View(), b, x, work);
  return Status::Ok();
}

SupernodalFactorView CholeskyFactor::View() const {
  const SymbolicCholesky& s = *symbolic_;
  SupernodalFactorView view;
  view.size = s.n_;
  view.num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  view.supernode_columns = s.supernode_columns_.data();
  view.permutation = s.permutation_.data();
  view.row_pointers = row_pointers_.data();
  view.value_pointers = value_pointers_.data();
  view.row_indices = row_indices_.data();
  view.values = values_.data();
  return view;
}

std::size_t CholeskyFactor::bytes() const {
  if (!symbolic_) return 0;
  return values_.size() * sizeof(double) + row_indices_.size() * sizeof(int) +
         (row_pointers_.size() + value_pointers_.size()) * sizeof(std::int64_t) +
         symbolic_->supernode_columns_.size() * sizeof(int);
}

}  // namespace deform
