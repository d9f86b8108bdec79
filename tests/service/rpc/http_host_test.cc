// The HTTP port answers only the Host names it is for (transport/http_host_policy.h): the DNS
// rebinding attack (a page on another name resolving to 127.0.0.1, sending its own Host and a
// matching Origin) is refused with 403 and a body on every endpoint, while the loopback names,
// the listen address and --http-allowed-host names keep working.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"
#include "service/transport/http_host_policy.h"
#include "tests/service/support/raw_http.h"
#include "tests/service/support/test_server.h"

namespace deform::test_support {
namespace {

std::string Post(const std::string& path, const std::string& host, const std::string& origin,
                 const std::string& body) {
  std::string request = "POST " + path + " HTTP/1.1\r\nHost: " + host + "\r\n";
  if (!origin.empty()) request += "Origin: " + origin + "\r\n";
  request +=
      "Content-Type: application/x-protobuf\r\nContent-Length: " + std::to_string(body.size()) +
      "\r\nConnection: close\r\n\r\n" + body;
  return request;
}

std::string Get(const std::string& path, const std::string& host, const std::string& extra) {
  return "GET " + path + " HTTP/1.1\r\nHost: " + host + "\r\n" + extra +
         "Connection: close\r\n\r\n";
}

std::string WebSocketUpgrade(const std::string& host, const std::string& origin) {
  return "GET /ws/Deform HTTP/1.1\r\nHost: " + host + "\r\nOrigin: " + origin +
         "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
         "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Protocol: deform.v1\r\n"
         "\r\n";
}

TEST(HttpHostPolicyTest, LoopbackNamesListenHostAndExtrasOnly) {
  const web::HttpHostPolicy policy("10.1.2.3:8080", {"Sim-Station.local", "[fd00::7]"});
  for (const char* host : {"localhost", "LOCALHOST:8080", "127.0.0.1:8080", "[::1]:8080", "[::1]",
                           "10.1.2.3:8080", "sim-station.local:8080", "[FD00::7]:1"}) {
    EXPECT_TRUE(policy.AllowsHost(host)) << host;
  }
  for (const char* host : {"", "rebind.attacker.example:8080", "localhost.attacker.example",
                           "127.0.0.1.nip.io", "localhost:80x", "localhost:", "[::1", "::1",
                           "[::1]x", "local host", "localhost\r\nX: y", "10.1.2.4"}) {
    EXPECT_FALSE(policy.AllowsHost(host)) << host;
  }
  EXPECT_TRUE(policy.AllowsRequest("localhost:8080", std::nullopt));
  EXPECT_TRUE(policy.AllowsRequest("localhost:8080", "http://localhost:8080"));
  EXPECT_FALSE(policy.AllowsRequest("localhost:8080", "http://localhost:8081"));
  EXPECT_FALSE(policy.AllowsRequest("localhost:8080", "http://evil.example"));
  EXPECT_FALSE(policy.AllowsRequest("localhost:8080", "null"));
  EXPECT_FALSE(
      policy.AllowsRequest("rebind.attacker.example:8080", "http://rebind.attacker.example:8080"));
  // A wildcard listen address names no host.
  const web::HttpHostPolicy any("0.0.0.0:8080", {});
  EXPECT_FALSE(any.AllowsHost("0.0.0.0:8080"));
  EXPECT_TRUE(any.AllowsHost("127.0.0.1:8080"));
}

class HttpHostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    web::WebOptions web_options;
    web_options.allowed_hosts = {"sim-station.local"};
    server_ = std::make_unique<TestServer>(TestServerOptions(), "", true, web_options);
    port_ = std::to_string(server_->web_port());
    client_ = server_->NewClient();
    ASSERT_TRUE(client_->WaitForReady(60'000));
    v1::MeshSummary summary;
    const grpc::Status loaded = client_->LoadPhantom(200, {}, &summary, {}, "patient-name");
    ASSERT_TRUE(loaded.ok()) << loaded.error_message();
    mesh_id_ = summary.mesh_id();
  }

  std::unique_ptr<TestServer> server_;
  std::unique_ptr<client::DeformClient> client_;
  std::string port_;
  std::string mesh_id_;
};

TEST_F(HttpHostTest, DnsRebindingIsRefusedOnEveryEndpoint) {
  const std::string host = "rebind.attacker.example:" + port_;
  const std::string origin = "http://" + host;
  v1::GetMeshInfoRequest info;
  info.set_mesh_id(mesh_id_);
  v1::UnloadMeshRequest unload;
  unload.set_mesh_id(mesh_id_);
  const std::vector<std::string> attacks = {
      Post("/api/ListMeshes", host, origin, ""),
      Post("/api/GetMeshInfo", host, origin, info.SerializeAsString()),
      Post("/api/UnloadMesh", host, origin, unload.SerializeAsString()),
      Post("/api/ListMeshes", host, "", ""),
      Get("/", host, "Origin: " + origin + "\r\n"),
      Get("/", host, ""),
      WebSocketUpgrade(host, origin),
  };
  for (const std::string& attack : attacks) {
    const RawHttpResponse response = RawHttpExchange(server_->web_port(), attack);
    EXPECT_EQ(response.status, 403) << attack << "\n" << response.head;
    EXPECT_NE(response.body.find("Host"), std::string::npos) << response.body;
    EXPECT_EQ(response.body.find("patient-name"), std::string::npos);
  }
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(client_->ListMeshes(&meshes).ok());
  ASSERT_EQ(meshes.size(), 1u) << "the rebinding page unloaded the mesh";
  EXPECT_EQ(meshes[0].mesh_id(), mesh_id_);
}

TEST_F(HttpHostTest, LoopbackNamesAndAllowedHostsStillWork) {
  for (const std::string name : {"localhost", "127.0.0.1", "[::1]", "sim-station.local"}) {
    const std::string host = name + ":" + port_;
    const RawHttpResponse listed =
        RawHttpExchange(server_->web_port(), Post("/api/ListMeshes", host, "http://" + host, ""));
    EXPECT_EQ(listed.status, 200) << host << "\n" << listed.head << listed.body;
    v1::ListMeshesResponse reply;
    ASSERT_TRUE(reply.ParseFromString(listed.body)) << host;
    EXPECT_EQ(reply.meshes_size(), 1) << host;
    const RawHttpResponse page = RawHttpExchange(server_->web_port(), Get("/", host, ""));
    EXPECT_EQ(page.status, 200) << host << "\n" << page.head;
  }
  // Same Host, another origin: still refused, with a body.
  const std::string host = "localhost:" + port_;
  const RawHttpResponse cross = RawHttpExchange(
      server_->web_port(), Post("/api/ListMeshes", host, "http://evil.example", ""));
  EXPECT_EQ(cross.status, 403) << cross.head;
  EXPECT_NE(cross.body.find("cross-origin"), std::string::npos) << cross.body;
}

}  // namespace
}  // namespace deform::test_support
