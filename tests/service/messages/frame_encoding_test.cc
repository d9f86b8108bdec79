// Compact frames over gRPC through the client library: each encoding decodes to the float32
// stream's frame within the error its frames state, in far fewer bytes; predicted frames carry the
// bone transforms; a bad encoding request is refused by name.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/service/support/service_fixture.h"

namespace deform {
namespace {

using ::testing::HasSubstr;

class FrameEncodingTest : public test_support::ServiceTest {};

struct ReceivedFrame {
  std::vector<float> positions;
  v1::DeformFrame frame;  // as received (positions decoded by the library)
};

ReceivedFrame FrameFor(client::DeformClient& client, const std::string& mesh_id,
                       v1::FrameEncoding encoding, const std::string& pose_spec) {
  test_support::StreamRecorder recorder(/*keep_positions=*/true);
  client::DeformClient::StreamOptions options;
  options.encoding = encoding;
  auto stream = client.OpenStream(mesh_id, recorder.Callbacks(), options);
  v1::PoseUpdate pose;
  std::string error;
  EXPECT_TRUE(client::ParsePoseAngles(pose_spec, &pose, &error)) << error;
  pose.set_sequence(1);
  EXPECT_TRUE(stream->SendPose(pose));
  EXPECT_TRUE(recorder.WaitForFrameWithSequence(1));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ReceivedFrame received;
  received.frame = recorder.last_frame();
  received.positions = client::DecodePositions(received.frame.positions());
  return received;
}

double LargestCoordinateError(const std::vector<float>& a, const std::vector<float>& b) {
  double worst = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    worst = std::max(worst, std::abs(static_cast<double>(a[k]) - b[k]));
  }
  return worst;
}

TEST_F(FrameEncodingTest, EveryEncodingDecodesWithinItsStatedErrorInFewerBytes) {
  StartServer();
  for (const v1::RotationBlend blend : {v1::ROTATION_BLEND_QUATERNION, v1::ROTATION_BLEND_LINEAR}) {
    v1::MethodOptions method;
    method.set_rotation_blend(blend);
    const std::string mesh_id = LoadPhantom(2000, method);
    const std::string pose = "knee:flexion:90,knee:rotation:10";
    const ReceivedFrame exact = FrameFor(*client_, mesh_id, v1::FRAME_ENCODING_FLOAT32, pose);
    ASSERT_FALSE(exact.frame.has_encoded());
    const std::size_t float_bytes = exact.frame.positions().size();
    for (const v1::FrameEncoding encoding :
         {v1::FRAME_ENCODING_QUANTIZED, v1::FRAME_ENCODING_PREDICTED}) {
      const ReceivedFrame coded = FrameFor(*client_, mesh_id, encoding, pose);
      ASSERT_TRUE(coded.frame.has_encoded());
      EXPECT_EQ(coded.frame.encoded().encoding(), encoding);
      ASSERT_EQ(coded.positions.size(), exact.positions.size());
      const double stated = coded.frame.encoded().max_error();
      EXPECT_GT(stated, 0);
      // Within the stated error plus float32 rounding of both sides.
      EXPECT_LE(LargestCoordinateError(coded.positions, exact.positions), stated + 2e-6)
          << "encoding " << encoding << " blend " << blend;
      EXPECT_LT(coded.frame.encoded().data().size() * 2, float_bytes) << "encoding " << encoding;
      v1::GetMeshInfoResponse info;
      ASSERT_TRUE(client_->GetMeshInfo(mesh_id, false, &info).ok());
      EXPECT_EQ(coded.frame.encoded().bone_transforms_size(),
                encoding == v1::FRAME_ENCODING_PREDICTED ? 12 * info.summary().bone_count() : 0);
    }
  }
}

TEST_F(FrameEncodingTest, PredictedFramesAreSmallerThanQuantizedOnes) {
  StartServer();
  const std::string mesh_id = LoadPhantom(2000);
  const std::string pose = "knee:flexion:60";
  const ReceivedFrame quantized = FrameFor(*client_, mesh_id, v1::FRAME_ENCODING_QUANTIZED, pose);
  const ReceivedFrame predicted = FrameFor(*client_, mesh_id, v1::FRAME_ENCODING_PREDICTED, pose);
  EXPECT_LT(predicted.frame.encoded().data().size(), quantized.frame.encoded().data().size());
}

TEST_F(FrameEncodingTest, ABadMaxErrorIsRefusedByName) {
  StartServer();
  const std::string mesh_id = LoadPhantom(400);
  test_support::StreamRecorder recorder;
  client::DeformClient::StreamOptions options;
  options.encoding = v1::FRAME_ENCODING_PREDICTED;
  options.max_error = 0.5;
  auto stream = client_->OpenStream(mesh_id, recorder.Callbacks(), options);
  const grpc::Status status = stream->Wait();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("max_error"));
  ExpectBackgroundStreamAlive();
}

}  // namespace
}  // namespace deform
