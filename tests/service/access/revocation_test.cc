// A token revoked or changed by a reload of the token file (deformd's SIGHUP,
// DeformServer::ReloadTokens) ends that token's open Deform streams within a second: a
// KIND_CREDENTIALS_REVOKED notice, then UNAUTHENTICATED. Streams of tokens that still stand carry
// on.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "service/access/identity.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_server.h"
#include "tests/service/support/token_file.h"

namespace deform::test_support {
namespace {

using Clock = std::chrono::steady_clock;

struct OpenStream {
  StreamRecorder recorder;
  std::unique_ptr<client::DeformStream> stream;
  std::unique_ptr<PosePacer> pacer;
};

void Open(client::DeformClient& client, const std::string& mesh_id, OpenStream* open) {
  open->stream = client.OpenStream(mesh_id, open->recorder.Callbacks());
  open->pacer = std::make_unique<PosePacer>(open->stream.get(), std::chrono::milliseconds(5));
  ASSERT_TRUE(open->recorder.WaitForFrames(3));
}

TEST(RevocationTest, ARevokedOrChangedTokenEndsItsStreamsWithinASecond) {
  TempDir dir;
  const std::string file = dir.Write("tokens", TokenLine("token-a", "ward-a", "tenant") +
                                                   TokenLine("token-b", "ward-b", "tenant") +
                                                   TokenLine("token-op", "ops", "operator"));
  TestServer server(TestServerOptions(), file);
  auto ward_a = server.NewClient(WithToken("token-a"));
  auto ward_b = server.NewClient(WithToken("token-b"));
  auto ops = server.NewClient(WithToken("token-op"));
  ASSERT_TRUE(ward_a->WaitForReady(60'000));
  v1::MeshSummary a_mesh, b_mesh;
  ASSERT_TRUE(ward_a->LoadPhantom(300, {}, &a_mesh).ok());
  ASSERT_TRUE(ward_b->LoadPhantom(300, {}, &b_mesh).ok());
  OpenStream revoked, changed, kept;
  Open(*ward_a, a_mesh.mesh_id(), &revoked);
  Open(*ops, a_mesh.mesh_id(), &changed);
  Open(*ward_b, b_mesh.mesh_id(), &kept);

  // ward-a's token is removed; the operator's token now names another role.
  dir.Write("tokens",
            TokenLine("token-b", "ward-b", "tenant") + TokenLine("token-op", "ops", "tenant"));
  const auto reloaded_at = Clock::now();
  ASSERT_TRUE(server.server().ReloadTokens().ok());
  for (OpenStream* ended : {&revoked, &changed}) {
    ASSERT_TRUE(ended->recorder.WaitForDone());
    EXPECT_LT(Clock::now() - reloaded_at, std::chrono::seconds(1));
    const grpc::Status status = *ended->recorder.status();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << status.error_message();
    const auto notice = ended->recorder.FindNotice(v1::Notice::KIND_CREDENTIALS_REVOKED);
    ASSERT_TRUE(notice.has_value()) << "no notice before the end";
    EXPECT_FALSE(ended->recorder.events().back().is_frame) << "a frame after the notice";
    ended->pacer.reset();
  }
  // The stream whose token stands carries on.
  const std::int64_t frames = kept.recorder.frames();
  ASSERT_TRUE(kept.recorder.WaitForFrames(frames + 5));
  EXPECT_FALSE(kept.recorder.status().has_value());
  kept.pacer.reset();
  kept.stream->Close();
  EXPECT_TRUE(kept.stream->Wait().ok());
  // A stream opened with the revoked token after the reload is refused.
  StreamRecorder late;
  auto stream = ward_a->OpenStream(a_mesh.mesh_id(), late.Callbacks());
  EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::UNAUTHENTICATED);
}

}  // namespace
}  // namespace deform::test_support
