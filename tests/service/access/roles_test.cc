// The token file's roles (access/identity.h): a `metrics` token scrapes /metrics and nothing
// else (every RPC PERMISSION_DENIED, every HTTP API call 403); an `operator` reaches every
// tenant's meshes, and each such access to another tenant's mesh leaves an audit line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "service/access/audit_log.h"
#include "service/access/identity.h"
#include "tests/service/support/raw_http.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_server.h"
#include "tests/service/support/token_file.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

class RolesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string file =
        dir_.Write("tokens", TokenLine("token-a", "ward-a", "tenant") +
                                 TokenLine("token-op", "ops", "operator") +
                                 TokenLine("token-scrape", "prometheus", "metrics"));
    service::ServerOptions options = TestServerOptions();
    options.metrics_address = "127.0.0.1:0";
    server_ = std::make_unique<TestServer>(options, file, true);
    ward_a_ = server_->NewClient(WithToken("token-a"));
    ASSERT_TRUE(ward_a_->WaitForReady(60'000));
    v1::MeshSummary summary;
    ASSERT_TRUE(ward_a_->LoadPhantom(300, {}, &summary, {}, "patient-name").ok());
    mesh_id_ = summary.mesh_id();
  }

  TempDir dir_;
  std::unique_ptr<TestServer> server_;
  std::unique_ptr<client::DeformClient> ward_a_;
  std::string mesh_id_;
};

TEST(RoleParsingTest, MetricsIsARoleAndUnknownRolesNameAllThree) {
  auto table = service::TokenTable::Parse(TokenLine("s", "prometheus", "metrics"));
  ASSERT_TRUE(table.ok()) << table.status().ToString();
  const service::Identity* identity = table->Find(service::Sha256Hex("s"));
  ASSERT_NE(identity, nullptr);
  EXPECT_EQ(identity->role, service::Role::kMetrics);
  EXPECT_FALSE(identity->CanAccess("prometheus"));
  auto bad = service::TokenTable::Parse(TokenLine("s", "x", "scraper"));
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.status().message(), HasSubstr("'tenant', 'operator' or 'metrics'"));
}

TEST_F(RolesTest, AMetricsTokenScrapesAndIsRefusedEverythingElse) {
  auto scraper = server_->NewClient(WithToken("token-scrape"));
  std::vector<v1::MeshSummary> meshes;
  EXPECT_EQ(scraper->ListMeshes(&meshes).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  v1::GetMeshInfoResponse info;
  EXPECT_EQ(scraper->GetMeshInfo(mesh_id_, true, &info).error_code(),
            grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(scraper->UnloadMesh(mesh_id_).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  v1::MeshSummary summary;
  EXPECT_EQ(scraper->LoadPhantom(300, {}, &summary).error_code(),
            grpc::StatusCode::PERMISSION_DENIED);
  StreamRecorder recorder;
  auto stream = scraper->OpenStream(mesh_id_, recorder.Callbacks());
  EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::PERMISSION_DENIED);
  // The HTTP API too, with a body.
  const std::string host = "127.0.0.1:" + std::to_string(server_->web_port());
  for (const char* call : {"ListMeshes", "GetMeshInfo", "UnloadMesh"}) {
    const RawHttpResponse response = RawHttpExchange(
        server_->web_port(), std::string("POST /api/") + call + " HTTP/1.1\r\nHost: " + host +
                                 "\r\nAuthorization: Bearer token-scrape\r\n"
                                 "Content-Type: application/x-protobuf\r\nContent-Length: 0\r\n"
                                 "Connection: close\r\n\r\n");
    EXPECT_EQ(response.status, 403) << call << "\n" << response.head;
    EXPECT_THAT(response.body, HasSubstr("metrics role"));
  }
  // The scrape itself.
  const std::string metrics_host = "127.0.0.1:" + std::to_string(server_->server().metrics_port());
  const RawHttpResponse scrape =
      RawHttpExchange(server_->server().metrics_port(),
                      "GET /metrics HTTP/1.1\r\nHost: " + metrics_host +
                          "\r\nAuthorization: Bearer token-scrape\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(scrape.status, 200) << scrape.head;
  EXPECT_THAT(scrape.body, HasSubstr("deformd_streams_open"));
  EXPECT_EQ(scrape.body.find("patient-name"), std::string::npos);
  // Nothing was unloaded.
  ASSERT_TRUE(ward_a_->ListMeshes(&meshes).ok());
  EXPECT_EQ(meshes.size(), 1u);
}

TEST_F(RolesTest, EveryCrossTenantAccessOfAnOperatorIsAudited) {
  auto logger = spdlog::get("audit");
  ASSERT_NE(logger, nullptr);
  std::ostringstream captured;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
  sink->set_pattern("%v");
  logger->sinks().push_back(sink);
  auto ops = server_->NewClient(WithToken("token-op"));
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(ops->ListMeshes(&meshes).ok());
  EXPECT_EQ(meshes.size(), 1u);
  v1::GetMeshInfoResponse info;
  ASSERT_TRUE(ops->GetMeshInfo(mesh_id_, true, &info).ok());
  ASSERT_TRUE(ward_a_->ListMeshes(&meshes).ok());  // its own: no cross-tenant line
  ASSERT_TRUE(ops->UnloadMesh(mesh_id_).ok());
  logger->flush();
  logger->sinks().pop_back();
  const std::string text = captured.str();
  for (const char* op : {"list", "find", "unload"}) {
    EXPECT_THAT(text, HasSubstr("tenant=ops action=cross_tenant mesh=" + mesh_id_ +
                                " result=owner=ward-a role=operator op=" + op));
  }
  EXPECT_EQ(text.find("tenant=ward-a action=cross_tenant"), std::string::npos) << text;
}

// Authentication comes before any check of the request: a garbage HTTP body without a token is
// 401 (it was 400: parsed first), a 200-byte mesh id without a token is UNAUTHENTICATED (it was
// INVALID_ARGUMENT).
TEST_F(RolesTest, AuthenticationComesBeforeAnyBodyIsParsed) {
  const std::string host = "127.0.0.1:" + std::to_string(server_->web_port());
  const std::string garbage = "\xff\xff\xff\xff garbage";
  const RawHttpResponse response = RawHttpExchange(
      server_->web_port(), "POST /api/GetMeshInfo HTTP/1.1\r\nHost: " + host +
                               "\r\nContent-Type: application/x-protobuf\r\nContent-Length: " +
                               std::to_string(garbage.size()) + "\r\nConnection: close\r\n\r\n" +
                               garbage);
  EXPECT_EQ(response.status, 401) << response.head << response.body;
  EXPECT_FALSE(response.body.empty());
  auto anonymous = server_->NewClient();
  v1::GetMeshInfoResponse info;
  EXPECT_EQ(anonymous->GetMeshInfo(std::string(200, 'm'), false, &info).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(anonymous->UnloadMesh(std::string(200, 'm')).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  // With a token, the length check still answers.
  EXPECT_EQ(ward_a_->GetMeshInfo(std::string(200, 'm'), false, &info).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

}  // namespace
}  // namespace deform::test_support
