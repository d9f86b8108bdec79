// A store shared by replicas (--store-shared, docs/cluster.md): a mesh loaded on one server is
// built on another when a call names it there (UNAVAILABLE with a retry delay meanwhile, which
// the client library waits out), an unload on one is seen by the other, another tenant cannot
// name it, and a stream whose server drains opens itself again on the next one (ReconnectPolicy).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service/access/identity.h"
#include "service/registry/mesh_store.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_server.h"

namespace deform {
namespace {

using test_support::KneePose;
using test_support::StreamRecorder;
using test_support::TempDir;
using test_support::TestServerOptions;
using ::testing::HasSubstr;

client::ClientOptions WithToken(const std::string& token) {
  client::ClientOptions options;
  options.token = token;
  return options;
}

// A replica: a server on the shared store (and tokens), optionally on a given port.
class Replica {
 public:
  Replica(const std::string& store, const std::string& key, const std::string& tokens,
          int port = 0) {
    service::ServerOptions options = TestServerOptions();
    options.listen_address = "127.0.0.1:" + std::to_string(port);
    server_ = std::make_unique<service::DeformServer>(options);
    EXPECT_TRUE(server_->UseTokenFile(tokens).ok());
    const Status used = server_->UseStore(store, nullptr, key, /*shared=*/true);
    EXPECT_TRUE(used.ok()) << used.ToString();
    const Status started = server_->Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
  }
  ~Replica() { server_->Shutdown(); }
  std::unique_ptr<client::DeformClient> NewClient(const std::string& token) const {
    return std::make_unique<client::DeformClient>(target(), WithToken(token));
  }
  std::string target() const { return "127.0.0.1:" + std::to_string(server_->port()); }
  int port() const { return server_->port(); }
  service::DeformServer& server() { return *server_; }

 private:
  std::unique_ptr<service::DeformServer> server_;
};

class SharedStoreTest : public ::testing::Test {
 protected:
  SharedStoreTest() {
    tokens_ = dir_.Write("tokens", service::Sha256Hex("token-a") + " ward-a tenant\n" +
                                       service::Sha256Hex("token-b") + " ward-b tenant\n");
    store_ = dir_.Path("store");
    key_ = dir_.Path("store.key");
  }
  std::string LoadPhantom(client::DeformClient& client, int vertices = 300) {
    v1::MeshSummary summary;
    const grpc::Status status = client.LoadPhantom(vertices, {}, &summary);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return summary.mesh_id();
  }

  TempDir dir_;
  std::string tokens_, store_, key_;
};

TEST_F(SharedStoreTest, AMeshLoadedOnOneReplicaIsBuiltOnAnotherWhenNamed) {
  Replica first(store_, key_, tokens_);
  Replica second(store_, key_, tokens_);
  const std::string id = LoadPhantom(*first.NewClient("token-a"));
  // Loading the same content on the other replica names the same mesh (the shared key).
  EXPECT_EQ(second.server().context().registry().mesh_count(), 0);

  // The first call naming it on the other replica: UNAVAILABLE with a retry delay, its build
  // started.
  auto raw = second.NewClient("token-a");
  grpc::ClientContext context;
  client::AddCallCredentials(WithToken("token-a"), &context);
  v1::GetMeshInfoRequest request;
  request.set_mesh_id(id);
  v1::GetMeshInfoResponse info;
  const grpc::Status building = raw->stub()->GetMeshInfo(&context, request, &info);
  ASSERT_EQ(building.error_code(), grpc::StatusCode::UNAVAILABLE) << building.error_message();
  EXPECT_THAT(building.error_message(), HasSubstr("being built"));
  google::rpc::Status details;
  ASSERT_TRUE(details.ParseFromString(building.error_details()));
  ASSERT_EQ(details.details_size(), 1);
  google::rpc::RetryInfo retry;
  ASSERT_TRUE(details.details(0).UnpackTo(&retry));
  EXPECT_GT(retry.retry_delay().nanos() + retry.retry_delay().seconds() * 1'000'000'000, 0);

  // The library waits it out; then frames come from the second replica.
  ASSERT_TRUE(raw->GetMeshInfo(id, false, &info).ok());
  EXPECT_EQ(info.summary().mesh_id(), id);
  EXPECT_EQ(second.server().context().registry().mesh_count(), 1);
  StreamRecorder recorder;
  auto stream = raw->OpenStream(id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 40)));
  EXPECT_TRUE(recorder.WaitForFrames(1));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());

  // The same content loaded on the second replica is that mesh (no second build).
  const int registrations = second.server().context().registry().registrations();
  EXPECT_EQ(LoadPhantom(*second.NewClient("token-a")), id);
  EXPECT_EQ(second.server().context().registry().registrations(), registrations);
}

TEST_F(SharedStoreTest, AnotherTenantCannotNameTheMeshOnAnyReplica) {
  Replica first(store_, key_, tokens_);
  Replica second(store_, key_, tokens_);
  const std::string id = LoadPhantom(*first.NewClient("token-a"));
  v1::GetMeshInfoResponse info;
  const grpc::Status status = second.NewClient("token-b")->GetMeshInfo(id, false, &info);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status.error_message();
  EXPECT_EQ(second.server().context().registry().mesh_count(), 0);  // nothing was built
  // The same file uploaded by the other tenant is another mesh.
  EXPECT_NE(LoadPhantom(*second.NewClient("token-b")), id);
}

TEST_F(SharedStoreTest, AnUnloadOnOneReplicaIsSeenByTheOther) {
  Replica first(store_, key_, tokens_);
  Replica second(store_, key_, tokens_);
  const std::string id = LoadPhantom(*first.NewClient("token-a"));
  v1::GetMeshInfoResponse info;
  ASSERT_TRUE(second.NewClient("token-a")->GetMeshInfo(id, false, &info).ok());
  ASSERT_TRUE(first.NewClient("token-a")->UnloadMesh(id).ok());
  EXPECT_EQ(second.NewClient("token-a")->GetMeshInfo(id, false, &info).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(second.server().context().registry().mesh_count(), 0);
  // An unload on a replica that never built the mesh removes it everywhere too.
  const std::string again = LoadPhantom(*first.NewClient("token-a"), 320);
  ASSERT_TRUE(second.NewClient("token-a")->UnloadMesh(again).ok());
  EXPECT_EQ(first.NewClient("token-a")->GetMeshInfo(again, false, &info).error_code(),
            grpc::StatusCode::NOT_FOUND);
}

TEST_F(SharedStoreTest, AStreamWhoseServerDrainsResumesOnTheNextOne) {
  auto first = std::make_unique<Replica>(store_, key_, tokens_);
  const int port = first->port();
  auto client = first->NewClient("token-a");
  const std::string id = LoadPhantom(*client);
  StreamRecorder recorder;
  std::atomic<int> reconnects{0};
  client::DeformClient::StreamCallbacks callbacks = recorder.Callbacks();
  callbacks.on_reconnect = [&](const grpc::Status& lost, int) {
    EXPECT_EQ(lost.error_code(), grpc::StatusCode::UNAVAILABLE) << lost.error_message();
    ++reconnects;
  };
  client::DeformClient::StreamOptions options;
  options.reconnect.enabled = true;
  auto stream = client->OpenStream(id, callbacks, options);
  ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrames(1));

  first.reset();  // drains: the stream ends UNAVAILABLE on that server
  Replica next(store_, key_, tokens_, port);
  // Poses sent meanwhile wait for the next server; the latest is sent there.
  EXPECT_TRUE(stream->SendPose(KneePose(2, 50)));
  EXPECT_TRUE(recorder.WaitForFrameWithSequence(2));
  EXPECT_GE(reconnects.load(), 1);
  EXPECT_FALSE(recorder.status().has_value());  // the application saw no end
  EXPECT_TRUE(stream->SendPose(KneePose(3, 60)));
  EXPECT_TRUE(recorder.WaitForFrameWithSequence(3));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
}

TEST_F(SharedStoreTest, WithoutReconnectAStreamEndsWhenItsServerDrains) {
  auto first = std::make_unique<Replica>(store_, key_, tokens_);
  auto client = first->NewClient("token-a");
  const std::string id = LoadPhantom(*client);
  StreamRecorder recorder;
  auto stream = client->OpenStream(id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrames(1));
  first.reset();
  EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::UNAVAILABLE);
}

TEST_F(SharedStoreTest, SharingNeedsAKeyAndExcludesAnExclusiveServer) {
  {
    service::DeformServer server(TestServerOptions());
    const Status refused = server.UseStore(store_, nullptr, "", /*shared=*/true);
    EXPECT_EQ(refused.code(), StatusCode::kFailedPrecondition);
    EXPECT_THAT(refused.message(), HasSubstr("--store-key"));
  }
  auto exclusive = service::MeshStore::Open(store_, key_);
  ASSERT_TRUE(exclusive.ok());
  EXPECT_FALSE(service::MeshStore::Open(store_, key_, /*shared=*/true).ok());
  exclusive->reset();
  auto shared = service::MeshStore::Open(store_, key_, /*shared=*/true);
  ASSERT_TRUE(shared.ok()) << shared.status().ToString();
  EXPECT_TRUE(service::MeshStore::Open(store_, key_, /*shared=*/true).ok());
  EXPECT_FALSE(service::MeshStore::Open(store_, key_).ok());
}

}  // namespace
}  // namespace deform
