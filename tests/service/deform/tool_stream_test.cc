// Tools in the Deform stream (PoseUpdate.tools): a sphere pressed into the phantom's thigh leaves
// no skin inside it and the frame reports it, a pose without tools gives back the tool-free frame
// bit for bit (latest wins: tools go with their pose), and bad tools reject the pose with a notice
// while the stream goes on. Every body runs over both transports.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/service/support/service_fixture.h"

namespace deform::test_support {
namespace {

constexpr int kVertices = 800;
// The 800-vertex phantom's diagonal (8.97): its thigh front is at y 6, z 0.66, so this sphere is
// pressed about 0.1 into it.
constexpr double kDiagonal = 8.97;
constexpr char kSphere[] = "sphere:0,6,0.86,0.3";

class ToolStreamTest : public ServiceTest, public ::testing::WithParamInterface<Transport> {
 protected:
  void SetUp() override { transport_ = GetParam(); }
};

INSTANTIATE_TEST_SUITE_P(Transports, ToolStreamTest,
                         ::testing::Values(Transport::kGrpc, Transport::kWebSocket), TransportName);

v1::PoseUpdate WithTool(v1::PoseUpdate pose, const std::string& spec) {
  std::string error;
  EXPECT_TRUE(client::AddToolSpec(spec, &pose, &error)) << error;
  return pose;
}

TEST_P(ToolStreamTest, ASpherePressesTheSkinAndLiftingItGivesBackTheFrame) {
  StartServer();
  const std::string mesh_id = LoadPhantom(kVertices);
  StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  const v1::DeformFrame free = recorder.last_frame();
  ASSERT_TRUE(stream->SendPose(WithTool(KneePose(2, 30), kSphere)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(2));
  const v1::DeformFrame pressed = recorder.last_frame();
  ASSERT_TRUE(stream->SendPose(KneePose(3, 30)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(3));
  const v1::DeformFrame lifted = recorder.last_frame();
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());

  const v1::FrameConstraints& c = pressed.constraints();
  EXPECT_GT(c.tool_penetrating_before(), 0u);
  EXPECT_EQ(c.tool_penetrating_after(), 0u);
  EXPECT_LE(c.tool_max_depth_after(), 1e-4 * kDiagonal);
  EXPECT_GT(c.tool_contacts(), 0u);
  EXPECT_LE(c.tool_contacts(), c.contacts());
  EXPECT_FALSE(c.tools_unresolved());
  EXPECT_NE(pressed.positions(), free.positions());
  EXPECT_EQ(lifted.positions(), free.positions());
  EXPECT_EQ(lifted.constraints().tool_contacts(), 0u);
  EXPECT_EQ(lifted.constraints().tool_penetrating_before(), 0u);
  ExpectBackgroundStreamAlive();
}

TEST_P(ToolStreamTest, BadToolsRejectThePoseAndTheStreamGoesOn) {
  StartServer();
  const std::string mesh_id = LoadPhantom(kVertices);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  v1::PoseUpdate five = KneePose(1, 30);
  for (int t = 0; t < 5; ++t) five = WithTool(five, kSphere);
  ASSERT_TRUE(stream->SendPose(five));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_POSE_REJECTED));
  EXPECT_THAT(recorder.FindNotice(v1::Notice::KIND_POSE_REJECTED)->message(),
              ::testing::HasSubstr("at most 4 tools"));
  // Each sent after the last one's notice: the client library's latest-wins would drop a pose
  // still waiting to be written.
  const auto rejected_notices = [&] {
    int count = 0;
    for (const RecordedEvent& event : recorder.EventsLocked()) {
      count += !event.is_frame && event.notice.kind() == v1::Notice::KIND_POSE_REJECTED;
    }
    return count;
  };
  v1::PoseUpdate unset = KneePose(0, 30);
  unset.add_tools()->set_radius(0.3);  // no shape
  std::vector<v1::PoseUpdate> bad = {WithTool(KneePose(0, 30), "sphere:0,6,0.86,0"),
                                     WithTool(KneePose(0, 30), "sphere:0,6,0.86,100"),
                                     WithTool(KneePose(0, 30), "sphere:0,600,0.86,0.3"), unset};
  std::uint64_t sequence = 2;
  for (v1::PoseUpdate& pose : bad) {
    pose.set_sequence(sequence++);
    ASSERT_TRUE(stream->SendPose(pose));
    const int expected = static_cast<int>(sequence) - 1;
    ASSERT_TRUE(recorder.WaitUntil([&] { return rejected_notices() >= expected; }));
  }
  ASSERT_TRUE(stream->SendPose(WithTool(KneePose(sequence, 30), kSphere)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(sequence));
  EXPECT_GT(recorder.last_frame().constraints().tool_contacts(), 0u);
  int rejected = 0;
  for (const RecordedEvent& event : recorder.events()) {
    if (event.is_frame || event.notice.kind() != v1::Notice::KIND_POSE_REJECTED) continue;
    ++rejected;
    EXPECT_THAT(event.notice.message(), ::testing::HasSubstr("tool"));
  }
  EXPECT_EQ(rejected, 5);
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
}

TEST_P(ToolStreamTest, AMeshWithoutBonesOrVolumeTakesTools) {
  StartServer();
  v1::LoadMeshHeader header;
  header.mutable_phantom()->set_vertices(kVertices);
  header.mutable_phantom()->set_without_bones(true);
  header.mutable_options()->mutable_constraints()->set_keep_volume(false);
  v1::MeshSummary summary;
  ASSERT_TRUE(client_->LoadMesh(header, {}, &summary).ok());
  StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = OpenStream(summary.mesh_id(), recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  const v1::DeformFrame free = recorder.last_frame();
  EXPECT_FALSE(free.has_constraints());
  ASSERT_TRUE(stream->SendPose(WithTool(KneePose(2, 30), kSphere)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(2));
  const v1::DeformFrame pressed = recorder.last_frame();
  EXPECT_GT(pressed.constraints().tool_contacts(), 0u);
  EXPECT_LE(pressed.constraints().tool_max_depth_after(), 1e-4 * kDiagonal);
  for (std::uint64_t sequence = 3; sequence <= 5; ++sequence) {  // through every frame slot
    ASSERT_TRUE(stream->SendPose(KneePose(sequence, 30)));
    ASSERT_TRUE(recorder.WaitForFrameWithSequence(sequence));
    const v1::DeformFrame lifted = recorder.last_frame();
    EXPECT_EQ(lifted.positions(), free.positions());
    EXPECT_EQ(lifted.constraints().tool_contacts(), 0u);
    EXPECT_EQ(lifted.constraints().tool_penetrating_before(), 0u);
  }
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
}

}  // namespace
}  // namespace deform::test_support
