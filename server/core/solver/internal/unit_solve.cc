#include "unit_solve.h"

#include <algorithm>
#include <vector>

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

}  // namespace

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
