#include "core/geometry/pose.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

Skeleton PhantomSkeleton() { return MakeKneePhantom(400)->skeleton; }

TEST(ParsePoseSpec, AcceptsNamesIndicesAndAxes) {
  const Skeleton skeleton = PhantomSkeleton();
  auto terms = ParsePoseSpec("knee:flexion:90, 0:x:-10,knee:varus_valgus:3", skeleton);
  ASSERT_TRUE(terms.ok()) << terms.status().ToString();
  ASSERT_EQ(terms->size(), 3u);
  EXPECT_EQ((*terms)[0].joint, 1);
  EXPECT_EQ((*terms)[0].dof, 0);
  EXPECT_EQ((*terms)[1].joint, 0);
  EXPECT_EQ((*terms)[1].dof, -1);
  EXPECT_DOUBLE_EQ((*terms)[1].degrees, -10);
  EXPECT_TRUE(ParsePoseSpec("rest", skeleton)->empty());
}

TEST(ParsePoseSpec, RefusesBadTerms) {
  const Skeleton skeleton = PhantomSkeleton();
  for (const char* bad : {"knee:flexion", "elbow:x:10", "knee:twist:10", "knee:x:abc", "knee:x:nan",
                          "knee:x:inf", "knee:x:10,,"}) {
    auto terms = ParsePoseSpec(bad, skeleton);
    EXPECT_FALSE(terms.ok()) << bad;
    EXPECT_EQ(terms.status().code(), StatusCode::kInvalidArgument) << bad;
  }
}

TEST(ResolvePoseAxis, NamesRestFrameAxesAndDegreesOfFreedom) {
  const Skeleton skeleton = PhantomSkeleton();
  PoseTerm term;
  term.joint = 1;  // the knee
  ASSERT_TRUE(ResolvePoseAxis(skeleton, "y", &term).ok());
  EXPECT_EQ(term.dof, -1);
  EXPECT_EQ(term.axis, Eigen::Vector3d::UnitY());
  ASSERT_TRUE(ResolvePoseAxis(skeleton, "varus_valgus", &term).ok());
  EXPECT_EQ(term.dof, 1);
  EXPECT_EQ(term.axis, skeleton.joint(1).dofs[1].axis);
  const Status unknown = ResolvePoseAxis(skeleton, "twist", &term);
  EXPECT_EQ(unknown.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(unknown.message(),
            "joint 'knee' has no axis 'twist' (known: x, y, z, flexion, varus_valgus, rotation)");
}

TEST(PoseFromTerms, ClampsToTheRangeOfMotion) {
  const Skeleton skeleton = PhantomSkeleton();
  Pose pose;
  auto clamped = PoseFromTerms(skeleton, *ParsePoseSpec("knee:flexion:200", skeleton), &pose);
  ASSERT_TRUE(clamped.ok());
  EXPECT_EQ(*clamped, 1);
  const double angle = Eigen::AngleAxisd(pose.joint_rotations[1]).angle() * 180 / M_PI;
  EXPECT_NEAR(angle, 150, 1e-9);  // the phantom knee flexes to 150 degrees at most
  clamped = PoseFromTerms(skeleton, *ParsePoseSpec("knee:x:200", skeleton), &pose);
  EXPECT_EQ(*clamped, 0);  // rest-frame axes have no range
}

TEST(ForwardKinematics, KneeFlexionSwingsTheAnkleBackward) {
  const Skeleton skeleton = PhantomSkeleton();
  Pose pose;
  ASSERT_TRUE(PoseFromTerms(skeleton, *ParsePoseSpec("knee:flexion:90", skeleton), &pose).ok());
  std::vector<RigidTransform> bones;
  ForwardKinematics(skeleton, pose, &bones);
  const Eigen::Vector3d knee = skeleton.joint(1).rest_position;
  const Eigen::Vector3d ankle = PosedJointPosition(skeleton, pose, bones, 2);
  const double shin = (skeleton.joint(2).rest_position - knee).norm();
  EXPECT_NEAR((ankle - (knee + Eigen::Vector3d(0, 0, -shin))).norm(), 0, 1e-12);
  // The thigh does not move.
  EXPECT_NEAR((bones[0].Apply(knee) - knee).norm(), 0, 1e-12);
}

TEST(ForwardKinematics, AnExplicitParentCarriesABoneThatDoesNotMeetIt) {
  // A pelvis bone (joint 0 -> 1) and a thigh hanging off it at a hip (joint 2 -> 3).
  std::vector<Joint> joints(4);
  joints[0] = {"pelvis", {0, 0, 0}, {}};
  joints[1] = {"spine", {0, 1, 0}, {}};
  joints[2] = {"hip", {1, 0, 0}, {}};
  joints[3] = {"knee", {1, -2, 0}, {}};
  auto skeleton = Skeleton::Create(joints, {{0, 1}, {2, 3}}, {-1, 0});
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  Pose pose = Pose::Rest(*skeleton);
  // Turning the pelvis joint by 90 degrees about z turns the pelvis bone and, with it, the hip
  // and the whole thigh.
  pose.joint_rotations[0] =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  std::vector<RigidTransform> bones;
  ForwardKinematics(*skeleton, pose, &bones);
  EXPECT_TRUE(
      PosedJointPosition(*skeleton, pose, bones, 2).isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
  EXPECT_TRUE(
      PosedJointPosition(*skeleton, pose, bones, 3).isApprox(Eigen::Vector3d(2, 1, 0), 1e-12));
  // Turning the hip moves the thigh only.
  pose = Pose::Rest(*skeleton);
  pose.joint_rotations[2] =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  ForwardKinematics(*skeleton, pose, &bones);
  EXPECT_TRUE(bones[0].rotation.isApprox(Eigen::Quaterniond::Identity()));
  EXPECT_TRUE(
      PosedJointPosition(*skeleton, pose, bones, 3).isApprox(Eigen::Vector3d(3, 0, 0), 1e-12));
}

TEST(ForwardKinematics, MatchesTheSharedReferenceTransforms) {
  DEFORM_REQUIRE_SHARED_FILE(tgf, "leg/leg.tgf");
  DEFORM_REQUIRE_SHARED_FILE(json_path, "leg/reference_poses.json");
  auto skeleton = ReadSkeletonFile(tgf);
  ASSERT_TRUE(skeleton.ok());
  std::ifstream in(json_path);
  const nlohmann::json reference = nlohmann::json::parse(in);
  int checked = 0;
  for (const auto& [name, pose_json] : reference["poses"].items()) {
    // Rebuild the pose from the bones' relative rotations: bone k's rotation is its head joint's.
    Pose pose = Pose::Rest(*skeleton);
    const auto& rotations = pose_json["relative_rotations_wxyz_per_bone"];
    for (int k = 0; k < skeleton->num_bones(); ++k) {
      const auto& q = rotations[k];
      pose.joint_rotations[skeleton->bone(k).head_joint] = Eigen::Quaterniond(
          q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>());
    }
    std::vector<RigidTransform> bones;
    ForwardKinematics(*skeleton, pose, &bones);
    for (int k = 0; k < skeleton->num_bones(); ++k) {
      const auto& expected = pose_json["absolute_bone_transforms_R_t"][k];
      for (int r = 0; r < 3; ++r) {
        EXPECT_NEAR(bones[k].translation[r], expected["t"][r].get<double>(), 1e-9) << name;
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(bones[k].rotation.toRotationMatrix()(r, c), expected["R"][r][c].get<double>(),
                      1e-9)
              << name;
        }
      }
    }
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}

}  // namespace
}  // namespace deform
