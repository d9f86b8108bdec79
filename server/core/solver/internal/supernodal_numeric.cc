#include "supernodal_numeric.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "update_product.h"

namespace deform::solver_internal {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using BlockMap = Eigen::Map<RowMatrix, 0, Eigen::OuterStride<>>;

std::vector<int> SupernodeOfColumn(int size, const std::vector<int>& supernode_columns) {
  std::vector<int> supernode_of(static_cast<std::size_t>(size));
  for (std::size_t s = 0; s + 1 < supernode_columns.size(); ++s) {
    for (int c = supernode_columns[s]; c < supernode_columns[s + 1]; ++c) {
      supernode_of[c] = static_cast<int>(s);
    }
  }
  return supernode_of;
}

// The first column of the w by w row-major lower triangle `a` whose pivot is not positive and
// finite, with that pivot (the unblocked Cholesky, on a copy: only to name the failure).
int FirstBadPivot(double* a, int w, double* pivot) {
  for (int i = 0; i < w; ++i) {
    double* row_i = a + static_cast<std::int64_t>(i) * w;
    for (int j = 0; j < i; ++j) {
      const double* row_j = a + static_cast<std::int64_t>(j) * w;
      double sum = row_i[j];
      for (int k = 0; k < j; ++k) sum -= row_i[k] * row_j[k];
      row_i[j] = sum / row_j[j];
    }
    double d = row_i[i];
    for (int k = 0; k < i; ++k) d -= row_i[k] * row_i[k];
    if (!(d > 0) || !std::isfinite(d)) {
      *pivot = d;
      return i;
    }
    row_i[i] = std::sqrt(d);
  }
  *pivot = 0;
  return -1;
}

}  // namespace

void SupernodeRows(int size, const std::vector<int>& supernode_columns,
                   const std::vector<std::int64_t>& row_pointers,
                   const std::vector<std::int64_t>& lower_pointers,
                   const std::vector<int>& lower_rows, int* rows) {
  const int count = static_cast<int>(supernode_columns.size()) - 1;
  const std::vector<int> supernode_of = SupernodeOfColumn(size, supernode_columns);
  std::vector<int> first_child(count, -1), next_sibling(count, -1);
  std::vector<int> mark(static_cast<std::size_t>(size), -1);
  for (int s = 0; s < count; ++s) {
    const int first = supernode_columns[s], last = supernode_columns[s + 1] - 1;
    int* out = rows + row_pointers[s];
    int w = 0;
    for (int c = first; c <= last; ++c) out[w++] = c;
    int* below = out + w;
    int n_below = 0;
    const auto add = [&](int row) {
      if (row > last && mark[row] != s) {
        mark[row] = s;
        below[n_below++] = row;
      }
    };
    for (int c = first; c <= last; ++c) {
      for (std::int64_t p = lower_pointers[c]; p < lower_pointers[c + 1]; ++p) add(lower_rows[p]);
    }
    for (int child = first_child[s]; child >= 0; child = next_sibling[child]) {
      const int child_width = supernode_columns[child + 1] - supernode_columns[child];
      for (std::int64_t p = row_pointers[child] + child_width; p < row_pointers[child + 1]; ++p) {
        add(rows[p]);
      }
    }
    assert(w + n_below == row_pointers[s + 1] - row_pointers[s]);
    std::sort(below, below + n_below);
    if (n_below > 0) {
      const int parent = supernode_of[below[0]];
      next_sibling[s] = first_child[parent];
      first_child[parent] = s;
    }
  }
}

SupernodalUpdates PlanSupernodalUpdates(int size, const std::vector<int>& supernode_columns,
                                        const std::vector<std::int64_t>& row_pointers,
                                        const std::vector<int>& row_indices) {
  const int count = static_cast<int>(supernode_columns.size()) - 1;
  const std::vector<int> supernode_of = SupernodeOfColumn(size, supernode_columns);
  SupernodalUpdates u;
  u.offsets.assign(count + 1, 0);
  // Calls visit(target, update) for every descendant's run of rows in a target, d ascending.
  const auto for_each_update = [&](auto visit) {
    for (int d = 0; d < count; ++d) {
      const int width = supernode_columns[d + 1] - supernode_columns[d];
      const int* rows = row_indices.data() + row_pointers[d];
      const int n = static_cast<int>(row_pointers[d + 1] - row_pointers[d]);
      for (int r = width; r < n;) {
        const int target = supernode_of[rows[r]];
        int end = r;
        while (end < n && rows[end] < supernode_columns[target + 1]) ++end;
        visit(target, SupernodalUpdates::Update{d, r, end});
        r = end;
      }
    }
  };
  for_each_update([&](int target, const SupernodalUpdates::Update& update) {
    ++u.offsets[target + 1];
    const std::int64_t rows = row_pointers[update.descendant + 1] - row_pointers[update.descendant];
    u.max_product = std::max(u.max_product, (rows - update.begin) * (update.end - update.begin));
  });
  for (int s = 0; s < count; ++s) u.offsets[s + 1] += u.offsets[s];
  u.updates.resize(u.offsets[count]);
  std::vector<std::int64_t> next(u.offsets.begin(), u.offsets.end() - 1);
  for_each_update([&](int target, const SupernodalUpdates::Update& update) {
    u.updates[next[target]++] = update;
  });
  return u;
}

SupernodalResult FactorizeSupernodes(const SupernodalNumericInput& in, const int* supernodes,
                                     int count, SupernodalWorkspace* work,
                                     const CancelToken* cancel) {
  if (work->position.size() < static_cast<std::size_t>(in.size)) work->position.resize(in.size);
  const std::int64_t product_size = std::max<std::int64_t>(in.updates->max_product, 1);
  if (work->product.size() < static_cast<std::size_t>(product_size)) {
    work->product.resize(product_size);
  }
  std::int64_t* position = work->position.data();
  for (int i = 0; i < count; ++i) {
    SupernodalResult result{CheckCancelled(cancel, "the numeric factorization"), -1};
    if (!result.status.ok()) return result;
    const int s = supernodes[i];
    const int first = in.supernode_columns[s];
    const int w = in.supernode_columns[s + 1] - first;
    const std::int64_t rows = in.row_pointers[s + 1] - in.row_pointers[s];
    const int* row_of = in.row_indices + in.row_pointers[s];
    double* block = in.values + in.value_pointers[s];
    for (std::int64_t k = 0; k < rows; ++k) position[row_of[k]] = k;
    // C's lower entries in the supernode's columns (every one falls on the block's rows).
    for (int c = 0; c < w; ++c) {
      for (std::int64_t p = in.lower_pointers[first + c]; p < in.lower_pointers[first + c + 1];
           ++p) {
        block[position[in.lower_rows[p]] * w + c] = in.lower_values[p];
      }
    }
    // Every descendant's update, its lower part only.
    for (std::int64_t q = in.updates->offsets[s]; q < in.updates->offsets[s + 1]; ++q) {
      const SupernodalUpdates::Update& u = in.updates->updates[q];
      const int d = u.descendant;
      const int wd = in.supernode_columns[d + 1] - in.supernode_columns[d];
      const int* d_rows = in.row_indices + in.row_pointers[d] + u.begin;
      const std::int64_t m = in.row_pointers[d + 1] - in.row_pointers[d] - u.begin;
      const int k = u.end - u.begin;
      const double* d_block = in.values + in.value_pointers[d] + u.begin * wd;
      UpdateProduct(d_block, m, d_block, k, wd, work->product.data());
      for (std::int64_t r = 0; r < m; ++r) {
        double* target = block + position[d_rows[r]] * w - first;
        const double* from = work->product.data() + r * k;
        const int columns = r < k ? static_cast<int>(r) + 1 : k;
        for (int c = 0; c < columns; ++c) target[d_rows[c]] -= from[c];
      }
    }
    // The diagonal block's dense Cholesky (a copy of its lower triangle kept to name a failure),
    // then the rows below: X L^T = B.
    const std::int64_t diagonal = static_cast<std::int64_t>(w) * w;
    if (work->product.size() < static_cast<std::size_t>(diagonal)) work->product.resize(diagonal);
    std::copy(block, block + diagonal, work->product.data());
    Eigen::Map<RowMatrix> l(block, w, w);
    Eigen::LLT<Eigen::Ref<RowMatrix>> llt(l);
    if (llt.info() != Eigen::Success || !l.diagonal().allFinite()) {
      double pivot = 0;
      const int bad = FirstBadPivot(work->product.data(), w, &pivot);
      const int column = first + std::max(bad, 0);
      return {Status::Internal("matrix is not positive definite (pivot " + std::to_string(column) +
                               " is " + std::to_string(pivot) + ")"),
              column};
    }
    for (int r = 0; r < w; ++r) {
      std::fill(block + static_cast<std::int64_t>(r) * w + r + 1, block + (r + 1) * w, 0.0);
    }
    if (rows > w) {
      BlockMap below(block + diagonal, rows - w, w, Eigen::OuterStride<>(w));
      l.transpose().triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(below);
    }
  }
  return {Status::Ok(), -1};
}

}  // namespace deform::solver_internal
