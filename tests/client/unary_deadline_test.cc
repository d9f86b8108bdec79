// The client library's unary calls carry a deadline: against a server that never answers them,
// each ends with DEADLINE_EXCEEDED instead of hanging.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>

#include "deform/v1/deform.grpc.pb.h"
#include "deform_client.h"

namespace deform {
namespace {

// A unary reactor that finishes only when the call is cancelled (by the client's deadline).
class NeverAnswer final : public grpc::ServerUnaryReactor {
 public:
  void OnCancel() override { Finish(grpc::Status::CANCELLED); }
  void OnDone() override { delete this; }
};

class SilentService final : public v1::DeformService::CallbackService {
  grpc::ServerUnaryReactor* GetMeshInfo(grpc::CallbackServerContext*, const v1::GetMeshInfoRequest*,
                                        v1::GetMeshInfoResponse*) override {
    return new NeverAnswer();
  }
  grpc::ServerUnaryReactor* ListMeshes(grpc::CallbackServerContext*, const v1::ListMeshesRequest*,
                                       v1::ListMeshesResponse*) override {
    return new NeverAnswer();
  }
  grpc::ServerUnaryReactor* UnloadMesh(grpc::CallbackServerContext*, const v1::UnloadMeshRequest*,
                                       v1::UnloadMeshResponse*) override {
    return new NeverAnswer();
  }
};

TEST(ClientUnaryDeadline, EveryUnaryCallEndsWithDeadlineExceeded) {
  SilentService service;
  int port = 0;
  grpc::ServerBuilder builder;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  ASSERT_NE(server, nullptr);

  client::ClientOptions options;
  options.unary_deadline_ms = 200;
  client::DeformClient client("127.0.0.1:" + std::to_string(port), options);
  ASSERT_TRUE(client.WaitForReady(5000));

  const auto start = std::chrono::steady_clock::now();
  v1::GetMeshInfoResponse info;
  EXPECT_EQ(client.GetMeshInfo("mesh", false, &info).error_code(),
            grpc::StatusCode::DEADLINE_EXCEEDED);
  std::vector<v1::MeshSummary> meshes;
  EXPECT_EQ(client.ListMeshes(&meshes).error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_EQ(client.UnloadMesh("mesh").error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // Three calls of 200 ms each; without deadlines they would never return.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(20));
  server->Shutdown();
}

}  // namespace
}  // namespace deform
