// The HTTP port's bounds as a client meets them: a request line and headers over 8 KiB are 431
// and a body over the limit 413, each with a body naming the limit (the client reads the status,
// not a reset); a connection that sends nothing gives its slot back within the header timeout, so
// half-open connections deny the viewer for seconds, not for as long as an attacker renews them.
// A WebSocket message over its limit ends the stream RESOURCE_EXHAUSTED with the stream
// contract's status message, not with a bare close frame.
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "tests/service/support/raw_http.h"
#include "tests/service/support/raw_tcp.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/test_server.h"
#include "tests/service/support/websocket_deform_stream.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

const std::string kGet = "GET /index.html HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n";

TEST(HttpLimitsTest, OversizedHeadersAre431AndAnOversizedBody413WithABody) {
  TestServer server(TestServerOptions(), "", true);
  const RawHttpResponse fine = RawHttpExchange(server.web_port(), kGet + "\r\n");
  EXPECT_EQ(fine.status, 200);

  const RawHttpResponse headers = RawHttpExchange(
      server.web_port(), kGet + "X-Padding: " + std::string(9000, 'a') + "\r\n\r\n");
  EXPECT_EQ(headers.status, 431) << headers.head;
  EXPECT_THAT(headers.body, HasSubstr("request line and headers over 8192 bytes"));
  EXPECT_THAT(headers.head, HasSubstr("Deform-Status: 8"));  // RESOURCE_EXHAUSTED

  const std::string body(200'000, 'b');
  const RawHttpResponse posted =
      RawHttpExchange(server.web_port(),
                      "POST /deform.v1.DeformService/ListMeshes HTTP/1.1\r\nHost: localhost\r\n"
                      "Content-Type: application/x-protobuf\r\nContent-Length: " +
                          std::to_string(body.size()) + "\r\n\r\n" + body);
  EXPECT_EQ(posted.status, 413) << posted.head;
  EXPECT_THAT(posted.body, HasSubstr("request body over 65536 bytes"));
  // The port still serves.
  EXPECT_EQ(RawHttpExchange(server.web_port(), kGet + "\r\n").status, 200);
}

TEST(HttpLimitsTest, HalfOpenConnectionsGiveTheirSlotsBackWithinTheHeaderTimeout) {
  web::WebOptions options;
  options.max_connections = 2;
  TestServer server(TestServerOptions(), "", true, options);
  const int first = IdleConnection(server.web_port());
  const int second = IdleConnection(server.web_port());
  ASSERT_GE(first, 0);
  ASSERT_GE(second, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));             // both accepted
  EXPECT_EQ(RawHttpExchange(server.web_port(), kGet + "\r\n").status, 0);  // every slot taken
  EXPECT_LT(SecondsUntilClosed(first, 10), 7.0);  // the header timeout is 5 s
  EXPECT_LT(SecondsUntilClosed(second, 10), 2.0);
  ::close(first);
  ::close(second);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(RawHttpExchange(server.web_port(), kGet + "\r\n").status, 200);
}

// The status of a GET sent on `fd` (0 when the server closed it without answering).
int StatusOfGet(int fd) {
  const std::string request = kGet + "\r\n";
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) !=
      static_cast<ssize_t>(request.size())) {
    return 0;
  }
  timeval timeout{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  std::string reply;
  char buffer[512];
  for (ssize_t got; reply.find("\r\n") == std::string::npos &&
                    (got = ::recv(fd, buffer, sizeof(buffer), 0)) > 0;) {
    reply.append(buffer, got);
  }
  return reply.rfind("HTTP/1.1 ", 0) == 0 ? std::atoi(reply.c_str() + 9) : 0;
}

// One peer address cannot take every slot: its connections over the per-address bound are closed
// at once and counted, while another address is served; a slot given back is taken again.
TEST(HttpLimitsTest, OnePeerAddressCannotTakeEverySlot) {
  web::WebOptions options;
  options.max_connections = 8;
  options.max_connections_per_address = 2;
  TestServer server(TestServerOptions(), "", true, options);
  const int first = IdleConnection(server.web_port());
  const int second = IdleConnection(server.web_port());
  ASSERT_GE(first, 0);
  ASSERT_GE(second, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // both accepted
  const int third = IdleConnection(server.web_port());
  ASSERT_GE(third, 0);
  EXPECT_LT(SecondsUntilClosed(third, 10), 2.0);  // refused at once, not at the header timeout
  ::close(third);
  const int other = IdleConnection(server.web_port(), "127.0.0.2");
  ASSERT_GE(other, 0) << "cannot connect from 127.0.0.2";
  EXPECT_EQ(StatusOfGet(other), 200);
  ::close(other);
  ::close(first);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const int again = IdleConnection(server.web_port());
  ASSERT_GE(again, 0);
  EXPECT_EQ(StatusOfGet(again), 200);
  ::close(again);
  ::close(second);
  const std::string page = server.server().context().metrics().Serialize();
  EXPECT_THAT(page, HasSubstr("deformd_refused_total{reason=\"http_connection_limit\"} 1"));
}

// Out of descriptors, the HTTP port rests between its tries (no spinning, no line per failure)
// and serves again once descriptors are free.
TEST(HttpLimitsTest, OutOfDescriptorsThePortRestsAndServesAgain) {
  TestServer server(TestServerOptions(), "", true);
  DescriptorShortage shortage(server.web_port());
  ASSERT_TRUE(shortage.ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const std::uint64_t refused = server.Refused("no_descriptors");
  const std::size_t opened = shortage.connections();
  shortage.End();
  EXPECT_GE(refused, 1u) << opened << " connections opened";
  EXPECT_LE(refused, 20u) << "the accept was tried again without a rest";
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  const int again = IdleConnection(server.web_port());
  ASSERT_GE(again, 0);
  EXPECT_EQ(StatusOfGet(again), 200);
  ::close(again);
}

TEST(HttpLimitsTest, AWebSocketMessageOverTheLimitEndsTheStreamResourceExhausted) {
  TestServer server(TestServerOptions(), "", true);
  auto client = server.NewClient();
  v1::MeshSummary summary;
  ASSERT_TRUE(client->LoadPhantom(300, {}, &summary).ok());
  StreamRecorder recorder;
  WebSocketDeformStream stream(server.web_port(), summary.mesh_id(), recorder.Callbacks());
  v1::PoseUpdate pose;
  pose.set_sequence(1);
  v1::JointAngle* angle = pose.add_angles();
  angle->set_joint(std::string(5 << 20, 'j'));  // 5 MiB, over the default 4 MiB
  angle->set_axis("x");
  ASSERT_TRUE(stream.SendPose(pose));
  const grpc::Status status = stream.Wait();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("over the limit of 4194304 bytes"));
  // The port still serves a stream.
  StreamRecorder next;
  WebSocketDeformStream again(server.web_port(), summary.mesh_id(), next.Callbacks());
  ASSERT_TRUE(again.SendPose(KneePose(1, 30)));
  EXPECT_TRUE(next.WaitForFrames(1));
  again.Close();
  EXPECT_TRUE(again.Wait().ok());
}

}  // namespace
}  // namespace deform::test_support
