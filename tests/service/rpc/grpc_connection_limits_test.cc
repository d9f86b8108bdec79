// The gRPC port's connection bounds as a client meets them (connection_acceptor.h): one peer
// address cannot take every connection, a connection over a bound is closed at once and counted,
// a connection given back is taken again, and a server that ran out of descriptors serves a new
// client within a second once they are free again.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "tests/service/support/raw_tcp.h"
#include "tests/service/support/test_server.h"

namespace deform::test_support {
namespace {

// Whether a new client (its own connection) lists the meshes within `seconds`.
bool ServedWithin(TestServer& server, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    client::ClientOptions options;
    options.unary_deadline_ms = 200;
    std::vector<v1::MeshSummary> meshes;
    if (server.NewClient(options)->ListMeshes(&meshes).ok()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

TEST(GrpcConnectionLimitsTest, OnePeerAddressCannotTakeEveryConnection) {
  service::ServerOptions options = TestServerOptions();
  options.connections.max_connections = 16;
  options.connections.max_connections_per_address = 3;
  TestServer server(options);
  std::vector<int> idle;
  for (int i = 0; i < 3; ++i) idle.push_back(IdleConnection(server.server().port()));
  for (const int fd : idle) ASSERT_GE(fd, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // all three accepted
  const int fourth = IdleConnection(server.server().port());
  ASSERT_GE(fourth, 0);
  EXPECT_EQ(BytesBeforeClose(fourth, 2.0), 0);  // closed at once, unserved
  ::close(fourth);
  EXPECT_FALSE(ServedWithin(server, 0.5)) << "a fourth connection from 127.0.0.1 was served";
  EXPECT_GE(server.Refused("grpc_connection_limit"), 1u);

  // Another address is served meanwhile: its connection hears the server's HTTP/2 settings and
  // stays open.
  const int other = IdleConnection(server.server().port(), "127.0.0.2");
  ASSERT_GE(other, 0) << "cannot connect from 127.0.0.2";
  EXPECT_EQ(BytesBeforeClose(other, 1.0), -1);
  ::close(other);

  // Connections given back are taken again.
  for (const int fd : idle) ::close(fd);
  EXPECT_TRUE(ServedWithin(server, 1.0));
}

TEST(GrpcConnectionLimitsTest, OverAllAddressesTheTotalHolds) {
  service::ServerOptions options = TestServerOptions();
  options.connections.max_connections = 4;
  options.connections.max_connections_per_address = 4;
  TestServer server(options);
  std::vector<int> idle;
  for (const char* from : {"127.0.0.2", "127.0.0.3", "127.0.0.4", "127.0.0.5"}) {
    idle.push_back(IdleConnection(server.server().port(), from));
    ASSERT_GE(idle.back(), 0) << "cannot connect from " << from;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(server.server().open_connections(), 4);
  const int fifth = IdleConnection(server.server().port(), "127.0.0.6");
  ASSERT_GE(fifth, 0);
  EXPECT_EQ(BytesBeforeClose(fifth, 2.0), 0);
  ::close(fifth);
  ::close(idle[0]);
  EXPECT_TRUE(ServedWithin(server, 1.0));
  for (std::size_t i = 1; i < idle.size(); ++i) ::close(idle[i]);
}

// A port that is not a number is refused, never replaced by one the kernel picks.
TEST(GrpcConnectionLimitsTest, AListenAddressWithABadPortIsRefused) {
  for (const char* address : {"127.0.0.1:http", "127.0.0.1:65536", "127.0.0.1:", "127.0.0.1"}) {
    service::ServerOptions options = TestServerOptions();
    options.listen_address = address;
    service::DeformServer server(options);
    const Status started = server.Start();
    EXPECT_EQ(started.code(), StatusCode::kFailedPrecondition) << address;
    EXPECT_NE(started.message().find("cannot listen on"), std::string::npos) << started.ToString();
    EXPECT_EQ(server.port(), 0) << address;
  }
}

// gRPC's own listener stops accepting for good after one EMFILE; this server accepts again.
TEST(GrpcConnectionLimitsTest, OutOfDescriptorsTheServerRecoversOnceTheyAreFree) {
  TestServer server;
  ASSERT_TRUE(ServedWithin(server, 2.0));
  // More connections than the process has descriptors left for: the clients' ends take some,
  // the server's accepts the rest, and the last ones wait in the backlog with none left.
  DescriptorShortage shortage(server.server().port());
  ASSERT_TRUE(shortage.ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const std::uint64_t refused = server.Refused("no_descriptors");
  const std::size_t opened = shortage.connections();
  shortage.CloseConnections();  // descriptors free again, under the same lowered limit
  EXPECT_GE(refused, 1u) << opened << " connections opened";
  EXPECT_TRUE(ServedWithin(server, 1.0)) << "not served within a second of the descriptors' return";
}

}  // namespace
}  // namespace deform::test_support
