#include "core/model/bone_weights.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/model/deformation_model.h"
#include "tests/core/model/shared_leg_model.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

void ExpectPartitionOfUnity(const BoneWeights& weights) {
  EXPECT_GE(weights.dense.minCoeff(), 0.0);
  EXPECT_LE(weights.dense.maxCoeff(), 1.0);
  const Eigen::VectorXd sums = weights.dense.rowwise().sum();
  EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-9);
  for (int i = 0; i < weights.num_vertices(); ++i) {
    double sum = 0;
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) sum += weights.weights[p];
    ASSERT_NEAR(sum, 1.0, 1e-12) << "vertex " << i;
  }
}

TEST(HarmonicBoneWeights, LieInTheUnitIntervalAndSumToOneOnThePhantom) {
  auto phantom = MakeKneePhantom();
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const BoneWeights& w = (*model)->bone_weights();
  ExpectPartitionOfUnity(w);
  // The blend is smooth across the knee: some vertices carry both bones.
  int blended = 0;
  for (int i = 0; i < w.num_vertices(); ++i) blended += (w.offsets[i + 1] - w.offsets[i]) > 1;
  EXPECT_GT(blended, 50);
}

TEST(HarmonicBoneWeights, LieInTheUnitIntervalAndSumToOneOnTheSharedLeg) {
  DEFORM_SHARED_LEG_MODEL(model);
  ExpectPartitionOfUnity(model->bone_weights());
}

TEST(HarmonicBoneWeights, KeepTheDirichletValues) {
  // A path 0-1-2-3-4 with its ends fixed to bones 0 and 1: the harmonic field is linear.
  VertexAdjacency path;
  path.offsets = {0, 1, 3, 5, 7, 8};
  path.neighbors = {1, 0, 2, 1, 3, 2, 4, 3};
  auto w = HarmonicBoneWeights(path, {0, -1, -1, -1, 1}, 2);
  ASSERT_TRUE(w.ok()) << w.status().ToString();
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(w->dense(i, 1), i / 4.0, 1e-12);
}

TEST(HarmonicBoneWeights, RefuseAComponentWithoutAFixedVertex) {
  VertexAdjacency two_edges;  // 0-1 and 2-3, only 0 fixed
  two_edges.offsets = {0, 1, 2, 3, 4};
  two_edges.neighbors = {1, 0, 3, 2};
  auto w = HarmonicBoneWeights(two_edges, {0, -1, -1, -1}, 1);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(w.status().message().find("vertex 2"), std::string::npos);
}

// A path 0-1-...-8 fixed to bone 0 at 0, bone 1 at 4 and bone 2 at 8, every free vertex allowed
// bones 0 and 1 except 5..7, which may use 1 and 2: bone 2's field stays off the left half, and
// bone 0's off the right half, however the unrestricted field would spread.
TEST(HarmonicBoneWeights, StayOnTheVerticesAllowedToUseThem) {
  VertexAdjacency path;
  path.offsets = {0};
  for (int i = 0; i < 9; ++i) {
    if (i > 0) path.neighbors.push_back(i - 1);
    if (i < 8) path.neighbors.push_back(i + 1);
    path.offsets.push_back(static_cast<int>(path.neighbors.size()));
  }
  const std::vector<int> fixed = {0, -1, -1, -1, 1, -1, -1, -1, 2};
  std::vector<std::vector<int>> allowed(9, std::vector<int>{0, 1});
  for (int i = 5; i <= 7; ++i) allowed[i] = {1, 2};
  auto w = HarmonicBoneWeights(path, fixed, 3, allowed);
  ASSERT_TRUE(w.ok()) << w.status().ToString();
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(w->dense.row(i).sum(), 1.0, 1e-12) << i;
  for (int i = 1; i <= 3; ++i) {
    EXPECT_EQ(w->dense(i, 2), 0.0);
    EXPECT_NEAR(w->dense(i, 1), i / 4.0, 1e-12);  // linear between the fixed ends, as before
  }
  for (int i = 5; i <= 7; ++i) {
    EXPECT_EQ(w->dense(i, 0), 0.0);
    EXPECT_NEAR(w->dense(i, 2), (i - 4) / 4.0, 1e-12);
  }
}

// Vertices allowed a bone that no fixed vertex holds (its field is 0 there) keep their other bones;
// one that no field reaches at all takes its first allowed bone.
TEST(HarmonicBoneWeights, AVertexNoFieldReachesTakesItsFirstAllowedBone) {
  VertexAdjacency path;  // 0-1-2, vertex 0 fixed to bone 0, 1 and 2 allowed only bone 1
  path.offsets = {0, 1, 3, 4};
  path.neighbors = {1, 0, 2, 1};
  auto w = HarmonicBoneWeights(path, {0, -1, -1}, 2, {{0}, {1}, {1}});
  ASSERT_TRUE(w.ok()) << w.status().ToString();
  EXPECT_EQ(w->dense(1, 1), 1.0);
  EXPECT_EQ(w->dense(2, 1), 1.0);
}

}  // namespace
}  // namespace deform
