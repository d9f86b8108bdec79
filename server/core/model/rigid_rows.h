// The rows of the right-hand side that one bone's rotation determines.
//
// A frame's right-hand side is A^T b = L'^T r + (anchor and joint-node targets), with
// r_j = w_j^2 T_j delta_j (T_j vertex j's rotation blend). Where every vertex j of a row i of L'^T
// is wholly one bone's (a single bone-weight entry, so T_j = R_b for the same bone b), the row is
//   (L'^T r)_i = R_b sum_j L'^T_ij w_j^2 delta_j = R_b c_i,
// with c_i fixed for a stiffness (the weights w_j are the factorization's). Rows away from the
// joint regions are such rigid rows (most of a limb's rows, fewer where the regions are wide:
// docs/performance.md, "Right-hand side"), so a frame computes them as one 3x3 product each, and
// rotates only the deltas that the other rows (general rows) read. The result equals the full
// product to round-off (a sum in another order: 1e-14 of its norm, tested).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "core/model/bone_weights.h"
#include "core/model/laplacian_system.h"

namespace deform {

struct RigidRows {
  // Per row of L'^T (n + m): the bone that determines it, or -1 for a general row (its vertices
  // follow different bones or blends, or it has none).
  std::vector<int> bone_of_row;
  // Per vertex (n): whether some general row reads its rotated delta r_j (the others' are never
  // read, so a frame need not compute them).
  std::vector<unsigned char> delta_read;

  // The rigid rows of `system`'s L'^T under `weights` (the model's blending weights).
  static RigidRows Find(const LaplacianSystem& system, const BoneWeights& weights);
  // Rows whose bone_of_row is >= 0.
  int rigid_row_count() const;
  std::size_t bytes() const;
};

// c_i = sum_j L'^T_ij w_j^2 delta_j of every rigid row, zero in the general rows ((n + m) by 3,
// row-major), for the vertex rows' squared weights `row_weights_squared` (n) of a factorization.
std::vector<double> RigidRowSums(const LaplacianSystem& system, const RigidRows& rigid,
                                 const Eigen::VectorXd& row_weights_squared);

// Rows [first_row, end_row) of L'^T r into `out` ((n + m) by 3, row-major; written, not added):
// a rigid row as rotations[bone] * sums_i (`sums` from RigidRowSums), a general row as the sparse
// product with `r` (n by 3, row-major; only the rows delta_read marks are read). `rotations`
// indexed by bone. No allocation; rows are independent (a parallel assembly splits them).
void MultiplyRotatedRows(const LaplacianSystem& system, const RigidRows& rigid, const double* sums,
                         const Eigen::Matrix3d* rotations, const double* r, double* out,
                         int first_row, int end_row);

}  // namespace deform
