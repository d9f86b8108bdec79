#include "core/model/rigid_rows.h"

#include <algorithm>
#include <cstddef>

namespace deform {
namespace {

// The bone vertex j follows wholly (a single bone-weight entry), or -1.
int WholeBone(const BoneWeights& weights, int j) {
  const int begin = weights.offsets[j];
  return weights.offsets[j + 1] - begin == 1 ? weights.bones[begin] : -1;
}

}  // namespace

RigidRows RigidRows::Find(const LaplacianSystem& system, const BoneWeights& weights) {
  const RowMajorSparseMatrix& lt = system.laplacian_transpose;
  const int rows = static_cast<int>(lt.outerSize());
  const int* columns = lt.innerIndexPtr();
  const int* row_begin = lt.outerIndexPtr();
  RigidRows rigid;
  rigid.bone_of_row.assign(rows, -1);
  rigid.delta_read.assign(system.num_vertices, 0);
  for (int i = 0; i < rows; ++i) {
    int bone = row_begin[i] < row_begin[i + 1] ? WholeBone(weights, columns[row_begin[i]]) : -1;
    for (int p = row_begin[i]; p < row_begin[i + 1] && bone >= 0; ++p) {
      if (WholeBone(weights, columns[p]) != bone) bone = -1;
    }
    rigid.bone_of_row[i] = bone;
    if (bone < 0) {
      for (int p = row_begin[i]; p < row_begin[i + 1]; ++p) rigid.delta_read[columns[p]] = 1;
    }
  }
  return rigid;
}

int RigidRows::rigid_row_count() const {
  return static_cast<int>(
      std::count_if(bone_of_row.begin(), bone_of_row.end(), [](int b) { return b >= 0; }));
}

std::size_t RigidRows::bytes() const {
  return bone_of_row.size() * sizeof(int) + delta_read.size();
}

std::vector<double> RigidRowSums(const LaplacianSystem& system, const RigidRows& rigid,
                                 const Eigen::VectorXd& row_weights_squared) {
  const RowMajorSparseMatrix& lt = system.laplacian_transpose;
  const int rows = static_cast<int>(lt.outerSize());
  const int* columns = lt.innerIndexPtr();
  const double* values = lt.valuePtr();
  const int* row_begin = lt.outerIndexPtr();
  std::vector<double> sums(3 * static_cast<std::size_t>(rows), 0.0);
  for (int i = 0; i < rows; ++i) {
    if (rigid.bone_of_row[i] < 0) continue;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int p = row_begin[i]; p < row_begin[i + 1]; ++p) {
      const int j = columns[p];
      sum += values[p] * row_weights_squared[j] * system.rest_deltas.row(j).transpose();
    }
    std::copy_n(sum.data(), 3, sums.data() + 3 * static_cast<std::size_t>(i));
  }
  return sums;
}

void MultiplyRotatedRows(const LaplacianSystem& system, const RigidRows& rigid, const double* sums,
                         const Eigen::Matrix3d* rotations, const double* __restrict r,
                         double* __restrict out, int first_row, int end_row) {
  const RowMajorSparseMatrix& lt = system.laplacian_transpose;
  const int* bone_of_row = rigid.bone_of_row.data();
  for (int row = first_row; row < end_row; ++row) {
    double* target = out + 3 * static_cast<std::ptrdiff_t>(row);
    if (const int bone = bone_of_row[row]; bone >= 0) {
      const Eigen::Map<const Eigen::Vector3d> c(sums + 3 * static_cast<std::ptrdiff_t>(row));
      Eigen::Map<Eigen::Vector3d>{target}.noalias() = rotations[bone] * c;
      continue;
    }
    SparseRowTimes3(lt, r, row, target);
  }
}

}  // namespace deform
