// A Deform stream's own memory is in the budgets (Admission::MemoryHold): its buffers from
// `start` (before they are allocated), and the factorization of a stiffness update while the
// stream holds it. A stream that does not fit is RESOURCE_EXHAUSTED naming the budget; a
// stiffness update that does not fit is KIND_STIFFNESS_REJECTED naming it, and the stream goes on
// with its frames. Everything is released when the stream ends.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "service/context/latest_frames.h"
#include "service/context/service_context.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/test_server.h"

namespace deform {
namespace {

using test_support::KneePose;
using test_support::StreamRecorder;
using test_support::TestServer;
using test_support::TestServerOptions;
using ::testing::HasSubstr;

constexpr int kVertices = 3000;

class StreamMemoryTest : public ::testing::Test {
 protected:
  // The phantom's sizes, measured on a roomy server.
  void SetUp() override {
    TestServer probe;
    const std::string id = Load(probe);
    mesh_bytes_ = probe.server().context().admission().memory_bytes_used();
    auto entry = probe.server().context().registry().Find(id);
    ASSERT_TRUE(entry.ok());
    // The solve's scratch, the constraints', each frame's bone surface transforms and the latest
    // frame kept for contact queries (latest_frames.h).
    const SkinConstraints* constraints = (*entry)->constraints.constraints.get();
    ASSERT_NE(constraints, nullptr);
    scratch_bytes_ = (*entry)->model->ScratchBytes() + constraints->ScratchBytes() +
                     3 * 48 * static_cast<std::size_t>(constraints->bones()->num_surfaces()) +
                     service::LatestFrame::Bytes((*entry)->model->mesh().num_vertices());
    factorization_bytes_ = (*entry)->model->FactorizationBytes();
  }

  // A server whose budget holds the phantom and `spare` more bytes.
  void StartWithSpare(std::size_t spare) {
    service::ServerOptions options = TestServerOptions();
    options.limits.max_memory_bytes = mesh_bytes_ + spare;
    server_ = std::make_unique<TestServer>(options);
    client_ = server_->NewClient();
    mesh_id_ = Load(*server_);
  }

  std::string Load(const TestServer& server) {
    v1::MeshSummary summary;
    const grpc::Status status = server.NewClient()->LoadPhantom(kVertices, {}, &summary);
    EXPECT_TRUE(status.ok()) << status.error_message();
    vertices_ = summary.vertex_count();
    return summary.mesh_id();
  }

  std::size_t StreamBytes() const {
    return server_->server().context().admission().memory_bytes_streams();
  }
  // Waits (up to 2 s) for the streams' holds to come to `bytes`: a reactor, and its hold, goes
  // with gRPC's and the workers' last references, just after the client sees the end.
  bool WaitForStreamBytes(std::size_t bytes) const {
    for (int i = 0; i < 200 && StreamBytes() != bytes; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return StreamBytes() == bytes;
  }

  // The bytes of one float32 stream: its scratch and three frames of 12 bytes per vertex.
  std::size_t OneStream() const { return scratch_bytes_ + std::size_t{3} * 12 * vertices_; }

  std::size_t vertices_ = 0;
  std::size_t mesh_bytes_ = 0;
  std::size_t scratch_bytes_ = 0;
  std::size_t factorization_bytes_ = 0;
  std::unique_ptr<TestServer> server_;
  std::unique_ptr<client::DeformClient> client_;
  std::string mesh_id_;
};

TEST_F(StreamMemoryTest, StreamsBeyondTheBudgetAreRefusedNamingIt) {
  const std::size_t one = OneStream();
  StartWithSpare(2 * one + one / 2);  // room for two streams' buffers, not three
  std::vector<std::unique_ptr<StreamRecorder>> recorders;
  std::vector<std::unique_ptr<client::DeformStream>> streams;
  for (int i = 0; i < 2; ++i) {
    recorders.push_back(std::make_unique<StreamRecorder>());
    streams.push_back(client_->OpenStream(mesh_id_, recorders.back()->Callbacks()));
    ASSERT_TRUE(streams.back()->SendPose(KneePose(1, 30)));
    ASSERT_TRUE(recorders.back()->WaitForFrames(1)) << "stream " << i;
  }
  EXPECT_EQ(StreamBytes(), 2 * one);

  StreamRecorder third;
  auto refused = client_->OpenStream(mesh_id_, third.Callbacks());
  const grpc::Status status = refused->Wait();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("a Deform stream's buffers"));
  EXPECT_THAT(status.error_message(), HasSubstr("--max-memory-mb"));
  EXPECT_TRUE(WaitForStreamBytes(2 * one)) << "a refused stream holds nothing";

  // The others stream on; one ends, and a new stream fits again.
  ASSERT_TRUE(streams[0]->SendPose(KneePose(2, 60)));
  ASSERT_TRUE(recorders[0]->WaitForFrameWithSequence(2));
  streams[1]->Close();
  EXPECT_TRUE(streams[1]->Wait().ok());
  ASSERT_TRUE(WaitForStreamBytes(one));
  StreamRecorder fourth;
  auto again = client_->OpenStream(mesh_id_, fourth.Callbacks());
  ASSERT_TRUE(again->SendPose(KneePose(1, 45)));
  ASSERT_TRUE(fourth.WaitForFrames(1)) << "the released buffers were not given back";
  for (auto* stream : {streams[0].get(), again.get()}) {
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
  }
}

TEST_F(StreamMemoryTest, AStiffnessFactorizationIsCountedWhileTheStreamHoldsIt) {
  const std::size_t one = OneStream();
  StartWithSpare(one + factorization_bytes_ + factorization_bytes_ / 2);
  StreamRecorder recorder;
  auto stream = client_->OpenStream(mesh_id_, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrames(1));
  EXPECT_EQ(StreamBytes(), one);

  v1::StiffnessUpdate stiffness;
  v1::RegionWeight* weight = stiffness.add_region_weights();
  weight->set_joint("knee");
  weight->set_weight(20);
  ASSERT_TRUE(stream->SendStiffness(stiffness));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_APPLIED));
  EXPECT_EQ(StreamBytes(), one + factorization_bytes_) << "the stream's own factorization";

  // A second update needs a second factorization beside the first while it is built: no room.
  weight->set_weight(5);
  ASSERT_TRUE(stream->SendStiffness(stiffness));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_REJECTED));
  const auto rejected = recorder.FindNotice(v1::Notice::KIND_STIFFNESS_REJECTED);
  EXPECT_EQ(rejected->stiffness_version(), 2u);
  EXPECT_THAT(rejected->message(), HasSubstr("the factorization of stiffness version 2"));
  EXPECT_THAT(rejected->message(), HasSubstr("--max-memory-mb"));
  EXPECT_EQ(StreamBytes(), one + factorization_bytes_);

  // Frames go on with the applied version.
  ASSERT_TRUE(stream->SendPose(KneePose(2, 60)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(2));
  EXPECT_EQ(recorder.last_frame().stiffness_version(), 1u);
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
}

TEST_F(StreamMemoryTest, EverythingIsReleasedWhenTheStreamEnds) {
  StartWithSpare(std::size_t{64} << 20);
  {
    StreamRecorder recorder;
    auto stream = client_->OpenStream(mesh_id_, recorder.Callbacks());
    ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
    ASSERT_TRUE(recorder.WaitForFrames(1));
    v1::StiffnessUpdate stiffness;
    v1::RegionWeight* weight = stiffness.add_region_weights();
    weight->set_joint("knee");
    weight->set_weight(20);
    ASSERT_TRUE(stream->SendStiffness(stiffness));
    ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_APPLIED));
    EXPECT_GT(StreamBytes(), 0u);
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
  }
  EXPECT_TRUE(WaitForStreamBytes(0)) << StreamBytes() << " bytes still held";
}

}  // namespace
}  // namespace deform
