#include "service/deform/pose_input.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/io/phantom.h"
#include "core/model/deformation_model.h"
#include "service/messages/proto_conversion.h"
#include "tests/allocation_counter.h"

namespace deform::service {
namespace {

using ::testing::HasSubstr;

class PoseInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto phantom = MakeKneePhantom(400);
    ASSERT_TRUE(phantom.ok());
    skeleton_ = phantom->skeleton;
  }

  static v1::PoseUpdate Angles(
      std::initializer_list<std::tuple<const char*, const char*, double>> angles) {
    v1::PoseUpdate update;
    update.set_sequence(7);
    update.set_client_timestamp_ns(1234);
    for (const auto& [joint, axis, degrees] : angles) {
      v1::JointAngle* angle = update.add_angles();
      angle->set_joint(joint);
      angle->set_axis(axis);
      angle->set_degrees(degrees);
    }
    return update;
  }

  Skeleton skeleton_;
};

TEST_F(PoseInputTest, MatchesTheCorePoseSpec) {
  PoseInput input;
  ASSERT_TRUE(
      PoseInputFromProto(Angles({{"knee", "flexion", 200}, {"hip", "x", 15}}), skeleton_, &input)
          .ok());
  EXPECT_EQ(input.sequence, 7u);
  EXPECT_EQ(input.client_timestamp_ns, 1234);
  Pose pose;
  auto clamped = PoseFromInput(skeleton_, input, &pose);
  ASSERT_TRUE(clamped.ok());
  EXPECT_EQ(*clamped, 1);  // knee flexion clamped to its range

  auto terms = ParsePoseSpec("knee:flexion:200,hip:x:15", skeleton_);
  ASSERT_TRUE(terms.ok());
  Pose expected;
  ASSERT_TRUE(PoseFromTerms(skeleton_, *terms, &expected).ok());
  for (int j = 0; j < skeleton_.num_joints(); ++j) {
    EXPECT_TRUE(pose.joint_rotations[j].isApprox(expected.joint_rotations[j], 1e-12)) << j;
  }
}

TEST_F(PoseInputTest, RotationsComeBeforeAnglesOfTheSameJoint) {
  v1::PoseUpdate update = Angles({{"knee", "y", 30}});
  v1::JointRotation* rotation = update.add_rotations();
  rotation->set_joint("knee");
  // 90 degrees about x, not normalized (the server normalizes norms within 0.1 of 1).
  rotation->set_w(1.05 * std::cos(M_PI / 4));
  rotation->set_x(1.05 * std::sin(M_PI / 4));
  PoseInput input;
  ASSERT_TRUE(PoseInputFromProto(update, skeleton_, &input).ok());
  Pose pose;
  ASSERT_TRUE(PoseFromInput(skeleton_, input, &pose).ok());
  const int knee = *skeleton_.FindJoint("knee");
  const Eigen::Quaterniond expected =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX())) *
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(pose.joint_rotations[knee].isApprox(expected, 1e-12));
}

TEST_F(PoseInputTest, RejectsNonFiniteAnglesUnknownNamesAndZeroQuaternions) {
  PoseInput input;
  const Status nan = PoseInputFromProto(
      Angles({{"knee", "flexion", std::numeric_limits<double>::quiet_NaN()}}), skeleton_, &input);
  EXPECT_EQ(nan.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(nan.message(), HasSubstr("not a finite number"));
  const Status inf = PoseInputFromProto(
      Angles({{"knee", "x", std::numeric_limits<double>::infinity()}}), skeleton_, &input);
  EXPECT_EQ(inf.code(), StatusCode::kInvalidArgument);
  const Status joint = PoseInputFromProto(Angles({{"elbow", "x", 1}}), skeleton_, &input);
  EXPECT_THAT(joint.message(), HasSubstr("elbow"));
  const Status axis = PoseInputFromProto(Angles({{"knee", "twist", 1}}), skeleton_, &input);
  EXPECT_THAT(axis.message(), HasSubstr("twist"));
  v1::PoseUpdate zero;
  zero.add_rotations()->set_joint("knee");
  EXPECT_THAT(PoseInputFromProto(zero, skeleton_, &input).message(), HasSubstr("zero"));
}

// The per-frame path of a stream (convert, pose, solve, encode) allocates nothing once warm.
TEST_F(PoseInputTest, FramePathIsAllocationFreeOnceWarm) {
  auto phantom = MakeKneePhantom(400);
  ASSERT_TRUE(phantom.ok());
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  ASSERT_TRUE(model.ok());
  DeformScratch scratch = (*model)->MakeScratch();
  const v1::PoseUpdate update = Angles({{"knee", "flexion", 45}, {"hip", "flexion", 10}});
  PoseInput input;
  Pose pose = Pose::Rest((*model)->skeleton());
  std::string positions(static_cast<std::size_t>((*model)->mesh().num_vertices()) * 12, '\0');
  const auto frame = [&] {
    ASSERT_TRUE(PoseInputFromProto(update, (*model)->skeleton(), &input).ok());
    ASSERT_TRUE(PoseFromInput((*model)->skeleton(), input, &pose).ok());
    (*model)->Deform(*(*model)->default_factorization(), pose, &scratch);
    EncodeFloat32(scratch.solution.data(), positions.size() / 4, positions.data());
  };
  frame();  // warm-up sizes the buffers
  constexpr int kFrames = 200;
  const long before = deform::test_support::AllocationCount();
  for (int i = 0; i < kFrames; ++i) frame();
  // Other threads of the test binary (gRPC's) may allocate now and then; a per-frame allocation
  // would add at least kFrames.
  EXPECT_LT(deform::test_support::AllocationCount() - before, kFrames / 4);
}

}  // namespace
}  // namespace deform::service
