#include "unit_solve.h"

#include <algorithm>
#include <vector>

#include "core/base/cpu_features.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace deform {
namespace {

// The supernode holding column `column` (permuted order).
int SupernodeOf(const SupernodalFactorView& f, int column) {
  const int* end = f.supernode_columns + f.num_supernodes + 1;
  return static_cast<int>(std::upper_bound(f.supernode_columns, end, column) -
                          f.supernode_columns) -
         1;
}

// The parent supernode of s: the one holding s's first row below its own columns; -1 at a root.
int ParentOf(const SupernodalFactorView& f, int s) {
  const int width = f.supernode_columns[s + 1] - f.supernode_columns[s];
  const std::int64_t rows = f.row_pointers[s + 1] - f.row_pointers[s];
  return rows > width ? SupernodeOf(f, f.row_indices[f.row_pointers[s] + width]) : -1;
}

template <typename Value>
int ForwardUnitSolveWith(const SupernodalFactorView& f, const Value* values_of_factor, int i,
                         int* path, double* values, std::int64_t max_values, double* work) {
  const int start = f.inverse_permutation[i];
  work[start] = 1;
  int length = 0;
  std::int64_t written = 0;
  for (int s = SupernodeOf(f, start); s >= 0;) {
    const int first = f.supernode_columns[s];
    const int width = f.supernode_columns[s + 1] - first;
    const std::int64_t rows = f.row_pointers[s + 1] - f.row_pointers[s];
    const Value* block = values_of_factor + f.value_pointers[s];
    double* y = work + first;
    // The diagonal block: lower triangular, row-major.
    for (int r = 0; r < width; ++r) {
      double v = y[r];
      for (int q = 0; q < r; ++q) v -= static_cast<double>(block[r * width + q]) * y[q];
      y[r] = v / static_cast<double>(block[r * width + r]);
    }
    // The rows below, all on ancestors of s.
    const int* row_index = f.row_indices + f.row_pointers[s];
    for (std::int64_t r = width; r < rows; ++r) {
      double v = 0;
      for (int q = 0; q < width; ++q) v += static_cast<double>(block[r * width + q]) * y[q];
      work[row_index[r]] -= v;
    }
    if (written + width > max_values) {
      // Leave `work` zero as promised: this and every later supernode's columns.
      for (int t = s; t >= 0; t = ParentOf(f, t)) {
        std::fill(work + f.supernode_columns[t], work + f.supernode_columns[t + 1], 0.0);
      }
      return -1;
    }
    std::copy(y, y + width, values + written);
    std::fill(y, y + width, 0.0);
    written += width;
    path[length++] = s;
    s = ParentOf(f, s);
  }
  return length;
}

// One supernode of ForwardUnitSolves for every lane of the block at once (a lane whose path does
// not pass through the supernode is zero on its columns, so it stays zero and scatters zeros):
// the diagonal block's triangular solve on `y` (its columns, kUnitSolveBlock lanes a column), then
// the rows below subtracted from their columns in `work`. Each lane's sums are ForwardUnitSolve's,
// in its order.
template <typename Value>
void ApplySupernode(const Value* block, int width, std::int64_t rows, const int* row_index,
                    double* y, double* work) {
  constexpr int B = kUnitSolveBlock;
  for (int r = 0; r < width; ++r) {
    double v[B];
    for (int t = 0; t < B; ++t) v[t] = y[r * B + t];
    const Value* row = block + static_cast<std::int64_t>(r) * width;
    for (int q = 0; q < r; ++q) {
      const double l = static_cast<double>(row[q]);
      for (int t = 0; t < B; ++t) v[t] -= l * y[q * B + t];
    }
    const double d = static_cast<double>(row[r]);
    for (int t = 0; t < B; ++t) y[r * B + t] = v[t] / d;
  }
  for (std::int64_t r = width; r < rows; ++r) {
    double v[B] = {};
    const Value* row = block + r * width;
    for (int q = 0; q < width; ++q) {
      const double l = static_cast<double>(row[q]);
      for (int t = 0; t < B; ++t) v[t] += l * y[q * B + t];
    }
    double* target = work + static_cast<std::int64_t>(row_index[r]) * B;
    for (int t = 0; t < B; ++t) target[t] -= v[t];
  }
}

#if defined(__x86_64__) || defined(__i386__)
static_assert(kUnitSolveBlock == 8, "the AVX2 kernel holds a column's lanes in two registers");

// ApplySupernode with AVX2 (multiplies and subtractions, no fused ones, so every lane rounds as
// the portable kernel and ForwardUnitSolve do); four rows below the diagonal at a time, so each
// column's lanes are loaded once for four rows.
template <typename Value>
__attribute__((target("avx2"))) void ApplySupernodeAvx2(const Value* block, int width,
                                                        std::int64_t rows, const int* row_index,
                                                        double* y, double* work) {
  for (int r = 0; r < width; ++r) {
    __m256d lo = _mm256_loadu_pd(y + 8 * r), hi = _mm256_loadu_pd(y + 8 * r + 4);
    const Value* row = block + static_cast<std::int64_t>(r) * width;
    for (int q = 0; q < r; ++q) {
      const __m256d l = _mm256_set1_pd(static_cast<double>(row[q]));
      lo = _mm256_sub_pd(lo, _mm256_mul_pd(l, _mm256_loadu_pd(y + 8 * q)));
      hi = _mm256_sub_pd(hi, _mm256_mul_pd(l, _mm256_loadu_pd(y + 8 * q + 4)));
    }
    const __m256d d = _mm256_set1_pd(static_cast<double>(row[r]));
    _mm256_storeu_pd(y + 8 * r, _mm256_div_pd(lo, d));
    _mm256_storeu_pd(y + 8 * r + 4, _mm256_div_pd(hi, d));
  }
  std::int64_t r = width;
  for (; r + 4 <= rows; r += 4) {
    __m256d lo[4], hi[4];
    for (int u = 0; u < 4; ++u) lo[u] = hi[u] = _mm256_setzero_pd();
    const Value* row = block + r * width;
    for (int q = 0; q < width; ++q) {
      const __m256d ylo = _mm256_loadu_pd(y + 8 * q), yhi = _mm256_loadu_pd(y + 8 * q + 4);
      for (int u = 0; u < 4; ++u) {
        const __m256d l = _mm256_set1_pd(static_cast<double>(row[u * width + q]));
        lo[u] = _mm256_add_pd(lo[u], _mm256_mul_pd(l, ylo));
        hi[u] = _mm256_add_pd(hi[u], _mm256_mul_pd(l, yhi));
      }
    }
    for (int u = 0; u < 4; ++u) {
      double* target = work + static_cast<std::int64_t>(row_index[r + u]) * 8;
      _mm256_storeu_pd(target, _mm256_sub_pd(_mm256_loadu_pd(target), lo[u]));
      _mm256_storeu_pd(target + 4, _mm256_sub_pd(_mm256_loadu_pd(target + 4), hi[u]));
    }
  }
  for (; r < rows; ++r) {
    __m256d lo = _mm256_setzero_pd(), hi = _mm256_setzero_pd();
    const Value* row = block + r * width;
    for (int q = 0; q < width; ++q) {
      const __m256d l = _mm256_set1_pd(static_cast<double>(row[q]));
      lo = _mm256_add_pd(lo, _mm256_mul_pd(l, _mm256_loadu_pd(y + 8 * q)));
      hi = _mm256_add_pd(hi, _mm256_mul_pd(l, _mm256_loadu_pd(y + 8 * q + 4)));
    }
    double* target = work + static_cast<std::int64_t>(row_index[r]) * 8;
    _mm256_storeu_pd(target, _mm256_sub_pd(_mm256_loadu_pd(target), lo));
    _mm256_storeu_pd(target + 4, _mm256_sub_pd(_mm256_loadu_pd(target + 4), hi));
  }
}

#else
template <typename Value>
void ApplySupernodeAvx2(const Value* block, int width, std::int64_t rows, const int* row_index,
                        double* y, double* work) {
  ApplySupernode(block, width, rows, row_index, y, work);
}
#endif

template <typename Value>
void ForwardUnitSolvesWith(const SupernodalFactorView& f, const Value* values_of_factor,
                           const int* columns_of, int count, int* paths, int path_stride,
                           int* lengths, double* values, std::int64_t value_stride, double* work,
                           bool use_avx2) {
  constexpr int B = kUnitSolveBlock;
  int next[B];
  std::int64_t written[B];
  for (int t = 0; t < count; ++t) {
    const int start = f.inverse_permutation[columns_of[t]];
    work[static_cast<std::int64_t>(start) * B + t] = 1;
    next[t] = SupernodeOf(f, start);
    lengths[t] = 0;
    written[t] = 0;
  }
  for (;;) {
    // The lowest supernode any path still has to climb: every contribution to its columns comes
    // from supernodes below it, which every path through it has done already.
    int s = -1;
    for (int t = 0; t < count; ++t) {
      if (next[t] >= 0 && (s < 0 || next[t] < s)) s = next[t];
    }
    if (s < 0) return;
    const int first = f.supernode_columns[s];
    const int width = f.supernode_columns[s + 1] - first;
    const std::int64_t rows = f.row_pointers[s + 1] - f.row_pointers[s];
    const Value* block = values_of_factor + f.value_pointers[s];
    double* y = work + static_cast<std::int64_t>(first) * B;
    const int* row_index = f.row_indices + f.row_pointers[s];
    if (use_avx2) {
      ApplySupernodeAvx2(block, width, rows, row_index, y, work);
    } else {
      ApplySupernode(block, width, rows, row_index, y, work);
    }
    const int parent = ParentOf(f, s);
    for (int t = 0; t < count; ++t) {
      if (next[t] != s) continue;
      double* out = values + t * value_stride + written[t];
      for (int q = 0; q < width; ++q) out[q] = y[q * B + t];
      written[t] += width;
      paths[t * path_stride + lengths[t]++] = s;
      next[t] = parent;
    }
    std::fill(y, y + static_cast<std::int64_t>(width) * B, 0.0);
  }
}

}  // namespace

void ForwardUnitSolves(const SupernodalFactorView& factor, const int* columns, int count,
                       int* paths, int path_stride, int* lengths, double* values,
                       std::int64_t value_stride, double* work) {
  static const bool use_avx2 = CpuHasAvx2();
  for (int begin = 0; begin < count; begin += kUnitSolveBlock) {
    const int block = std::min(kUnitSolveBlock, count - begin);
    if (factor.float_values != nullptr) {
      ForwardUnitSolvesWith(factor, factor.float_values, columns + begin, block,
                            paths + static_cast<std::int64_t>(begin) * path_stride, path_stride,
                            lengths + begin, values + begin * value_stride, value_stride, work,
                            use_avx2);
    } else {
      ForwardUnitSolvesWith(factor, factor.values, columns + begin, block,
                            paths + static_cast<std::int64_t>(begin) * path_stride, path_stride,
                            lengths + begin, values + begin * value_stride, value_stride, work,
                            use_avx2);
    }
  }
}

int ForwardUnitSolve(const SupernodalFactorView& factor, int i, int* path, double* values,
                     std::int64_t max_values, double* work) {
  return factor.float_values != nullptr
             ? ForwardUnitSolveWith(factor, factor.float_values, i, path, values, max_values, work)
             : ForwardUnitSolveWith(factor, factor.values, i, path, values, max_values, work);
}

void LongestUnitSolvePath(const SupernodalFactorView& f, std::int64_t* columns, int* supernodes) {
  // Parents have higher numbers, so one pass from the top sets every chain's length.
  std::vector<std::int64_t> chain_columns(f.num_supernodes, 0);
  std::vector<int> chain_supernodes(f.num_supernodes, 0);
  *columns = 0;
  *supernodes = 0;
  for (int s = f.num_supernodes - 1; s >= 0; --s) {
    const int parent = ParentOf(f, s);
    const int width = f.supernode_columns[s + 1] - f.supernode_columns[s];
    chain_columns[s] = width + (parent >= 0 ? chain_columns[parent] : 0);
    chain_supernodes[s] = 1 + (parent >= 0 ? chain_supernodes[parent] : 0);
    *columns = std::max(*columns, chain_columns[s]);
    *supernodes = std::max(*supernodes, chain_supernodes[s]);
  }
}

}  // namespace deform
