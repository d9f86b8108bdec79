// The gRPC methods deformd serves, the label sets of the standard gRPC server metrics
// (grpc_server_*, as go-grpc-prometheus names them): deform.v1.DeformService, the standard health
// service (grpc.health.v1.Health) and server reflection (gRPC 1.51 serves v1alpha only). Every
// series is created at start-up from this table, so no client can add one; a call to a method not
// in it (an unknown name) is counted only in deformd_rpcs_total's "other".
//
// tests/service/metrics/grpc_methods_test.cc checks the DeformService rows against the proto's
// descriptor, so a new method fails the test until it is listed here.
#pragma once

#include <array>
#include <string_view>

namespace deform::service {

// go-grpc-prometheus' grpc_type values.
enum class GrpcType { kUnary, kClientStream, kServerStream, kBidiStream };

struct GrpcMethod {
  std::string_view service;  // "deform.v1.DeformService"
  std::string_view method;   // "Deform"
  GrpcType type;
};

inline constexpr std::array<GrpcMethod, 9> kServedGrpcMethods = {{
    {"deform.v1.DeformService", "LoadMesh", GrpcType::kBidiStream},
    {"deform.v1.DeformService", "GetMeshInfo", GrpcType::kUnary},
    {"deform.v1.DeformService", "ListMeshes", GrpcType::kUnary},
    {"deform.v1.DeformService", "UnloadMesh", GrpcType::kUnary},
    {"deform.v1.DeformService", "Deform", GrpcType::kBidiStream},
    {"deform.v1.DeformService", "QueryContact", GrpcType::kBidiStream},
    {"grpc.health.v1.Health", "Check", GrpcType::kUnary},
    {"grpc.health.v1.Health", "Watch", GrpcType::kServerStream},
    {"grpc.reflection.v1alpha.ServerReflection", "ServerReflectionInfo", GrpcType::kBidiStream},
}};

// "unary", "client_stream", "server_stream" or "bidi_stream".
const char* GrpcTypeName(GrpcType type);

// The row of `full_name` ("/deform.v1.DeformService/Deform", as gRPC names a call) in
// kServedGrpcMethods; -1 for a method deformd does not serve.
int ServedGrpcMethodIndex(std::string_view full_name);

}  // namespace deform::service
