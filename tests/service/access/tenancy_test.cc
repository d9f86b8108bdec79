// Identity and tenancy through the real client library: calls without a valid bearer token are
// UNAUTHENTICATED; a tenant sees, downloads, streams and unloads only its own meshes (another
// tenant's id is NOT_FOUND with the unknown-id message); an operator sees all; per-tenant limits;
// the token file reloads (tokens rotate without a restart, a bad file keeps the old tokens); audit
// lines escape client strings.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service/access/audit_log.h"
#include "service/access/identity.h"
#include "service/registry/mesh_id.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_server.h"

namespace deform {
namespace {

using test_support::StreamRecorder;
using test_support::TempDir;
using test_support::TestServer;
using test_support::TestServerOptions;
using ::testing::HasSubstr;
using ::testing::Not;

std::string TokenLine(const std::string& token, const std::string& tenant,
                      const std::string& role) {
  return service::Sha256Hex(token) + "  " + tenant + "  " + role + "\n";
}

std::string TokenFile() {
  return "# deformd tokens\n\n" + TokenLine("token-of-ward-a", "ward-a", "tenant") +
         TokenLine("token-of-ward-b", "ward-b", "tenant") +
         TokenLine("token-of-operator", "ops", "operator");
}

client::ClientOptions WithToken(const std::string& token) {
  client::ClientOptions options;
  options.token = token;
  return options;
}

std::string LoadPhantom(client::DeformClient& client, const std::string& name = "phantom") {
  v1::MeshSummary summary;
  const grpc::Status status = client.LoadPhantom(300, {}, &summary, {}, name);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return summary.mesh_id();
}

std::vector<std::string> ListIds(client::DeformClient& client) {
  std::vector<v1::MeshSummary> meshes;
  const grpc::Status status = client.ListMeshes(&meshes);
  EXPECT_TRUE(status.ok()) << status.error_message();
  std::vector<std::string> ids;
  for (const v1::MeshSummary& mesh : meshes) ids.push_back(mesh.mesh_id());
  return ids;
}

grpc::Status StreamStatus(client::DeformClient& client, const std::string& mesh_id) {
  StreamRecorder recorder;
  auto stream = client.OpenStream(mesh_id, recorder.Callbacks());
  stream->Close();
  return stream->Wait();
}

class TenancyTest : public ::testing::Test {
 protected:
  void Start(service::ServerOptions options = TestServerOptions()) {
    token_file_ = dir_.Write("tokens", TokenFile());
    server_ = std::make_unique<TestServer>(options, token_file_);
    ward_a_ = server_->NewClient(WithToken("token-of-ward-a"));
    ward_b_ = server_->NewClient(WithToken("token-of-ward-b"));
    operator_ = server_->NewClient(WithToken("token-of-operator"));
    ASSERT_TRUE(ward_a_->WaitForReady(60'000));
  }

  TempDir dir_;
  std::string token_file_;
  std::unique_ptr<TestServer> server_;
  std::unique_ptr<client::DeformClient> ward_a_, ward_b_, operator_;
};

TEST_F(TenancyTest, CallsWithoutAValidTokenAreUnauthenticated) {
  Start();
  const std::string mesh_id = LoadPhantom(*ward_a_);
  for (const std::string& token :
       {std::string(), std::string("not-a-token"), service::Sha256Hex("token-of-ward-a")}) {
    SCOPED_TRACE("token '" + token + "'");
    auto client = server_->NewClient(WithToken(token));
    std::vector<v1::MeshSummary> meshes;
    const grpc::Status listed = client->ListMeshes(&meshes);
    EXPECT_EQ(listed.error_code(), grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_THAT(listed.error_message(), Not(HasSubstr("token-of")));
    v1::GetMeshInfoResponse info;
    EXPECT_EQ(client->GetMeshInfo(mesh_id, true, &info).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(client->UnloadMesh(mesh_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
    v1::MeshSummary summary;
    EXPECT_EQ(client->LoadPhantom(300, {}, &summary).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(StreamStatus(*client, mesh_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  EXPECT_EQ(ListIds(*ward_a_), std::vector<std::string>{mesh_id});  // nothing was unloaded
}

TEST_F(TenancyTest, ATenantSeesOnlyItsOwnMeshes) {
  Start();
  const std::string a_mesh = LoadPhantom(*ward_a_, "patient A");
  const std::string b_mesh = LoadPhantom(*ward_b_, "patient B");
  EXPECT_EQ(ListIds(*ward_a_), std::vector<std::string>{a_mesh});
  EXPECT_EQ(ListIds(*ward_b_), std::vector<std::string>{b_mesh});

  // Ward B asking for ward A's mesh gets exactly what it gets for an id that does not exist.
  const std::string unknown = service::NewMeshId();
  v1::GetMeshInfoResponse info;
  const grpc::Status unknown_status = ward_b_->GetMeshInfo(unknown, false, &info);
  const grpc::Status other_status = ward_b_->GetMeshInfo(a_mesh, false, &info);
  EXPECT_EQ(other_status.error_code(), grpc::StatusCode::NOT_FOUND);
  std::string expected = unknown_status.error_message();
  expected.replace(expected.find(unknown), unknown.size(), a_mesh);
  EXPECT_EQ(other_status.error_message(), expected);
  EXPECT_EQ(ward_b_->GetMeshInfo(a_mesh, true, &info).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(StreamStatus(*ward_b_, a_mesh).error_code(), grpc::StatusCode::NOT_FOUND);
  const grpc::Status unloaded = ward_b_->UnloadMesh(a_mesh);
  EXPECT_EQ(unloaded.error_code(), grpc::StatusCode::NOT_FOUND);

  // Ward A's mesh is untouched and serves ward A.
  ASSERT_TRUE(ward_a_->GetMeshInfo(a_mesh, true, &info).ok());
  EXPECT_EQ(info.summary().name(), "patient A");
  EXPECT_TRUE(StreamStatus(*ward_a_, a_mesh).ok());

  // The operator sees both, streams on either and may unload them.
  EXPECT_EQ(ListIds(*operator_), (std::vector<std::string>{a_mesh, b_mesh}));
  EXPECT_TRUE(StreamStatus(*operator_, b_mesh).ok());
  EXPECT_TRUE(operator_->UnloadMesh(a_mesh).ok());
  EXPECT_TRUE(ListIds(*ward_a_).empty());
  EXPECT_EQ(ListIds(*ward_b_), std::vector<std::string>{b_mesh});
}

TEST_F(TenancyTest, PerTenantMeshAndStreamLimits) {
  service::ServerOptions options = TestServerOptions();
  options.limits.tenant_max_meshes = 1;
  options.limits.tenant_max_streams = 1;
  Start(options);
  const std::string a_mesh = LoadPhantom(*ward_a_);
  v1::MeshSummary summary;
  const grpc::Status second = ward_a_->LoadPhantom(300, {}, &summary);
  EXPECT_EQ(second.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(second.error_message(), HasSubstr("--tenant-max-meshes"));
  // The machine-readable form: a QuotaFailure naming the tenant and the option.
  google::rpc::Status details;
  ASSERT_TRUE(details.ParseFromString(second.error_details()));
  google::rpc::QuotaFailure quota_failure;
  ASSERT_EQ(details.details_size(), 1);
  ASSERT_TRUE(details.details(0).UnpackTo(&quota_failure));
  ASSERT_EQ(quota_failure.violations_size(), 1);
  EXPECT_EQ(quota_failure.violations(0).subject(), "tenant:ward-a");
  EXPECT_THAT(quota_failure.violations(0).description(), HasSubstr("--tenant-max-meshes"));
  const std::string b_mesh = LoadPhantom(*ward_b_);  // another tenant is not affected

  StreamRecorder first;
  auto open = ward_a_->OpenStream(a_mesh, first.Callbacks());
  v1::PoseUpdate pose;
  pose.set_sequence(1);
  ASSERT_TRUE(open->SendPose(pose));
  ASSERT_TRUE(first.WaitForFrames(1));  // the stream is open and counted
  const grpc::Status refused = StreamStatus(*ward_a_, a_mesh);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("--tenant-max-streams"));
  EXPECT_TRUE(StreamStatus(*ward_b_, b_mesh).ok());
  open->Close();
  EXPECT_TRUE(open->Wait().ok());
  // The closed stream's place is free again.
  grpc::Status again;
  for (int attempt = 0; attempt < 100; ++attempt) {
    again = StreamStatus(*ward_a_, a_mesh);
    if (again.ok()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(again.ok()) << again.error_message();
}

TEST_F(TenancyTest, TheServerStreamLimitCountsEveryTenantsStreams) {
  service::ServerOptions options = TestServerOptions();
  options.limits.max_streams = 1;
  Start(options);
  const std::string a_mesh = LoadPhantom(*ward_a_);
  const std::string b_mesh = LoadPhantom(*ward_b_);
  StreamRecorder first;
  auto open = ward_a_->OpenStream(a_mesh, first.Callbacks());
  v1::PoseUpdate pose;
  pose.set_sequence(1);
  ASSERT_TRUE(open->SendPose(pose));
  ASSERT_TRUE(first.WaitForFrames(1));
  // Another tenant, with no per-tenant limit, is refused too: the server's streams are all taken.
  const grpc::Status refused = StreamStatus(*ward_b_, b_mesh);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("--max-streams"));
  open->Close();
  EXPECT_TRUE(open->Wait().ok());
  grpc::Status again;
  for (int attempt = 0; attempt < 100; ++attempt) {
    again = StreamStatus(*ward_b_, b_mesh);
    if (again.ok()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(again.ok()) << again.error_message();
}

TEST_F(TenancyTest, PerTenantMemoryBudget) {
  service::ServerOptions options = TestServerOptions();
  options.limits.tenant_max_memory_bytes = 1;  // less than any mesh
  Start(options);
  v1::MeshSummary summary;
  const grpc::Status refused = ward_a_->LoadPhantom(300, {}, &summary);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("--tenant-max-memory-mb"));
  EXPECT_TRUE(ListIds(*operator_).empty());
}

TEST_F(TenancyTest, ReloadRotatesTokensAndABadFileKeepsTheOldOnes) {
  Start();
  const std::string a_mesh = LoadPhantom(*ward_a_);
  // Ward A's token is replaced by a new one; the old one stops working, the new one sees A's mesh.
  dir_.Write("tokens", TokenLine("new-token-of-ward-a", "ward-a", "tenant") +
                           TokenLine("token-of-ward-b", "ward-b", "tenant"));
  ASSERT_TRUE(server_->server().ReloadTokens().ok());
  std::vector<v1::MeshSummary> meshes;
  EXPECT_EQ(ward_a_->ListMeshes(&meshes).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(operator_->ListMeshes(&meshes).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  auto rotated = server_->NewClient(WithToken("new-token-of-ward-a"));
  EXPECT_EQ(ListIds(*rotated), std::vector<std::string>{a_mesh});

  dir_.Write("tokens", "this line is not a token line\n");
  const Status bad = server_->server().ReloadTokens();
  EXPECT_EQ(bad.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.message(), HasSubstr("line 1"));
  EXPECT_EQ(ListIds(*rotated), std::vector<std::string>{a_mesh});  // the old table stays
  EXPECT_EQ(ListIds(*ward_b_).size(), 0u);
}

TEST(AuditLogTest, LinesNameTheTenantActionMeshAndResultWithClientStringsEscaped) {
  service::Audit("ward-a", "warm-up", "", "OK");  // creates the "audit" logger
  std::ostringstream captured;
  auto logger = spdlog::get("audit");
  ASSERT_NE(logger, nullptr);
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
  sink->set_pattern("[%n] %v");
  logger->sinks().push_back(sink);
  TestServer server;
  auto client = server.NewClient();
  v1::GetMeshInfoResponse info;
  EXPECT_EQ(client->GetMeshInfo("mesh-x\n[info] forged line", false, &info).error_code(),
            grpc::StatusCode::NOT_FOUND);
  logger->flush();
  logger->sinks().pop_back();
  const std::string text = captured.str();
  EXPECT_THAT(text, HasSubstr("[audit] tenant=default action=get_mesh_info "
                              "mesh=mesh-x\\n[info] forged line result=NOT_FOUND"));
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
}

}  // namespace
}  // namespace deform
