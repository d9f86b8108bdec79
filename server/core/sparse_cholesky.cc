#include "core/sparse_cholesky.h"

#include <metis.h>

#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <type_traits>

// The solve kernels are compiled twice, for AVX2+FMA and for the baseline, and picked at load
// time by the CPU (GCC's target_clones), so one binary runs everywhere and fast where it can.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define DEFORM_SOLVE_KERNEL __attribute__((target_clones("arch=haswell", "default")))
#else
#define DEFORM_SOLVE_KERNEL
#endif

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
  f.values_.assign(f.value_pointers_.back(), 0.0);
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
  return symbolic_ ? 3 * static_cast<std::size_t>(symbolic_->n_ + symbolic_->max_supernode_width_)
                   : 0;
}

namespace {

// The supernode kernels. A supernode's own unknowns are kept planar (all x, then y, then z) in a
// small buffer while its block is applied, so every inner loop is a contiguous dot product or
// axpy over the block's row; kWidth > 0 fixes the width at compile time (the common narrow
// supernodes), 0 reads it at run time.
template <int kWidth>
DEFORM_SOLVE_KERNEL void ForwardUpdate(const double* __restrict block, const int* __restrict rows,
                                       std::int64_t first_row, std::int64_t num_rows,
                                       int dynamic_width, const double* __restrict planar,
                                       double* __restrict y) {
  const int width = kWidth > 0 ? kWidth : dynamic_width;
  const double* px = planar;
  const double* py = planar + width;
  const double* pz = planar + 2 * width;
  std::int64_t r = first_row;
  if (kWidth == 0) {
    // Four rows at a time share each load of the supernode's unknowns.
    for (; r + 4 <= num_rows; r += 4) {
      const double* row0 = block + r * width;
      const double* row1 = row0 + width;
      const double* row2 = row1 + width;
      const double* row3 = row2 + width;
      double a0 = 0, a1 = 0, a2 = 0, b0 = 0, b1 = 0, b2 = 0;
      double c0 = 0, c1 = 0, c2 = 0, d0 = 0, d1 = 0, d2 = 0;
      for (int k = 0; k < width; ++k) {
        const double x = px[k], yv = py[k], z = pz[k];
        a0 += row0[k] * x;
        a1 += row0[k] * yv;
        a2 += row0[k] * z;
        b0 += row1[k] * x;
        b1 += row1[k] * yv;
        b2 += row1[k] * z;
        c0 += row2[k] * x;
        c1 += row2[k] * yv;
        c2 += row2[k] * z;
        d0 += row3[k] * x;
        d1 += row3[k] * yv;
        d2 += row3[k] * z;
      }
      double* t0 = y + 3 * static_cast<std::ptrdiff_t>(rows[r]);
      double* t1 = y + 3 * static_cast<std::ptrdiff_t>(rows[r + 1]);
      double* t2 = y + 3 * static_cast<std::ptrdiff_t>(rows[r + 2]);
      double* t3 = y + 3 * static_cast<std::ptrdiff_t>(rows[r + 3]);
      t0[0] -= a0;
      t0[1] -= a1;
      t0[2] -= a2;
      t1[0] -= b0;
      t1[1] -= b1;
      t1[2] -= b2;
      t2[0] -= c0;
      t2[1] -= c1;
      t2[2] -= c2;
      t3[0] -= d0;
      t3[1] -= d1;
      t3[2] -= d2;
    }
  }
  for (; r < num_rows; ++r) {
    const double* row = block + r * width;
    double s0 = 0, s1 = 0, s2 = 0;
    for (int k = 0; k < width; ++k) {
      s0 += row[k] * px[k];
      s1 += row[k] * py[k];
      s2 += row[k] * pz[k];
    }
    double* target = y + 3 * static_cast<std::ptrdiff_t>(rows[r]);
    target[0] -= s0;
    target[1] -= s1;
    target[2] -= s2;
  }
}

template <int kWidth>
DEFORM_SOLVE_KERNEL void BackwardUpdate(const double* __restrict block, const int* __restrict rows,
                                        std::int64_t first_row, std::int64_t num_rows,
                                        int dynamic_width, double* __restrict planar,
                                        const double* __restrict y) {
  const int width = kWidth > 0 ? kWidth : dynamic_width;
  double* px = planar;
  double* py = planar + width;
  double* pz = planar + 2 * width;
  std::int64_t r = first_row;
  if (kWidth == 0) {
    // Four rows at a time share each load and store of the accumulators.
    for (; r + 4 <= num_rows; r += 4) {
      const double* row0 = block + r * width;
      const double* row1 = row0 + width;
      const double* row2 = row1 + width;
      const double* row3 = row2 + width;
      const double* s0 = y + 3 * static_cast<std::ptrdiff_t>(rows[r]);
      const double* s1 = y + 3 * static_cast<std::ptrdiff_t>(rows[r + 1]);
      const double* s2 = y + 3 * static_cast<std::ptrdiff_t>(rows[r + 2]);
      const double* s3 = y + 3 * static_cast<std::ptrdiff_t>(rows[r + 3]);
      const double a0 = s0[0], a1 = s0[1], a2 = s0[2], b0 = s1[0], b1 = s1[1], b2 = s1[2];
      const double c0 = s2[0], c1 = s2[1], c2 = s2[2], d0 = s3[0], d1 = s3[1], d2 = s3[2];
      for (int k = 0; k < width; ++k) {
        px[k] -= row0[k] * a0 + row1[k] * b0 + row2[k] * c0 + row3[k] * d0;
        py[k] -= row0[k] * a1 + row1[k] * b1 + row2[k] * c1 + row3[k] * d1;
        pz[k] -= row0[k] * a2 + row1[k] * b2 + row2[k] * c2 + row3[k] * d2;
      }
    }
  }
  for (; r < num_rows; ++r) {
    const double* row = block + r * width;
    const double* source = y + 3 * static_cast<std::ptrdiff_t>(rows[r]);
    const double z0 = source[0], z1 = source[1], z2 = source[2];
    for (int k = 0; k < width; ++k) {
      px[k] -= row[k] * z0;
      py[k] -= row[k] * z1;
      pz[k] -= row[k] * z2;
    }
  }
}

// Forward substitution with a supernode's dense lower-triangular diagonal block (row-major,
// `width` square): solves for its unknowns, given interleaved in `ys`, writing them back to `ys`
// and planar into `planar`. Rows go four at a time, so the sums over the already solved unknowns
// run as twelve independent chains instead of three.
DEFORM_SOLVE_KERNEL void ForwardDiagonal(const double* __restrict block, int width,
                                         double* __restrict ys, double* __restrict planar) {
  double* px = planar;
  double* py = planar + width;
  double* pz = planar + 2 * width;
  int c = 0;
  for (; c + 4 <= width; c += 4) {
    const double* r0 = block + c * width;
    const double* r1 = r0 + width;
    const double* r2 = r1 + width;
    const double* r3 = r2 + width;
    double a0 = ys[3 * c], a1 = ys[3 * c + 1], a2 = ys[3 * c + 2];
    double b0 = ys[3 * c + 3], b1 = ys[3 * c + 4], b2 = ys[3 * c + 5];
    double c0 = ys[3 * c + 6], c1 = ys[3 * c + 7], c2 = ys[3 * c + 8];
    double d0 = ys[3 * c + 9], d1 = ys[3 * c + 10], d2 = ys[3 * c + 11];
    for (int k = 0; k < c; ++k) {
      const double x = px[k], y = py[k], z = pz[k];
      a0 -= r0[k] * x;
      a1 -= r0[k] * y;
      a2 -= r0[k] * z;
      b0 -= r1[k] * x;
      b1 -= r1[k] * y;
      b2 -= r1[k] * z;
      c0 -= r2[k] * x;
      c1 -= r2[k] * y;
      c2 -= r2[k] * z;
      d0 -= r3[k] * x;
      d1 -= r3[k] * y;
      d2 -= r3[k] * z;
    }
    // The 4 by 4 triangle at the tile's corner.
    px[c] = a0 / r0[c];
    py[c] = a1 / r0[c];
    pz[c] = a2 / r0[c];
    b0 -= r1[c] * px[c];
    b1 -= r1[c] * py[c];
    b2 -= r1[c] * pz[c];
    px[c + 1] = b0 / r1[c + 1];
    py[c + 1] = b1 / r1[c + 1];
    pz[c + 1] = b2 / r1[c + 1];
    c0 -= r2[c] * px[c] + r2[c + 1] * px[c + 1];
    c1 -= r2[c] * py[c] + r2[c + 1] * py[c + 1];
    c2 -= r2[c] * pz[c] + r2[c + 1] * pz[c + 1];
    px[c + 2] = c0 / r2[c + 2];
    py[c + 2] = c1 / r2[c + 2];
    pz[c + 2] = c2 / r2[c + 2];
    d0 -= r3[c] * px[c] + r3[c + 1] * px[c + 1] + r3[c + 2] * px[c + 2];
    d1 -= r3[c] * py[c] + r3[c + 1] * py[c + 1] + r3[c + 2] * py[c + 2];
    d2 -= r3[c] * pz[c] + r3[c + 1] * pz[c + 1] + r3[c + 2] * pz[c + 2];
    px[c + 3] = d0 / r3[c + 3];
    py[c + 3] = d1 / r3[c + 3];
    pz[c + 3] = d2 / r3[c + 3];
  }
  for (; c < width; ++c) {
    const double* row = block + c * width;
    double s0 = ys[3 * c], s1 = ys[3 * c + 1], s2 = ys[3 * c + 2];
    for (int k = 0; k < c; ++k) {
      s0 -= row[k] * px[k];
      s1 -= row[k] * py[k];
      s2 -= row[k] * pz[k];
    }
    px[c] = s0 / row[c];
    py[c] = s1 / row[c];
    pz[c] = s2 / row[c];
  }
  for (int k = 0; k < width; ++k) {
    ys[3 * k] = px[k];
    ys[3 * k + 1] = py[k];
    ys[3 * k + 2] = pz[k];
  }
}

// Back substitution with the transpose of the diagonal block: `planar` holds the right-hand side
// on entry; the solution goes to `ys` (interleaved). Each solved unknown updates the ones before
// it along its contiguous row of the block (independent updates, no long sums).
DEFORM_SOLVE_KERNEL void BackwardDiagonal(const double* __restrict block, int width,
                                          double* __restrict ys, double* __restrict planar) {
  double* px = planar;
  double* py = planar + width;
  double* pz = planar + 2 * width;
  for (int c = width - 1; c >= 0; --c) {
    const double* row = block + c * width;
    const double x0 = px[c] / row[c], x1 = py[c] / row[c], x2 = pz[c] / row[c];
    ys[3 * c] = x0;
    ys[3 * c + 1] = x1;
    ys[3 * c + 2] = x2;
    for (int k = 0; k < c; ++k) {
      px[k] -= row[k] * x0;
      py[k] -= row[k] * x1;
      pz[k] -= row[k] * x2;
    }
  }
}

template <typename Kernel>
void DispatchByWidth(int width, Kernel&& kernel) {
  switch (width) {
    case 1:
      kernel(std::integral_constant<int, 1>());
      break;
    case 2:
      kernel(std::integral_constant<int, 2>());
      break;
    case 3:
      kernel(std::integral_constant<int, 3>());
      break;
    case 4:
      kernel(std::integral_constant<int, 4>());
      break;
    default:
      kernel(std::integral_constant<int, 0>());
      break;
  }
}

}  // namespace

void CholeskyFactor::Solve3(const double* b, double* x, double* work) const {
  const SymbolicCholesky& s = *symbolic_;
  const int n = s.n_;
  const int num_supernodes = static_cast<int>(s.supernode_columns_.size()) - 1;
  const int* perm = s.permutation_.data();
  double* __restrict y = work;
  double* __restrict planar = work + 3 * static_cast<std::ptrdiff_t>(n);  // 3 * widest supernode

  for (int i = 0; i < n; ++i) {
    const double* src = b + 3 * static_cast<std::ptrdiff_t>(perm[i]);
    y[3 * i] = src[0];
    y[3 * i + 1] = src[1];
    y[3 * i + 2] = src[2];
  }

  // L y = P b, one pass over the factor.
  for (int sn = 0; sn < num_supernodes; ++sn) {
    const int first = s.supernode_columns_[sn];
    const int width = s.supernode_columns_[sn + 1] - first;
    const int* rows = row_indices_.data() + row_pointers_[sn];
    const std::int64_t num_rows = row_pointers_[sn + 1] - row_pointers_[sn];
    const double* block = values_.data() + value_pointers_[sn];
    double* ys = y + 3 * static_cast<std::ptrdiff_t>(first);  // the supernode's own unknowns
    ForwardDiagonal(block, width, ys, planar);
    DispatchByWidth(width, [&](auto w) {
      ForwardUpdate<decltype(w)::value>(block, rows, width, num_rows, width, planar, y);
    });
  }

  // L^T z = y, one pass over the factor backwards.
  for (int sn = num_supernodes - 1; sn >= 0; --sn) {
    const int first = s.supernode_columns_[sn];
    const int width = s.supernode_columns_[sn + 1] - first;
    const int* rows = row_indices_.data() + row_pointers_[sn];
    const std::int64_t num_rows = row_pointers_[sn + 1] - row_pointers_[sn];
    const double* block = values_.data() + value_pointers_[sn];
    double* ys = y + 3 * static_cast<std::ptrdiff_t>(first);
    for (int k = 0; k < width; ++k) {
      planar[k] = ys[3 * k];
      planar[width + k] = ys[3 * k + 1];
      planar[2 * width + k] = ys[3 * k + 2];
    }
    DispatchByWidth(width, [&](auto w) {
      BackwardUpdate<decltype(w)::value>(block, rows, width, num_rows, width, planar, y);
    });
    BackwardDiagonal(block, width, ys, planar);
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
         (row_pointers_.size() + value_pointers_.size()) * sizeof(std::int64_t) +
         symbolic_->supernode_columns_.size() * sizeof(int);
}

}  // namespace deform
