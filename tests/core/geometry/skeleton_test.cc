#include "core/geometry/skeleton.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace deform {
namespace {

std::vector<Joint> ThreeJoints() {
  std::vector<Joint> joints(3);
  joints[0] = {"hip", {0, 2, 0}, {}};
  joints[1] = {"knee", {0, 1, 0}, {{"flexion", {2, 0, 0}, -5, 150}}};
  joints[2] = {"ankle", {0, 0, 0}, {}};
  return joints;
}

std::string CreateError(std::vector<Joint> joints, std::vector<std::pair<int, int>> bones) {
  auto skeleton = Skeleton::Create(std::move(joints), std::move(bones));
  EXPECT_FALSE(skeleton.ok());
  EXPECT_EQ(skeleton.status().code(), StatusCode::kInvalidArgument);
  return skeleton.status().message();
}

TEST(Skeleton, DerivesParentsAndNormalisesAxes) {
  auto skeleton = Skeleton::Create(ThreeJoints(), {{1, 2}, {0, 1}});
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  EXPECT_EQ(skeleton->bone(0).parent_bone, 1);
  EXPECT_EQ(skeleton->bone(1).parent_bone, -1);
  EXPECT_EQ(skeleton->BonesParentsFirst(), (std::vector<int>{1, 0}));
  EXPECT_EQ(skeleton->IncomingBone(2), 0);
  EXPECT_EQ(skeleton->InnerJoints(), (std::vector<int>{1}));
  EXPECT_EQ(skeleton->joint(1).dofs[0].axis, Eigen::Vector3d::UnitX());
  EXPECT_EQ(*skeleton->FindJoint("ankle"), 2);
  EXPECT_EQ(*skeleton->FindJoint("1"), 1);
  EXPECT_EQ(skeleton->FindJoint("3").status().code(), StatusCode::kNotFound);
}

TEST(Skeleton, NamesTheFirstProblem) {
  EXPECT_EQ(CreateError({}, {{0, 1}}), "skeleton has no joints");
  EXPECT_EQ(CreateError(ThreeJoints(), {}), "skeleton has no bones");
  auto joints = ThreeJoints();
  joints[2].name = "hip";
  EXPECT_EQ(CreateError(joints, {{0, 1}}), "joint name 'hip' is used twice");
  joints = ThreeJoints();
  joints[1].dofs.push_back({"flexion", {1, 0, 0}, 0, 1});
  EXPECT_EQ(CreateError(joints, {{0, 1}}), "joint 'knee' names degree of freedom 'flexion' twice");
  joints = ThreeJoints();
  joints[1].dofs[0].max_degrees = -10;
  EXPECT_EQ(CreateError(joints, {{0, 1}}), "degree of freedom 'knee:flexion' has an invalid range");
  joints = ThreeJoints();
  joints[1].dofs[0].axis.setZero();
  EXPECT_EQ(CreateError(joints, {{0, 1}}),
            "degree of freedom 'knee:flexion' has a zero or non-finite axis");
  EXPECT_EQ(CreateError(ThreeJoints(), {{0, 7}}),
            "bone 0 references joint 7 but the skeleton has 3 joints");
  EXPECT_EQ(CreateError(ThreeJoints(), {{0, 0}}), "bone 0 has zero length");
  EXPECT_EQ(CreateError(ThreeJoints(), {{0, 2}, {1, 2}}),
            "joint 'ankle' is the tail of two bones; a skeleton must be a tree");
  EXPECT_EQ(CreateError(ThreeJoints(), {{0, 1}, {1, 0}}), "skeleton bones form a cycle");
}

}  // namespace
}  // namespace deform
