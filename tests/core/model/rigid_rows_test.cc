#include "core/model/rigid_rows.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tests/core/model/random_row_system.h"

namespace deform {
namespace {

// A system of n vertex columns and n + m rows whose row i reads vertices i, i + 1, ..., i + 4
// (mod n) with random values, and bone weights where vertices [0, n / 2) are wholly bone 0's,
// [n / 2, 3n / 4) wholly bone 1's, every seventh of those blended with bone 2, and the rest
// blended between bones 1 and 2.
struct Fixture {
  static constexpr int n = 96;
  static constexpr int m = 2;
  LaplacianSystem system;
  BoneWeights weights;
  Eigen::VectorXd w2 = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::Matrix3d> rotations;

  Fixture() {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> value(-1, 1);
    system = test_support::RandomRowSystem(
        n, m, 1, [](int) { return 5; }, &random);
    weights.num_bones = 3;
    weights.offsets.push_back(0);
    for (int j = 0; j < n; ++j) {
      if (j < n / 2) {
        weights.bones.push_back(0);
        weights.weights.push_back(1.0);
      } else if (j < 3 * n / 4 && j % 7 != 0) {
        weights.bones.push_back(1);
        weights.weights.push_back(1.0);
      } else {
        weights.bones.insert(weights.bones.end(), {1, 2});
        weights.weights.insert(weights.weights.end(), {0.6, 0.4});
      }
      weights.offsets.push_back(static_cast<int>(weights.bones.size()));
      w2[j] = 0.5 + value(random) * value(random);
    }
    for (int b = 0; b < 3; ++b) {
      rotations.push_back(
          Eigen::AngleAxisd(0.3 + b, Eigen::Vector3d(1, b, 2).normalized()).toRotationMatrix());
    }
  }

  int WholeBone(int j) const {
    return weights.offsets[j + 1] - weights.offsets[j] == 1 ? weights.bones[weights.offsets[j]]
                                                            : -1;
  }
};

TEST(RigidRows, ARowIsRigidExactlyWhenAllItsVerticesAreOneBonesWholly) {
  const Fixture f;
  const RigidRows rigid = RigidRows::Find(f.system, f.weights);
  const RowMajorSparseMatrix& lt = f.system.laplacian_transpose;
  int rigid_rows = 0;
  std::vector<bool> read(Fixture::n, false);
  for (int i = 0; i < Fixture::n + Fixture::m; ++i) {
    int expected = f.WholeBone(lt.innerIndexPtr()[lt.outerIndexPtr()[i]]);
    for (RowMajorSparseMatrix::InnerIterator it(lt, i); it; ++it) {
      if (f.WholeBone(it.col()) != expected) expected = -1;
    }
    EXPECT_EQ(rigid.bone_of_row[i], expected) << "row " << i;
    if (expected >= 0) ++rigid_rows;
    for (RowMajorSparseMatrix::InnerIterator it(lt, i); it; ++it) {
      if (expected < 0) read[it.col()] = true;
    }
  }
  EXPECT_GT(rigid_rows, Fixture::n / 3);           // bone 0's and bone 1's runs
  EXPECT_LT(rigid_rows, Fixture::n + Fixture::m);  // and the blended rows
  EXPECT_EQ(rigid.rigid_row_count(), rigid_rows);
  for (int j = 0; j < Fixture::n; ++j) EXPECT_EQ(rigid.delta_read[j] != 0, read[j]) << j;
}

// The product through the rigid rows' sums equals the full product L'^T r with
// r_j = w_j^2 T_j delta_j to round-off, and never reads a delta it did not mark as read.
TEST(RigidRows, TheProductEqualsTheFullProductAndReadsOnlyTheMarkedDeltas) {
  const Fixture f;
  const RigidRows rigid = RigidRows::Find(f.system, f.weights);
  const std::vector<double> sums = RigidRowSums(f.system, rigid, f.w2);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> r(Fixture::n, 3);
  const Eigen::Matrix3d blended =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int j = 0; j < Fixture::n; ++j) {
    const int bone = f.WholeBone(j);
    const Eigen::Vector3d delta = f.system.rest_deltas.row(j).transpose();
    r.row(j) = f.w2[j] * ((bone >= 0 ? f.rotations[bone] : blended) * delta).transpose();
  }
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> expected(Fixture::n + Fixture::m, 3);
  MultiplyLaplacianTranspose(f.system, r.data(), expected.data());

  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> unread_poisoned = r;
  for (int j = 0; j < Fixture::n; ++j) {
    if (!rigid.delta_read[j])
      unread_poisoned.row(j).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> product(Fixture::n + Fixture::m, 3);
  // In two ranges, as a parallel assembly splits the rows.
  const int half = (Fixture::n + Fixture::m) / 2;
  MultiplyRotatedRows(f.system, rigid, sums.data(), f.rotations.data(), unread_poisoned.data(),
                      product.data(), 0, half);
  MultiplyRotatedRows(f.system, rigid, sums.data(), f.rotations.data(), unread_poisoned.data(),
                      product.data(), half, Fixture::n + Fixture::m);
  ASSERT_TRUE(product.allFinite());
  EXPECT_LT((product - expected).norm(), 1e-14 * expected.norm());
  EXPECT_GT(expected.norm(), 1.0);
}

}  // namespace
}  // namespace deform
