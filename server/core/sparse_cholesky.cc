#include "core/sparse_cholesky.h"

#include <metis.h>

#include <Eigen/OrderingMethods>
#include <cmath>
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
  const int rc = METIS_NodeND(&nvtxs, xadj.data(), adjncy.data(), nullptr, options, perm.data(),
                              iperm.data());
  if (rc != METIS_OK) return Status::Internal("METIS_NodeND failed with code " + std::to_string(rc));
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
    case Ordering::kNatural: return "natural";
    case Ordering::kAmd: return "amd";
    case Ordering::kMetis: return "metis";
  }
  return "unknown";
}

StatusOr<std::shared_ptr<const SymbolicCholesky>> SymbolicCholesky::Analyze(const ColMajorMatrix& a,
                                                                            Ordering ordering) {
  if (a.rows() != a.cols()) return Status::InvalidArgument("Cholesky needs a square matrix");
  if (!a.isCompressed()) return Status::InvalidArgument("Cholesky needs a compressed matrix");
  const int n = static_cast<int>(a.cols());
  auto s = std::make_shared<SymbolicCholesky>();
  s->n_ = n;
  s->ordering_ = ordering;
  DEFORM_ASSIGN_OR_RETURN(s->permutation_, ComputeOrdering(a, ordering));
  std::vector<int> inverse(n);
  for (int i = 0; i < n; ++i) inverse[s->permutation_[i]] = i;

  // Pattern of C = P A P^T (upper part) and the map from A's entries to C's.
  s->a_nonzeros_ = a.nonZeros();
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
  if (s->column_pointers_[n] > std::numeric_limits<int>::max()) {
    return Status::ResourceExhausted("Cholesky factor would have " +
                                     std::to_string(s->column_pointers_[n]) + " non-zeros");
  }
  return std::shared_ptr<const SymbolicCholesky>(std::move(s));
}

StatusOr<CholeskyFactor> CholeskyFactor::Factorize(std::shared_ptr<const SymbolicCholesky> symbolic,
                                                   const ColMajorMatrix& a) {
  const SymbolicCholesky& s = *symbolic;
  const int n = s.n_;
  if (a.rows() != n || a.cols() != n || a.nonZeros() != s.a_nonzeros_ || !a.isCompressed()) {
    return Status::InvalidArgument("matrix pattern differs from the analysed one");
  }
  // Values of C's upper triangle.
  std::vector<double> c_values(s.c_row_indices_.size(), 0.0);
  for (std::int64_t p = 0; p < s.a_nonzeros_; ++p) {
    if (s.a_to_c_[p] >= 0) c_values[s.a_to_c_[p]] = a.valuePtr()[p];
  }

  CholeskyFactor f;
  f.symbolic_ = std::move(symbolic);
  f.row_indices_.assign(s.column_pointers_[n], 0);
  f.values_.assign(s.column_pointers_[n], 0.0);
  std::vector<std::int64_t> next(s.column_pointers_.begin(), s.column_pointers_.end() - 1);
  std::vector<double> x(n, 0.0);
  std::vector<int> stack(n), mark(n, -1);

  // Up-looking factorisation (CSparse's cs_chol): row k of L from the rows above it.
  for (int k = 0; k < n; ++k) {
    const int top = RowPattern(k, s.c_column_pointers_, s.c_row_indices_, s.elimination_tree_,
                               &stack, &mark);
    x[k] = 0;
    for (int p = s.c_column_pointers_[k]; p < s.c_column_pointers_[k + 1]; ++p) {
      if (s.c_row_indices_[p] <= k) x[s.c_row_indices_[p]] = c_values[p];
    }
    double d = x[k];
    x[k] = 0;
    for (int t = top; t < n; ++t) {
      const int i = stack[t];
      const double lki = x[i] / f.values_[s.column_pointers_[i]];
      x[i] = 0;
      for (std::int64_t p = s.column_pointers_[i] + 1; p < next[i]; ++p) {
        x[f.row_indices_[p]] -= f.values_[p] * lki;
      }
      d -= lki * lki;
      const std::int64_t q = next[i]++;
      f.row_indices_[q] = k;
      f.values_[q] = lki;
    }
    if (!(d > 0) || !std::isfinite(d)) {
      return Status::Internal("matrix is not positive definite (pivot " + std::to_string(k) +
                              " is " + std::to_string(d) + ")");
    }
    const std::int64_t q = next[k]++;
    f.row_indices_[q] = k;
    f.values_[q] = std::sqrt(d);
  }
  return f;
}

void CholeskyFactor::Solve3(const double* b, double* x, double* work) const {
  const SymbolicCholesky& s = *symbolic_;
  const int n = s.n_;
  const int* perm = s.permutation_.data();
  const std::int64_t* cp = s.column_pointers_.data();
  const int* ri = row_indices_.data();
  const double* lx = values_.data();
  double* y = work;

  for (int i = 0; i < n; ++i) {
    const double* src = b + 3 * static_cast<std::ptrdiff_t>(perm[i]);
    y[3 * i] = src[0];
    y[3 * i + 1] = src[1];
    y[3 * i + 2] = src[2];
  }
  // L y = P b, one pass over L.
  for (int j = 0; j < n; ++j) {
    const double inv_diagonal = 1.0 / lx[cp[j]];
    const double y0 = y[3 * j] * inv_diagonal;
    const double y1 = y[3 * j + 1] * inv_diagonal;
    const double y2 = y[3 * j + 2] * inv_diagonal;
    y[3 * j] = y0;
    y[3 * j + 1] = y1;
    y[3 * j + 2] = y2;
    for (std::int64_t p = cp[j] + 1; p < cp[j + 1]; ++p) {
      double* yi = y + 3 * static_cast<std::ptrdiff_t>(ri[p]);
      const double v = lx[p];
      yi[0] -= v * y0;
      yi[1] -= v * y1;
      yi[2] -= v * y2;
    }
  }
  // L^T z = y, one pass over L backwards.
  for (int j = n - 1; j >= 0; --j) {
    double s0 = y[3 * j], s1 = y[3 * j + 1], s2 = y[3 * j + 2];
    for (std::int64_t p = cp[j] + 1; p < cp[j + 1]; ++p) {
      const double* yi = y + 3 * static_cast<std::ptrdiff_t>(ri[p]);
      const double v = lx[p];
      s0 -= v * yi[0];
      s1 -= v * yi[1];
      s2 -= v * yi[2];
    }
    const double inv_diagonal = 1.0 / lx[cp[j]];
    y[3 * j] = s0 * inv_diagonal;
    y[3 * j + 1] = s1 * inv_diagonal;
    y[3 * j + 2] = s2 * inv_diagonal;
  }
  for (int i = 0; i < n; ++i) {
    double* dst = x + 3 * static_cast<std::ptrdiff_t>(perm[i]);
    dst[0] = y[3 * i];
    dst[1] = y[3 * i + 1];
    dst[2] = y[3 * i + 2];
  }
}

std::size_t CholeskyFactor::bytes() const {
  if (!symbolic_) return 0;
  return values_.size() * sizeof(double) + row_indices_.size() * sizeof(int) +
         symbolic_->column_pointers_.size() * sizeof(std::int64_t);
}

}  // namespace deform
