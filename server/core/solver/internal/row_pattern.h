// The row patterns of a Cholesky factor, for the symbolic analysis' column counts. Internal to the
// solver.
#pragma once

#include <vector>

namespace deform::solver_internal {

// Non-zero pattern of row k of L, from column k of C's upper triangle (column pointers `cp`, row
// indices `ci`) and the elimination tree `parent` (CSparse's ereach). Writes the pattern to
// stack[top..n-1] in topological order and returns top. `stack` and `mark` hold n entries; `mark`
// starts as all -1 (or anything below 0) and is reused from one k to the next, k ascending.
inline int RowPattern(int k, const std::vector<int>& cp, const std::vector<int>& ci,
                      const std::vector<int>& parent, std::vector<int>* stack,
                      std::vector<int>* mark) {
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

}  // namespace deform::solver_internal
