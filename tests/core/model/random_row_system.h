// The random systems the row kernels' tests (rigid_rows_test.cc, general_rows_test.cc) work on.
#pragma once

#include <Eigen/SparseCore>
#include <random>
#include <vector>

#include "core/model/laplacian_system.h"

namespace deform::test_support {

// A system of n vertex columns and n + m rows: row i reads the row_length(i) vertices i,
// i + stride, i + 2 stride, ... (mod n) with values uniform in [-1, 1), drawn from `random` row by
// row, then the n rest deltas likewise. Only the fields the row kernels read are set.
template <typename RowLength>
LaplacianSystem RandomRowSystem(int n, int m, int stride, RowLength&& row_length,
                                std::mt19937* random) {
  std::uniform_real_distribution<double> value(-1, 1);
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n + m; ++i) {
    const int length = row_length(i);
    for (int k = 0; k < length; ++k) entries.emplace_back(i, (i + stride * k) % n, value(*random));
  }
  LaplacianSystem system;
  system.num_vertices = n;
  system.num_nodes = m;
  system.laplacian_transpose.resize(n + m, n);
  system.laplacian_transpose.setFromTriplets(entries.begin(), entries.end());
  system.laplacian_transpose.makeCompressed();
  system.rest_deltas = Positions::NullaryExpr(n, 3, [&] { return value(*random); });
  return system;
}

}  // namespace deform::test_support
