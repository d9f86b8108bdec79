// PoseFromBoneTransforms: absolute bone transforms (what animation files hold) into the API's
// pose. Forward kinematics of the converted pose reproduces the transforms to round-off.
#include "bone_transforms.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/geometry/pose.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

v1::MeshSummary SummaryOf(const Skeleton& skeleton) {
  v1::MeshSummary summary;
  for (const Joint& joint : skeleton.joints()) {
    v1::JointInfo* info = summary.add_joints();
    info->set_name(joint.name);
    for (int c = 0; c < 3; ++c) info->add_rest_position(joint.rest_position[c]);
  }
  for (const Bone& bone : skeleton.bones()) {
    v1::BoneInfo* info = summary.add_bones();
    info->set_head_joint(bone.head_joint);
    info->set_tail_joint(bone.tail_joint);
    info->set_parent_bone(bone.parent_bone);
  }
  return summary;
}

Pose RandomPose(const Skeleton& skeleton, std::mt19937* random) {
  std::normal_distribution<double> gaussian;
  Pose pose = Pose::Rest(skeleton);
  for (auto& rotation : pose.joint_rotations) {
    rotation = Eigen::Quaterniond(1 + 0.5 * gaussian(*random), 0.4 * gaussian(*random),
                                  0.4 * gaussian(*random), 0.4 * gaussian(*random))
                   .normalized();
  }
  pose.root.rotation =
      Eigen::Quaterniond(gaussian(*random), gaussian(*random), gaussian(*random), gaussian(*random))
          .normalized();
  pose.root.translation = Eigen::Vector3d(10 * gaussian(*random), gaussian(*random), 3);
  return pose;
}

// The API's pose back into the core's (rotations by joint name, the root).
Pose CorePose(const Skeleton& skeleton, const v1::PoseUpdate& update) {
  Pose pose = Pose::Rest(skeleton);
  for (const v1::JointRotation& r : update.rotations()) {
    const int joint = *skeleton.FindJoint(r.joint());
    pose.joint_rotations[joint] = Eigen::Quaterniond(r.w(), r.x(), r.y(), r.z()).normalized();
  }
  const auto& root = update.root();
  pose.root.rotation = Eigen::Quaterniond(root.rotation().w(), root.rotation().x(),
                                          root.rotation().y(), root.rotation().z())
                           .normalized();
  pose.root.translation =
      Eigen::Vector3d(root.translation().x(), root.translation().y(), root.translation().z());
  return pose;
}

void ExpectRoundTrip(const Skeleton& skeleton) {
  const v1::MeshSummary summary = SummaryOf(skeleton);
  std::mt19937 random(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = RandomPose(skeleton, &random);
    std::vector<RigidTransform> expected;
    ForwardKinematics(skeleton, pose, &expected);
    std::vector<client::BoneTransform> given;
    for (const RigidTransform& t : expected) {
      given.push_back({{t.rotation.w(), t.rotation.x(), t.rotation.y(), t.rotation.z()},
                       {t.translation.x(), t.translation.y(), t.translation.z()}});
    }
    client::PoseConversion conversion;
    std::string error;
    ASSERT_TRUE(client::PoseFromBoneTransforms(summary, given, &conversion, &error)) << error;
    EXPECT_LT(conversion.sibling_disagreement_degrees, 1e-9);
    EXPECT_LT(conversion.joint_gap, 1e-9);
    std::vector<RigidTransform> again;
    ForwardKinematics(skeleton, CorePose(skeleton, conversion.pose), &again);
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_LT(expected[k].rotation.angularDistance(again[k].rotation), 1e-12) << "bone " << k;
      EXPECT_LT((expected[k].translation - again[k].translation).norm(), 1e-9) << "bone " << k;
    }
  }
}

TEST(PoseFromBoneTransforms, ReproducesThePhantomsBoneTransforms) {
  auto phantom = MakeKneePhantom(300);
  ASSERT_TRUE(phantom.ok());
  ExpectRoundTrip(phantom->skeleton);
}

TEST(PoseFromBoneTransforms, ReproducesABranchingBodyRig) {
  DEFORM_REQUIRE_SHARED_FILE(path, "body/body.tgf");
  auto skeleton = ReadSkeletonFile(path);
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  ExpectRoundTrip(*skeleton);
}

TEST(PoseFromBoneTransforms, ReportsTransformsThatAreNoPoseOfTheSkeleton) {
  auto phantom = MakeKneePhantom(300);
  ASSERT_TRUE(phantom.ok());
  const v1::MeshSummary summary = SummaryOf(phantom->skeleton);
  std::vector<client::BoneTransform> given(phantom->skeleton.num_bones());
  given.back().translation = {0.5, 0, 0};  // the shin leaves the knee
  client::PoseConversion conversion;
  std::string error;
  ASSERT_TRUE(client::PoseFromBoneTransforms(summary, given, &conversion, &error));
  EXPECT_NEAR(conversion.joint_gap, 0.5, 1e-12);
  given.pop_back();
  EXPECT_FALSE(client::PoseFromBoneTransforms(summary, given, &conversion, &error));
  EXPECT_NE(error.find("bone transforms"), std::string::npos) << error;
}

TEST(BoneTransformFromMatrix, ReadsAColumnMajorRigidMatrix) {
  // 90 degrees about +Z, then translation (1, 2, 3).
  const std::array<double, 16> m = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1};
  const client::BoneTransform t = client::BoneTransformFromMatrix(m);
  const Eigen::Quaterniond q(t.rotation[0], t.rotation[1], t.rotation[2], t.rotation[3]);
  EXPECT_LT((q * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(t.translation, (std::array<double, 3>{1, 2, 3}));
}

}  // namespace
}  // namespace deform
