// The linear rotation blend over any number of bones (linear_blend_plan.h): the simplex grid's
// cells, the blend's continuity and its approach to the quaternion blend, and the response built
// from it on a rig whose vertices blend three bones.
#include "core/model/linear_blend_plan.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/skeleton_io.h"
#include "core/io/skin_weights_io.h"
#include "core/model/deformation_model.h"
#include "tests/core/model/model_test_util.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

std::vector<double> RandomWeights(int m, std::mt19937* random) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> weights(m);
  double sum = 0;
  for (double& w : weights) sum += (w = uniform(*random));
  for (double& w : weights) w /= sum;
  return weights;
}

TEST(SimplexGridCell, CornersAreGridPointsWhoseBlendIsTheWeights) {
  std::mt19937 random(7);
  std::vector<int> shares;
  std::vector<double> coefficients;
  for (int m = 1; m <= 6; ++m) {
    for (int segments : {1, 2, 3, 4, 8}) {
      for (int trial = 0; trial < 200; ++trial) {
        const std::vector<double> weights = RandomWeights(m, &random);
        SimplexGridCell(weights, segments, &shares, &coefficients);
        std::vector<double> reproduced(m, 0.0);
        double coefficient_sum = 0;
        for (int c = 0; c < m; ++c) {
          EXPECT_GE(coefficients[c], -1e-15);
          coefficient_sum += coefficients[c];
          int share_sum = 0;
          for (int j = 0; j < m; ++j) {
            const int share = shares[c * m + j];
            EXPECT_GE(share, 0);
            share_sum += share;
            reproduced[j] += coefficients[c] * share / segments;
          }
          EXPECT_EQ(share_sum, segments);
        }
        EXPECT_NEAR(coefficient_sum, 1.0, 1e-12);
        for (int j = 0; j < m; ++j) EXPECT_NEAR(reproduced[j], weights[j], 1e-12);
      }
    }
  }
}

TEST(SimplexGridCell, TwoWeightsTakeTheTwoSamplesAroundTheSecond) {
  std::vector<int> shares;
  std::vector<double> coefficients;
  SimplexGridCell({0.7, 0.3}, 4, &shares, &coefficients);  // 0.3 lies between 1/4 and 2/4
  std::vector<std::pair<int, double>> second_share_and_coefficient;
  for (int c = 0; c < 2; ++c)
    second_share_and_coefficient.emplace_back(shares[2 * c + 1], coefficients[c]);
  std::sort(second_share_and_coefficient.begin(), second_share_and_coefficient.end());
  EXPECT_EQ(second_share_and_coefficient[0].first, 1);
  EXPECT_NEAR(second_share_and_coefficient[0].second, 0.8, 1e-12);
  EXPECT_EQ(second_share_and_coefficient[1].first, 2);
  EXPECT_NEAR(second_share_and_coefficient[1].second, 0.2, 1e-12);
}

// Bone weights of hand-made vertices, each a list of (bone, weight).
BoneWeights MakeBoneWeights(int num_bones,
                            const std::vector<std::vector<std::pair<int, double>>>& vertices) {
  BoneWeights bw;
  bw.num_bones = num_bones;
  bw.offsets = {0};
  for (const auto& vertex : vertices) {
    for (const auto& [bone, weight] : vertex) {
      bw.bones.push_back(bone);
      bw.weights.push_back(weight);
    }
    bw.offsets.push_back(static_cast<int>(bw.bones.size()));
  }
  return bw;
}

// Three bones turned about different axes by up to 120 degrees.
std::vector<RigidTransform> ThreeTurnedBones() {
  std::vector<RigidTransform> bones(3);
  bones[1].rotation = Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitX());
  bones[2].rotation = Eigen::AngleAxisd(2.1, Eigen::Vector3d(0.3, 1, 0.2).normalized());
  return bones;
}

Eigen::Matrix3d BlendOf(const LinearBlendPlan& plan, int vertex,
                        const std::vector<RigidTransform>& bones) {
  std::vector<Eigen::Matrix3d> slots(plan.num_slots());
  plan.SlotRotations(bones, slots.data());
  return plan.Blend(vertex, slots.data());
}

Eigen::Matrix3d QuaternionBlendOf(const std::vector<std::pair<int, double>>& vertex,
                                  const std::vector<RigidTransform>& bones) {
  Eigen::Quaterniond q;
  q.coeffs().setZero();
  for (const auto& [bone, weight] : vertex) q.coeffs() += weight * bones[bone].rotation.coeffs();
  return q.normalized().toRotationMatrix();
}

TEST(LinearBlendPlan, ThreeBoneVerticesApproachTheQuaternionBlend) {
  const std::vector<std::pair<int, double>> vertex = {{0, 0.3}, {1, 0.3}, {2, 0.4}};
  const auto bones = ThreeTurnedBones();
  const Eigen::Matrix3d quaternion = QuaternionBlendOf(vertex, bones);
  double previous_error = 1e9;
  for (int segments : {1, 2, 4, 8, 16}) {
    const auto plan = LinearBlendPlan::Build(MakeBoneWeights(3, {vertex}), 3, segments);
    const Eigen::Matrix3d blend = BlendOf(plan, 0, bones);
    const double error = (blend - quaternion).norm();
    EXPECT_LT(error, previous_error) << segments << " segments";
    previous_error = error;
  }
  // The plain blend (1 segment) shrinks the skin by a third here; 16 segments by well under 1%.
  const auto plain = LinearBlendPlan::Build(MakeBoneWeights(3, {vertex}), 3, 1);
  EXPECT_LT(Eigen::JacobiSVD<Eigen::Matrix3d>(BlendOf(plain, 0, bones)).singularValues()(2), 0.7);
  const auto fine = LinearBlendPlan::Build(MakeBoneWeights(3, {vertex}), 3, 16);
  EXPECT_GT(Eigen::JacobiSVD<Eigen::Matrix3d>(BlendOf(fine, 0, bones)).singularValues()(2), 0.99);
  EXPECT_LT(previous_error, 0.02);
}

// A third bone entering with a vanishing weight changes the blend continuously: the cells of the
// grid over three bones meet the pair's segments on the grid's edges.
TEST(LinearBlendPlan, IsContinuousAsABoneEnters) {
  const auto bones = ThreeTurnedBones();
  for (double epsilon : {1e-2, 1e-4, 1e-6}) {
    const auto plan = LinearBlendPlan::Build(
        MakeBoneWeights(3, {{{0, 0.62}, {1, 0.38}},
                            {{0, 0.62 - epsilon / 2}, {1, 0.38 - epsilon / 2}, {2, epsilon}}}),
        3, 4);
    EXPECT_LT((BlendOf(plan, 0, bones) - BlendOf(plan, 1, bones)).norm(), 10 * epsilon);
  }
}

TEST(LinearBlendPlan, AgreeingBonesGiveTheirRotationExactly) {
  std::mt19937 random(3);
  std::vector<std::vector<std::pair<int, double>>> vertices;
  for (int v = 0; v < 50; ++v) {
    const std::vector<double> weights = RandomWeights(5, &random);
    vertices.push_back({});
    for (int k = 0; k < 5; ++k) vertices.back().emplace_back(k, weights[k]);
  }
  const auto plan = LinearBlendPlan::Build(MakeBoneWeights(5, vertices), 5, 4);
  std::vector<RigidTransform> bones(5);
  for (auto& bone : bones)
    bone.rotation = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized());
  const Eigen::Matrix3d expected = bones[0].rotation.toRotationMatrix();
  for (int v = 0; v < 50; ++v) EXPECT_LT((BlendOf(plan, v, bones) - expected).norm(), 1e-13);
  // Grid points have at most `segments` non-zero shares: 5 bones in 4 segments need no knot of 5.
  for (int j = 0; j < plan.num_knots(); ++j) EXPECT_LE(plan.KnotShares(j).size(), 4u);
}

// The arm's authored weights blend up to three bones near the elbow: the response built from the
// plan equals the solve with the same blend, and stays near the quaternion blend's frame.
TEST(LinearBlendPlan, TheResponseEqualsTheSolveOnThreeBoneVertices) {
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "arm/arm_8311.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "arm/arm.tgf");
  DEFORM_REQUIRE_SHARED_FILE(weights_path, "arm/arm_8311_weights.dmat");
  auto mesh = ReadMeshFile(mesh_path);
  auto skeleton = ReadSkeletonFile(skeleton_path);
  ASSERT_TRUE(mesh.ok() && skeleton.ok());
  auto weights = LoadSkinWeightsFile(weights_path, mesh->num_vertices(), skeleton->num_bones());
  ASSERT_TRUE(weights.ok()) << weights.status().ToString();
  ModelOptions options = ModelOptions::Paper();
  options.rotation_blend = RotationBlend::kLinear;
  auto model = DeformationModel::Build(*mesh, *skeleton, options, &*weights);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const auto& factorization = *(*model)->default_factorization();
  ASSERT_NE(factorization.linear_response(), nullptr);
  int three_bone_knots = 0;
  const LinearBlendPlan& plan = *(*model)->linear_blend_plan();
  for (int j = 0; j < plan.num_knots(); ++j) three_bone_knots += plan.KnotShares(j).size() >= 3;
  EXPECT_GT(three_bone_knots, 0);

  const Pose pose = test_support::PoseFromSpec((*model)->skeleton(), "2:z:-90,1:x:20");
  DeformScratch fast = (*model)->MakeScratch();
  (*model)->Deform(factorization, pose, &fast);
  DeformScratch solved = (*model)->MakeScratch();
  (*model)->AssembleRightHandSide(factorization, pose, &solved);
  (*model)->SolveInPlace(factorization, &solved);
  const double diagonal = (*model)->bounding_box_diagonal();
  EXPECT_LT(test_support::MaxDistance(fast.positions(), solved.positions()), 1e-10 * diagonal);
  EXPECT_GT(test_support::MaxDistance(fast.positions(), (*model)->mesh().vertices),
            0.05 * diagonal);
}

}  // namespace
}  // namespace deform
