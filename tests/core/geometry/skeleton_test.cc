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

TEST(Skeleton, DerivesParentsAndNormalizesAxes) {
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

// A pelvis bone (0 -> 1) and a thigh (2 -> 3) hanging off it at a hip away from the pelvis
// bone's tail, as game-engine rigs have them.
std::vector<Joint> PelvisAndThigh() {
  std::vector<Joint> joints(4);
  joints[0] = {"pelvis", {0, 0, 0}, {}};
  joints[1] = {"spine", {0, 1, 0}, {}};
  joints[2] = {"hip", {1, 0, 0}, {}};
  joints[3] = {"knee", {1, -2, 0}, {}};
  return joints;
}

TEST(Skeleton, ExplicitParentsCarryBonesThatDoNotMeetTheirParent) {
  auto derived = Skeleton::Create(PelvisAndThigh(), {{0, 1}, {2, 3}});
  ASSERT_TRUE(derived.ok());
  EXPECT_EQ(derived->bone(1).parent_bone, -1) << "without parents: two trees";
  EXPECT_TRUE(derived->InnerJoints().empty());

  auto skeleton = Skeleton::Create(PelvisAndThigh(), {{0, 1}, {2, 3}}, {-1, 0});
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  EXPECT_EQ(skeleton->bone(1).parent_bone, 0);
  EXPECT_TRUE(skeleton->HasExplicitParent(1));
  EXPECT_FALSE(skeleton->HasExplicitParent(0));
  EXPECT_EQ(skeleton->IncomingBone(2), 0) << "the pelvis bone carries the hip";
  EXPECT_EQ(skeleton->InnerJoints(), (std::vector<int>{2}));
  EXPECT_EQ(skeleton->BonesParentsFirst(), (std::vector<int>{0, 1}));
}

TEST(Skeleton, ExplicitParentsAreChecked) {
  const auto error = [](std::vector<std::pair<int, int>> bones, std::vector<int> parents) {
    auto skeleton = Skeleton::Create(PelvisAndThigh(), std::move(bones), parents);
    EXPECT_FALSE(skeleton.ok());
    return skeleton.status().message();
  };
  EXPECT_EQ(error({{0, 1}, {2, 3}}, {-1}), "the skeleton gives 1 bone parents for 2 bones");
  EXPECT_EQ(error({{0, 1}, {2, 3}}, {-1, 2}),
            "bone 1 names parent bone 2, which is not another bone of the 2");
  EXPECT_EQ(error({{0, 1}, {2, 3}}, {-1, 1}),
            "bone 1 names parent bone 1, which is not another bone of the 2");
  // The hip ends bone 2, so bone 1 (starting there) cannot name bone 0 as its parent.
  EXPECT_EQ(error({{0, 1}, {2, 3}, {1, 2}}, {-1, 0, -1}),
            "bone 1 names parent bone 0 but its head joint 'hip' is carried by bone 2");
  // Two bones at one head joint with different parents.
  auto joints = PelvisAndThigh();
  joints.push_back({"toe", {2, -2, 0}, {}});
  auto two = Skeleton::Create(joints, {{0, 1}, {2, 3}, {2, 4}}, {-1, 0, 1});
  ASSERT_FALSE(two.ok());
  EXPECT_EQ(two.status().message(),
            "bone 2 names parent bone 1 but its head joint 'hip' is carried by bone 0");
  // A cycle through explicit parents.
  EXPECT_EQ(error({{0, 1}, {2, 3}}, {1, 0}), "skeleton bones form a cycle");
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
