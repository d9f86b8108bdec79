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

TEST_F(PoseInputTest, ToolsAreCheckedAgainstTheMeshBox) {
  const Eigen::Vector3d lower(0, 0, 0), upper(1, 1, 1);
  v1::PoseUpdate update;
  v1::ToolState* sphere = update.add_tools();
  sphere->set_shape(v1::ToolState::SHAPE_SPHERE);
  sphere->mutable_center()->set_z(1.1);
  sphere->set_radius(0.2);
  v1::ToolState* capsule = update.add_tools();
  capsule->set_shape(v1::ToolState::SHAPE_CAPSULE);
  capsule->mutable_center()->set_x(0.5);
  capsule->mutable_end()->set_x(0.9);
  capsule->set_radius(0.1);
  ToolSet tools;
  ASSERT_TRUE(ToolsFromProto(update, lower, upper, &tools).ok());
  ASSERT_EQ(tools.count, 2);
  EXPECT_EQ(tools.tools[0].shape, Tool::Shape::kSphere);
  EXPECT_EQ(tools.tools[0].a, Eigen::Vector3d(0, 0, 1.1));
  EXPECT_EQ(tools.tools[1].shape, Tool::Shape::kCapsule);
  EXPECT_EQ(tools.tools[1].b, Eigen::Vector3d(0.9, 0, 0));

  v1::PoseUpdate bad = update;
  bad.mutable_tools(1)->clear_end();
  EXPECT_THAT(ToolsFromProto(bad, lower, upper, &tools).message(), HasSubstr("tool 1"));
  bad = update;
  bad.mutable_tools(0)->set_radius(std::numeric_limits<double>::quiet_NaN());
  EXPECT_THAT(ToolsFromProto(bad, lower, upper, &tools).message(), HasSubstr("finite"));
  bad = update;
  bad.mutable_tools(0)->set_shape(v1::ToolState::SHAPE_UNSPECIFIED);
  EXPECT_THAT(ToolsFromProto(bad, lower, upper, &tools).message(), HasSubstr("shape"));
  bad = update;
  bad.mutable_tools(0)->clear_center();
  EXPECT_FALSE(ToolsFromProto(bad, lower, upper, &tools).ok());
  bad = update;
  for (int t = 0; t < ToolSet::kMaxTools; ++t) *bad.add_tools() = update.tools(0);
  EXPECT_THAT(ToolsFromProto(bad, lower, upper, &tools).message(), HasSubstr("at most 4"));
  EXPECT_EQ(tools.count, 0);
}

}  // namespace
}  // namespace deform::service
