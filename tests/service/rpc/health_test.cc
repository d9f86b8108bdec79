// The standard health service answers for the server and for deform.v1.DeformService.
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>
#include <string>

#include "tests/service/support/test_server.h"

namespace deform::test_support {
namespace {

// grpc.health.v1.Health/Check through a generic stub (the health protos are not compiled here):
// HealthCheckRequest{service} is field 1 (string); HealthCheckResponse{status} is field 1 (enum,
// SERVING = 1).
grpc::Status CheckHealth(const std::string& target, const std::string& service,
                         std::string* response_bytes) {
  auto channel = grpc::CreateChannel(target, grpc::InsecureChannelCredentials());
  grpc::GenericStub stub(channel);
  std::string request_bytes;
  if (!service.empty()) {
    request_bytes.push_back(0x0a);
    request_bytes.push_back(static_cast<char>(service.size()));
    request_bytes += service;
  }
  grpc::Slice slice(request_bytes);
  grpc::ByteBuffer request(&slice, 1);
  grpc::ByteBuffer response;
  grpc::ClientContext context;
  std::mutex mutex;
  std::condition_variable done_cv;
  bool done = false;
  grpc::Status result;
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request, &response,
                 [&](grpc::Status status) {
                   std::lock_guard<std::mutex> lock(mutex);
                   result = std::move(status);
                   done = true;
                   done_cv.notify_all();
                 });
  std::unique_lock<std::mutex> lock(mutex);
  done_cv.wait(lock, [&] { return done; });
  if (result.ok()) {
    std::vector<grpc::Slice> slices;
    EXPECT_TRUE(response.Dump(&slices).ok());
    response_bytes->clear();
    for (const grpc::Slice& s : slices) {
      response_bytes->append(reinterpret_cast<const char*>(s.begin()), s.size());
    }
  }
  return result;
}

TEST(HealthTest, ServerAndServiceAreServing) {
  TestServer server;
  const std::string serving("\x08\x01", 2);
  std::string response;
  const grpc::Status overall = CheckHealth(server.target(), "", &response);
  ASSERT_TRUE(overall.ok()) << overall.error_message();
  EXPECT_EQ(response, serving);
  const grpc::Status service = CheckHealth(server.target(), "deform.v1.DeformService", &response);
  ASSERT_TRUE(service.ok()) << service.error_message();
  EXPECT_EQ(response, serving);
  EXPECT_EQ(CheckHealth(server.target(), "no.such.Service", &response).error_code(),
            grpc::StatusCode::NOT_FOUND);
}

}  // namespace
}  // namespace deform::test_support
