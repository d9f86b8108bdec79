// Root motion over gRPC: the pose's root transform moves the whole body rigidly (world frame), on
// both rotation blends; quaternions too large to square are normalized, not turned into the rest
// pose; a bad root is rejected with a notice while the stream goes on.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/geometry/mesh.h"
#include "core/io/phantom.h"
#include "tests/service/support/service_fixture.h"

namespace deform {
namespace {

using ::testing::HasSubstr;

class RootMotionTest : public test_support::ServiceTest {};

// The frame answering `pose` (sent with sequence 1) on a new stream.
std::vector<float> FrameFor(client::DeformClient& client, const std::string& mesh_id,
                            v1::PoseUpdate pose) {
  test_support::StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = client.OpenStream(mesh_id, recorder.Callbacks());
  pose.set_sequence(1);
  EXPECT_TRUE(stream->SendPose(pose));
  EXPECT_TRUE(recorder.WaitForFrameWithSequence(1));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  return client::DecodePositions(recorder.last_frame().positions());
}

v1::PoseUpdate RootPose(double degrees_about_y, const Eigen::Vector3d& translation) {
  v1::PoseUpdate pose;
  const Eigen::Quaterniond q(
      Eigen::AngleAxisd(degrees_about_y * M_PI / 180, Eigen::Vector3d::UnitY()));
  v1::RootTransform* root = pose.mutable_root();
  root->mutable_rotation()->set_w(q.w());
  root->mutable_rotation()->set_x(q.x());
  root->mutable_rotation()->set_y(q.y());
  root->mutable_rotation()->set_z(q.z());
  root->mutable_translation()->set_x(translation.x());
  root->mutable_translation()->set_y(translation.y());
  root->mutable_translation()->set_z(translation.z());
  return pose;
}

TEST_F(RootMotionTest, RootTransformMovesTheRestMeshRigidly) {
  StartServer();
  constexpr int kVertices = 800;
  auto phantom = MakeKneePhantom(kVertices);
  ASSERT_TRUE(phantom.ok());
  const double diagonal = BoundingBoxDiagonal(phantom->mesh.vertices);
  const Eigen::Vector3d translation(10, 0, 0);
  const Eigen::AngleAxisd rotation(M_PI / 2, Eigen::Vector3d::UnitY());
  for (const v1::RotationBlend blend : {v1::ROTATION_BLEND_QUATERNION, v1::ROTATION_BLEND_LINEAR}) {
    v1::MethodOptions options;
    options.set_rotation_blend(blend);
    const std::string mesh_id = LoadPhantom(kVertices, options);
    const std::vector<float> frame = FrameFor(*client_, mesh_id, RootPose(90, translation));
    ASSERT_EQ(frame.size(), 3u * phantom->mesh.num_vertices());
    double worst = 0;
    for (int i = 0; i < phantom->mesh.num_vertices(); ++i) {
      const Eigen::Vector3d expected =
          rotation * Eigen::Vector3d(phantom->mesh.vertices.row(i).transpose()) + translation;
      const Eigen::Vector3d got(frame[3 * i], frame[3 * i + 1], frame[3 * i + 2]);
      worst = std::max(worst, (got - expected).norm());
    }
    EXPECT_LT(worst, 1e-6 * diagonal) << "blend " << blend;
  }
  ExpectBackgroundStreamAlive();
}

TEST_F(RootMotionTest, NearlyUnitQuaternionsAreNormalized) {
  StartServer();
  const std::string mesh_id = LoadPhantom(400);
  v1::PoseUpdate scaled = RootPose(90, Eigen::Vector3d::Zero());
  v1::Quaternion* q = scaled.mutable_root()->mutable_rotation();
  q->set_w(q->w() * 0.95);
  q->set_y(q->y() * 0.95);
  const std::vector<float> near_unit = FrameFor(*client_, mesh_id, scaled);
  const std::vector<float> unit =
      FrameFor(*client_, mesh_id, RootPose(90, Eigen::Vector3d::Zero()));
  ASSERT_EQ(near_unit.size(), unit.size());
  for (std::size_t c = 0; c < near_unit.size(); ++c) ASSERT_NEAR(near_unit[c], unit[c], 1e-5) << c;
}

TEST_F(RootMotionTest, NonFiniteOrZeroRootIsRejectedAndTheStreamGoesOn) {
  StartServer();
  const std::string mesh_id = LoadPhantom(400);
  test_support::StreamRecorder recorder;
  auto stream = client_->OpenStream(mesh_id, recorder.Callbacks());
  v1::PoseUpdate zero = RootPose(0, Eigen::Vector3d::Zero());
  zero.mutable_root()->mutable_rotation()->set_w(0);
  zero.set_sequence(1);
  ASSERT_TRUE(stream->SendPose(zero));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_POSE_REJECTED));
  EXPECT_THAT(recorder.FindNotice(v1::Notice::KIND_POSE_REJECTED)->message(),
              HasSubstr("zero quaternion"));
  v1::PoseUpdate far = RootPose(0, Eigen::Vector3d(std::nan(""), 0, 0));
  far.set_sequence(2);
  ASSERT_TRUE(stream->SendPose(far));
  v1::PoseUpdate good = RootPose(0, Eigen::Vector3d(1, 0, 0));
  good.set_sequence(3);
  ASSERT_TRUE(stream->SendPose(good));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(3));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

}  // namespace
}  // namespace deform
