// A fixture with an in-process server, a client for the test, and a second client whose stream
// keeps running through the test: every test can check that its bad input did not disturb it.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "deform_client.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/test_server.h"
#include "tests/service/support/websocket_deform_stream.h"

namespace deform::test_support {

// The transports a stream handler's tests run over (one body each: TEST_P over both).
enum class Transport { kGrpc, kWebSocket };

inline std::string TransportName(const ::testing::TestParamInfo<Transport>& info) {
  return info.param == Transport::kGrpc ? "Grpc" : "WebSocket";
}

class ServiceTest : public ::testing::Test {
 protected:
  // Starts the server and the background client: a phantom of `background_vertices` loaded and
  // streamed from its own client and thread.
  void StartServer(service::ServerOptions options = TestServerOptions(),
                   int background_vertices = 300) {
    server_ = std::make_unique<TestServer>(options, "", transport_ == Transport::kWebSocket);
    client_ = server_->NewClient();
    ASSERT_TRUE(client_->WaitForReady(60'000));
    background_client_ = server_->NewClient();
    v1::MeshSummary summary;
    const grpc::Status loaded =
        background_client_->LoadPhantom(background_vertices, {}, &summary, {}, "background");
    ASSERT_TRUE(loaded.ok()) << loaded.error_message();
    background_mesh_id_ = summary.mesh_id();
    background_stream_ =
        background_client_->OpenStream(background_mesh_id_, background_recorder_.Callbacks());
    background_pacer_ =
        std::make_unique<PosePacer>(background_stream_.get(), std::chrono::milliseconds(5));
    ASSERT_TRUE(background_recorder_.WaitForFrames(3));
  }

  void TearDown() override {
    background_pacer_.reset();
    if (background_stream_ != nullptr) {
      background_stream_->Close();
      const grpc::Status status = background_stream_->Wait();
      if (expect_background_ok_at_end_) {
        EXPECT_TRUE(status.ok()) << "background stream: " << status.error_message();
      }
      background_stream_.reset();
    }
    client_.reset();
    background_client_.reset();
    server_.reset();
  }

  // The background stream is still open and still receiving frames.
  void ExpectBackgroundStreamAlive() {
    ASSERT_NE(background_stream_, nullptr);
    const std::int64_t before = background_recorder_.frames();
    EXPECT_TRUE(background_recorder_.WaitForFrames(before + 3))
        << "the background stream stopped receiving frames";
    EXPECT_FALSE(background_recorder_.status().has_value())
        << "the background stream ended: " << background_recorder_.status()->error_message();
  }

  // A Deform stream of the test's on `mesh_id`, over the test's transport (the background stream
  // always runs over gRPC).
  std::unique_ptr<client::DeformStream> OpenStream(
      const std::string& mesh_id, client::DeformClient::StreamCallbacks callbacks) {
    if (transport_ == Transport::kWebSocket) {
      return std::make_unique<WebSocketDeformStream>(server_->web_port(), mesh_id,
                                                     std::move(callbacks));
    }
    return client_->OpenStream(mesh_id, std::move(callbacks));
  }

  // Loads a phantom through the test's client; its id.
  std::string LoadPhantom(int vertices, const v1::MethodOptions& options = {},
                          v1::MeshSummary* summary_out = nullptr) {
    v1::MeshSummary summary;
    const grpc::Status status = client_->LoadPhantom(vertices, options, &summary);
    if (summary_out != nullptr) *summary_out = summary;
    EXPECT_TRUE(status.ok()) << status.error_message();
    return summary.mesh_id();
  }

  std::unique_ptr<TestServer> server_;
  std::unique_ptr<client::DeformClient> client_;
  std::unique_ptr<client::DeformClient> background_client_;
  std::string background_mesh_id_;
  StreamRecorder background_recorder_;
  std::unique_ptr<client::DeformStream> background_stream_;
  std::unique_ptr<PosePacer> background_pacer_;
  bool expect_background_ok_at_end_ = true;
  Transport transport_ = Transport::kGrpc;
};

}  // namespace deform::test_support
